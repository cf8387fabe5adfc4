// CARMEN 0.7.4 map files (.map, .map.gz): reading and writing, in C++.
//
// Layout (see the project's format notes): optional '#' comment lines, the
// 17-byte id "CARMENMAPFILEv020", then chunks until the end of the file:
//   uint8 type | int32 size | char description[10] | [name '\0' if type&0x80] | payload
// where `size` counts everything after itself. All numbers are little-endian
// (CARMEN writes host order; every known map comes from x86). This module
// reads and writes little-endian whatever the host.
//
// Reading is defensive: every size a file claims is checked against what the
// file holds before memory is allocated for it (plain files: against the file
// size; gzip files: the payload is read in bounded pieces, so a short stream
// fails with a clean error before the claimed size is ever allocated), and
// every error is a carmen::FileError naming the file, the chunk and the offset.
// Whether a file is gzip is told by its name (file_names.h: ".gz" in any case).
// Reading is map_file_reader.h (carmen_compat/src), writing map_file_write.cc;
// map_format.h picks a format (CARMEN map, PGM + YAML, PNG) by extension.
#ifndef CARMEN_COMPAT_MAP_FILE_H
#define CARMEN_COMPAT_MAP_FILE_H

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace carmen {

class AtomicOutput;

// ---------------------------------------------------------------------------
// Chunk codes (the values of CARMEN's CARMEN_MAP_*_CHUNK macros).
// ---------------------------------------------------------------------------
enum MapChunkType : int {
  kOldCreatorChunk = 0,  // pre-0.7 creator code; read as CREATOR when no CREATOR exists
  kGridmapChunk = 1,
  kOfflimitsChunk = 2,
  kHmapChunk = 3,  // not supported: skipped like an unknown chunk
  kPlacesChunk = 4,
  kExpectedChunk = 8,  // never written by CARMEN: skipped like an unknown chunk
  kLaserscansChunk = 16,
  kCreatorChunk = 32,
  kGlobalOffsetChunk = 64,
};
constexpr int kNamedChunkFlag = 0x80;
constexpr char kMapLabel[] = "CARMENMAPFILE";
constexpr char kMapVersion[] = "v020";
constexpr int kMapIdLength = 17;  // label + version, no terminator

// The 10-character description CARMEN writes for a chunk type ("GRIDMAP   "),
// or "UNKNOWN   " for codes it does not know. The named flag is ignored.
std::string chunk_description(int type);
// A short name for messages: "GRIDMAP", "PLACES", ..., or "type 102".
std::string chunk_type_name(int type);

// ---------------------------------------------------------------------------
// Cell values
// ---------------------------------------------------------------------------
constexpr float kUnknownCell = -1.0f;  // exactly -1 means "never observed"

// True for the values a CARMEN map may hold: exactly -1 (unknown), a
// probability in [0, 1], or [2, 3] (CARMEN's off-limits overlay adds 2 to a
// probability in memory). Everything else — NaN, infinities, other negative
// numbers, (1, 2), > 3 — is damage.
bool valid_cell_value(float v);

// ---------------------------------------------------------------------------
// Payloads
// ---------------------------------------------------------------------------
struct GridMap {
  int size_x = 0, size_y = 0;
  double resolution = 0;     // metres per cell (stored in the file as float32)
  std::vector<float> cells;  // x-major: cells[x*size_y + y]; y points up

  // Bounds-checked access (throws std::out_of_range).
  float at(int x, int y) const;
  float &at(int x, int y);
  bool contains(int x, int y) const { return x >= 0 && y >= 0 && x < size_x && y < size_y; }
  // A size_x × size_y map with every cell set to `value`.
  static GridMap filled(int size_x, int size_y, double resolution, float value = kUnknownCell);
};

struct GlobalOffset {
  double x = 0, y = 0, theta = 0;
};

struct CreatorInfo {
  std::string user;         // at most 10 characters are stored
  std::string origin;       // at most 80
  std::string description;  // at most 80
  int64_t time = 0;         // seconds since 1970 (time_t)
  int time_bytes = 8;       // width of time_t in the file: 4 (all shipped maps) or 8
};

// Place types (CARMEN's CARMEN_NAMED_POSITION_TYPE etc.). A position stores
// x y, a pose x y theta, a localization init x y theta x_std y_std theta_std
// (all as float32 in the file).
enum PlaceType : int {
  kNamedPosition = 0,
  kNamedPose = 1,
  kLocalizationInit = 2,
};
struct Place {
  int type = kNamedPosition;
  std::string name;  // at most 20 characters are stored
  double x = 0, y = 0, theta = 0;
  double x_std = 0, y_std = 0, theta_std = 0;
};

// Off-limits areas in cell coordinates.
struct OffLimits {
  struct Point {
    int32_t x = 0, y = 0;
  };
  struct Segment {  // a line, or a rectangle given by two corners
    int32_t x1 = 0, y1 = 0, x2 = 0, y2 = 0;
  };
  std::vector<Point> points;
  std::vector<Segment> lines;
  std::vector<Segment> rects;
  bool empty() const { return points.empty() && lines.empty() && rects.empty(); }
};

struct LaserScan {
  double x = 0, y = 0, theta = 0;  // stored as float32
  std::vector<float> ranges;
};

using PlaceList = std::vector<Place>;
using LaserScanList = std::vector<LaserScan>;
using ChunkPayload = std::variant<GridMap, OffLimits, PlaceList, LaserScanList, CreatorInfo, GlobalOffset>;

// A chunk written with the 0x80 flag and a name. type() is the base code.
struct NamedChunk {
  std::string name;  // non-empty, no NUL
  ChunkPayload payload;
  int type() const;
};

// What the reader saw, chunk by chunk, in file order (for --info and tests).
struct ChunkInfo {
  int type = 0;             // the raw type byte (named flag included)
  int64_t offset = 0;       // byte offset of the type byte in the (uncompressed) data
  int32_t size = 0;         // the size field: bytes after it, description included
  std::string description;  // the 10-byte description as stored
  std::string name;         // for named chunks
  bool named() const { return (type & kNamedChunkFlag) != 0; }
  int base_type() const { return type & ~kNamedChunkFlag; }
  bool used = false;  // parsed into MapFile (false: unknown, unsupported or a duplicate)
  // A named chunk of a kind MapFile holds, indexed but not read
  // (NamedChunkReading::Index): read_named_chunk() reads it when asked.
  bool deferred = false;
};

struct MapFile {
  // Comment lines without the leading '#' and the newline: the line
  // "# Map size : 300 x 300" is stored as " Map size : 300 x 300".
  std::vector<std::string> comments;
  std::optional<CreatorInfo> creator;
  std::optional<GridMap> gridmap;
  std::optional<GlobalOffset> offset;
  std::optional<PlaceList> places;
  std::optional<OffLimits> offlimits;
  std::optional<LaserScanList> laserscans;
  std::vector<NamedChunk> named;
  // Chunks skipped on reading (and so not written back): unknown codes,
  // HMAP, EXPECTED (named or not) and repeated unnamed chunks of a type
  // already read (CARMEN uses the first one).
  int unknown_chunks = 0;
  bool old_style_creator = false;  // the creator came from a code-0 chunk
  std::vector<ChunkInfo> chunks;   // filled by the reader; ignored by the writer
};

// ---------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------
// What the reader does with named chunks. A file may hold thousands of named
// GRIDMAPs that compress to almost nothing: Index lists them (MapFile::chunks,
// deferred = true) and keeps none of their cells, so a reader that wants the
// main map or a summary (mapconvert --info) needs memory for one grid only.
enum class NamedChunkReading {
  Parse,  // every named chunk parsed into MapFile::named (checked, counted in max_kept_bytes)
  Index,  // headers only; MapFile::named stays empty; read one with read_named_chunk()
};

// What the reader reads as CARMEN reads it, with a warning, although the file
// is not as its sizes say:
//  - a GRIDMAP chunk whose data ends inside its cells (the map is cut short,
//    or a byte was lost, as in CARMEN's own nsh_level_3.map): the cells there
//    are read and the missing ones are unknown (-1). Only a chunk whose header
//    is sound (sizes, resolution, a size field that matches them) and of whose
//    cells at least half (or all but 1 MiB) are in the file: so what is
//    allocated stays within twice what the file holds, and a few bytes cannot
//    claim gigabytes. A gzip stream that is itself cut short or corrupt is
//    still an error (zlib reports it).
//  - OFFLIMITS chunks in the layouts CARMEN 0.7.4's writers give them
//    (decode_offlimits_payload below).
struct MapReadOptions {
  // Reject gridmaps holding values outside valid_cell_value(). On: a damaged
  // map (NaN, huge or negative garbage) is reported, not passed on.
  bool check_cells = true;
  // The most chunk data a read keeps in memory (every chunk parsed, named
  // ones included). A few kilobytes of .gz can claim gigabytes of cells; a
  // file that needs more is refused with the number to raise. 1 GiB holds a
  // 16000 x 16000 grid.
  uint64_t max_kept_bytes = uint64_t(1) << 30;
  NamedChunkReading named_chunks = NamedChunkReading::Parse;
  // Where warnings go (one line each, "FILE: warning: the GRIDMAP chunk at
  // byte N ..."): only for a chunk that is read, not for one passed on the
  // way to it. Unset: printed on stderr.
  std::function<void(const std::string &)> on_warning;
};

// Reads a whole map file; ".gz" names are gunzipped (as carmen_fopen does:
// by name, not content). Throws carmen::FileError naming the file (and
// what is wrong and where) for anything unreadable, truncated or damaged.
MapFile read_map_file(const std::string &path);
MapFile read_map_file(const std::string &path, const MapReadOptions &options);

// Reads the one named chunk `chunk` (an entry of MapFile::chunks or of
// list_map_chunks() for this file), checked as read_map_file checks it.
// Throws carmen::FileError when the file no longer holds that chunk there.
NamedChunk read_named_chunk(const std::string &path, const ChunkInfo &chunk,
                            const MapReadOptions &options = MapReadOptions{});

// Scans the chunk headers only (payloads are skipped, not parsed or kept).
// Throws carmen::FileError like read_map_file for a damaged layout.
std::vector<ChunkInfo> list_map_chunks(const std::string &path);

// ---------------------------------------------------------------------------
// One chunk, found as CARMEN finds it (carmen_map_advance_to_chunk and
// carmen_map_advance_to_named_chunk): the chunk headers are scanned from the
// start of the file up to the first chunk whose type, named flag masked off,
// is `type` (name == nullptr: named or not; otherwise the first named chunk
// of that type called *name), and nothing after it is looked at. So a map
// whose only GRIDMAP is named still has a gridmap, and damage in a chunk
// after the one asked for does not matter; damage in that chunk or in one
// before it is a carmen::FileError naming the chunk and its byte offset.
// Memory stays bounded as for read_map_file: no size a header claims is
// allocated before the bytes are there.
// ---------------------------------------------------------------------------
struct FoundChunk {
  ChunkInfo info;        // the chunk's header (raw type, offset, size, name)
  ChunkPayload payload;  // parsed and checked as read_map_file would
};
// The header of that chunk, or nullopt when the scan reaches the end of the
// file without one.
std::optional<ChunkInfo> find_first_chunk(const std::string &path, int type,
                                          const std::string *name = nullptr);
// The same chunk read, in one pass. `type` is a kind ChunkPayload holds
// (GRIDMAP, CREATOR, OFFSET, PLACES, OFFLIMITS, LASERSCANS) or the old creator
// code 0 (read as a CreatorInfo); anything else is std::invalid_argument.
std::optional<FoundChunk> read_first_chunk(const std::string &path, int type, const std::string *name = nullptr,
                                           const MapReadOptions &options = MapReadOptions{});

// The size and resolution of a gridmap (what carmen_map_read_gridmap_config
// reads): the first GRIDMAP found as above, its header checked (positive
// sizes and resolution, a chunk size that matches the cells) but its cells
// neither read nor checked.
struct GridMapHeader {
  ChunkInfo info;
  int size_x = 0, size_y = 0;
  double resolution = 0;
};
std::optional<GridMapHeader> read_first_gridmap_header(const std::string &path, const std::string *name = nullptr);

// True when the file opens and its comments are followed by the CARMEN id
// (what CARMEN's carmen_map_file() tests). Never throws.
bool is_map_file(const std::string &path);

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------
// Writes comments, id, creator, gridmap, places, offlimits, laserscans,
// offset (each only if present), then the named chunks, in that order. A
// ".gz" name is gzipped. Atomic: written to a temporary file beside `path`
// and renamed over it, so a failure never leaves half a file.
// Comment lines are written as '#' + text + '\n'; newlines inside a comment
// become spaces and lines are cut to 97 characters, so that CARMEN's reader
// (fgets with a 100-byte buffer) reads each line whole.
// Throws std::invalid_argument for an inconsistent MapFile (cells.size() !=
// size_x*size_y, a chunk over 2 GiB, an empty chunk name, bad place type or
// time width) and carmen::FileError for I/O failures.
void write_map_file(const std::string &path, const MapFile &map);
// The same into an output the caller commits (one of an OutputTransaction's).
void write_map_file(AtomicOutput &out, const MapFile &map);

// The comment block CARMEN 0.7.4's carmen_map_write_comment_chunk writes at
// the top of a map, as MapFile::comments lines: encode_comment_lines() of
// these gives CARMEN's bytes. A rule of 53 '#', "#", the title, "#", the
// author, the date (asctime() of localtime(), as CARMEN's), the size, the
// resolution as "%.1f", the origin, then the description followed directly by
// the "#" of the next line (CARMEN's Description line has no newline, so its
// file reads "...: desc#"), and the rule again.
std::vector<std::string> standard_map_comments(int size_x, int size_y, double resolution,
                                               const std::string &origin, const std::string &description,
                                               const std::string &author, int64_t time);

// ---------------------------------------------------------------------------
// Byte encoders (what write_map_file writes; used by the CARMEN C writers).
// Each returns a whole chunk: type, size, description, [name], payload.
// An empty name writes an unnamed chunk. Throw std::invalid_argument like
// write_map_file.
// ---------------------------------------------------------------------------
std::string encode_map_id();
std::string encode_comment_lines(const std::vector<std::string> &comments);
std::string encode_gridmap_chunk(const GridMap &map, const std::string &name = {});
std::string encode_creator_chunk(const CreatorInfo &creator, const std::string &name = {});
std::string encode_global_offset_chunk(const GlobalOffset &offset, const std::string &name = {});
std::string encode_places_chunk(const PlaceList &places, const std::string &name = {});
std::string encode_offlimits_chunk(const OffLimits &offlimits, const std::string &name = {});
std::string encode_laserscans_chunk(const LaserScanList &scans, const std::string &name = {});
std::string encode_chunk(const ChunkPayload &payload, const std::string &name = {});
// A whole chunk of `type` around a payload already encoded by the caller
// (for kinds MapFile does not hold, such as HMAP).
std::string encode_raw_chunk(int type, const std::string &payload, const std::string &name = {});

// ---------------------------------------------------------------------------
// OFFLIMITS payloads as CARMEN 0.7.4's writers lay them out. The layout is
// int32 points, (x y) each; int32 lines, (x1 y1 x2 y2) each; int32
// rectangles, (x1 y1 x2 y2) each. CARMEN's writer counts every line but
// writes only those among the first `lines` items of its list (its loop runs
// to the line count, not the item count), while its size field counts them
// all: such a chunk ends 16 bytes early for each line left out, and the next
// chunk begins there. Its named writer also sizes the chunk without the name
// and the items (the size field says 22, where the writer does not crash),
// so a named chunk's end is found from its counts. decode_offlimits_payload
// reads the layout the size field gives when it parses and the data after it
// ends or is a chunk header of a kind CARMEN writes; else the layout CARMEN
// wrote, when one fits (the lines that are there, the rectangles after them,
// followed likewise by the end or a chunk header); else the sized layout,
// when it parses.
// ---------------------------------------------------------------------------
struct OffLimitsPayload {
  bool ok = false;
  std::string error;            // when !ok: what is wrong (the size field's layout)
  OffLimits offlimits;
  uint64_t length = 0;          // payload bytes the chunk holds: the next chunk begins there
  uint64_t lines_left_out = 0;  // lines counted but not written by CARMEN's writer
  bool carmen_layout = false;   // the size field does not give the chunk's end
};
// Makes `bytes` hold the payload's first `want` bytes, or all there are when
// the data ends first, by appending to it. May throw (the caller's errors).
using PayloadFetch = std::function<void(std::vector<unsigned char> &bytes, uint64_t want)>;
// `bytes` starts empty and is filled through `fetch` only; on return it
// holds all that was fetched, which may run past the chunk's end (the caller
// reads that again as the next chunk). `declared`: the payload bytes the
// size field gives (after the name); `named`: the chunk has the 0x80 flag
// (its size field is not trusted). CARMEN's layouts are looked for within
// the first 16 MiB only.
OffLimitsPayload decode_offlimits_payload(std::vector<unsigned char> &bytes, uint64_t declared, bool named,
                                          const PayloadFetch &fetch);

// The bytes after the size field of a chunk found by list_map_chunks():
// description, name and NUL (named chunks), payload. Throws FileError.
std::string read_chunk_body(const std::string &path, const ChunkInfo &chunk);

}  // namespace carmen

#endif  // CARMEN_COMPAT_MAP_FILE_H
