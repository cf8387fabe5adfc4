// CARMEN map files: the defensive reader (map_file.h): the public readers,
// and the Reader's walk over a file's layout: comments, id, chunk headers,
// which chunks are read and which passed (map_file_reader.h).
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "map_file_bytes.h"
#include "map_file_reader.h"

namespace carmen {
namespace map_read {

using namespace map_bytes;

bool is_named_kind(int base) {
  switch (base) {
    case kGridmapChunk:
    case kCreatorChunk:
    case kGlobalOffsetChunk:
    case kPlacesChunk:
    case kOfflimitsChunk:
    case kLaserscansChunk: return true;
    default: return false;
  }
}

MapFile Reader::run() {
  read_comments();
  read_id();
  ChunkInfo info;
  uint64_t left = 0;
  while (read_chunk_header(&info, &left)) {
    read_chunk(info, left);
    map_.chunks.push_back(std::move(info));
    info = ChunkInfo{};
  }
  if (!map_.creator && old_creator_) {
    map_.creator = std::move(old_creator_);
    map_.old_style_creator = true;
  }
  check_kept_cells();  // last, so that a file damaged in its layout reports that
  return std::move(map_);
}

// The named chunk `listed` (from a listing of this file), read and checked.
NamedChunk Reader::read_named_at(const ChunkInfo &listed) {
  if (in_.skip(uint64_t(listed.offset)) != uint64_t(listed.offset)) fail_short("the data before the chunk");
  ChunkInfo info;
  uint64_t left = 0;
  if (!read_chunk_header(&info, &left) || info.type != listed.type || info.name != listed.name ||
      !info.named() || !is_named_kind(info.base_type()))
    fail("at byte " + std::to_string(listed.offset) + " is not the named chunk the listing gave");
  chunk_ = &info;
  NamedChunk nc{info.name, parse_or_fail([&] { return named_payload(info, left); })};
  if (const auto *g = std::get_if<GridMap>(&nc.payload); g != nullptr && opts_.check_cells) check_cells(*g);
  chunk_ = nullptr;
  return nc;
}

// CARMEN's lookup (map_file.h, find_first_chunk): scans from the start to
// the first chunk of `type` (named flag masked) or, with a name, the first
// named one of that type called *name. On true, the input is at its
// payload; false when the data ends first.
bool Reader::seek_first(int type, const std::string *name, ChunkInfo *info, uint64_t *left) {
  read_comments();
  read_id();
  while (read_chunk_header(info, left)) {
    if (info->base_type() == type && (name == nullptr || (info->named() && info->name == *name))) return true;
    pass(*info, *left);
    *info = ChunkInfo{};
    chunk_ = nullptr;
  }
  return false;
}

std::optional<ChunkInfo> Reader::find_first(int type, const std::string *name) {
  ChunkInfo info;
  uint64_t left = 0;
  if (!seek_first(type, name, &info, &left)) return std::nullopt;
  chunk_ = nullptr;
  return info;
}

std::optional<FoundChunk> Reader::read_first(int type, const std::string *name) {
  if (type != kOldCreatorChunk && !is_named_kind(type))
    throw std::invalid_argument("read_first_chunk: chunk type " + std::to_string(type) + " is not read into a payload");
  ChunkInfo info;
  uint64_t left = 0;
  if (!seek_first(type, name, &info, &left)) return std::nullopt;
  chunk_ = &info;
  ChunkPayload p = parse_or_fail(
      [&] { return type == kOldCreatorChunk ? ChunkPayload(parse_creator(payload(left))) : named_payload(info, left); });
  if (const auto *g = std::get_if<GridMap>(&p); g != nullptr && opts_.check_cells) check_cells(*g);
  chunk_ = nullptr;
  return FoundChunk{std::move(info), std::move(p)};
}

std::optional<GridMapHeader> Reader::read_first_header(const std::string *name) {
  ChunkInfo info;
  uint64_t left = 0;
  if (!seek_first(kGridmapChunk, name, &info, &left)) return std::nullopt;
  chunk_ = &info;
  const GridMap g = read_gridmap_header(left);
  chunk_ = nullptr;
  return GridMapHeader{std::move(info), g.size_x, g.size_y, g.resolution};
}

// The comments and id only; true when the id is CARMEN's.
bool Reader::check_id_only() {
  try {
    read_comments();
    read_id();
    return true;
  } catch (...) {
    return false;
  }
}

// One chunk whose header was read: parsed into map_, deferred or skipped.
void Reader::read_chunk(ChunkInfo &info, uint64_t left) {
  chunk_ = &info;
  if (headers_only_) {
    pass(info, left);
  } else if (info.named() && opts_.named_chunks == NamedChunkReading::Index) {
    info.deferred = is_named_kind(info.base_type());
    pass(info, left);
    map_.unknown_chunks += !info.deferred;
  } else {
    info.used = parse_or_fail([&] { return info.named() ? read_named(info, left) : read_unnamed(info, left); });
    if (!info.used) {
      pass(info, left);
      ++map_.unknown_chunks;
    }
  }
  chunk_ = nullptr;
}

// False (nothing read) for unknown kinds and repeats: CARMEN uses the first.
bool Reader::read_unnamed(const ChunkInfo &info, uint64_t left) {
  switch (info.base_type()) {
    case kGridmapChunk: return !map_.gridmap && (map_.gridmap = read_gridmap(left), true);
    case kCreatorChunk: return !map_.creator && (map_.creator = parse_creator(payload(left)), true);
    case kOldCreatorChunk:
      return !old_creator_ && (left == 174 || left == 178) && (old_creator_ = parse_creator(payload(left)), true);
    case kGlobalOffsetChunk: return !map_.offset && (map_.offset = parse_offset(payload(left)), true);
    case kPlacesChunk: return !map_.places && (map_.places = parse_places(payload(left)), true);
    case kOfflimitsChunk: return !map_.offlimits && (map_.offlimits = read_offlimits(info, left, true), true);
    case kLaserscansChunk: return !map_.laserscans && (map_.laserscans = parse_laserscans(payload(left)), true);
    default: return false;
  }
}

bool Reader::read_named(const ChunkInfo &info, uint64_t left) {
  if (!is_named_kind(info.base_type())) return false;
  map_.named.push_back(NamedChunk{info.name, named_payload(info, left)});
  return true;
}

ChunkPayload Reader::named_payload(const ChunkInfo &info, uint64_t left) {
  switch (info.base_type()) {
    case kGridmapChunk: return read_gridmap(left);
    case kCreatorChunk: return parse_creator(payload(left));
    case kGlobalOffsetChunk: return parse_offset(payload(left));
    case kPlacesChunk: return parse_places(payload(left));
    case kOfflimitsChunk: return read_offlimits(info, left, true);
    default: return parse_laserscans(payload(left));
  }
}

// Past a chunk that is not read: by its size, but an OFFLIMITS chunk to
// where it really ends, and a GRIDMAP cut short as read_gridmap would
// accept it. Nothing is reported but damage.
void Reader::pass(const ChunkInfo &info, uint64_t left) {
  switch (info.base_type()) {
    case kOfflimitsChunk: read_offlimits(info, left, false); break;
    case kGridmapChunk: pass_gridmap(left); break;
    default: skip(left);
  }
}

// The cells of every gridmap read, in file order.
void Reader::check_kept_cells() {
  size_t next_named = 0;
  for (const ChunkInfo &info : grid_chunks_) {
    chunk_ = &info;
    if (!info.named()) {
      check_cells(*map_.gridmap);
      continue;
    }
    while (!std::holds_alternative<GridMap>(map_.named[next_named].payload) ||
           map_.named[next_named].name != info.name)
      ++next_named;
    check_cells(std::get<GridMap>(map_.named[next_named++].payload));
  }
  chunk_ = nullptr;
}

void Reader::read_comments() {
  size_t total = 0;
  while (in_.peek() == '#') {
    in_.get();
    std::string line;
    int c;
    while ((c = in_.get()) >= 0 && c != '\n') {
      if (line.size() >= kMaxCommentLine) {
        fail("has a comment line longer than " + std::to_string(kMaxCommentLine) + " bytes (near byte " +
             std::to_string(in_.pos()) + "): not a CARMEN map");
      }
      line.push_back(static_cast<char>(c));
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    total += line.size() + 2;
    if (total > kMaxCommentBytes) fail("has over 1 MiB of comment lines: not a CARMEN map");
    map_.comments.push_back(std::move(line));
  }
}

void Reader::read_id() {
  unsigned char id[kMapIdLength];
  const int64_t at = in_.pos();
  const size_t got = in_.read(id, sizeof id);
  if (got == 0) {
    const std::string damage = in_.stream_error();
    if (!damage.empty()) fail(damage);
    fail(at == 0
             ? std::string("is empty: not a CARMEN map file")
             : "ends after its comment lines: there is no CARMENMAPFILEv020 id, so it is not a CARMEN map");
  }
  const std::string text(reinterpret_cast<const char *>(id), got);
  if (got >= 2 && id[0] == 0x1f && id[1] == 0x8b) {
    fail(std::string("holds gzip-compressed data where the CARMENMAPFILEv020 id should be: ") +
         (in_.compressed() ? "it was compressed twice" : "name it .gz to read it"));
  }
  const size_t label_len = std::strlen(kMapLabel);
  if (got < label_len || text.compare(0, label_len, kMapLabel) != 0) {
    fail("is not a CARMEN map file: no CARMENMAPFILEv020 id at byte " + std::to_string(at));
  }
  if (got < sizeof id) fail("is cut short: it ends inside its CARMENMAPFILEv020 id");
  if (text.compare(label_len, std::string::npos, kMapVersion) != 0) {
    fail("has map format version \"" + printable(text.substr(label_len)) + "\"; only " + kMapVersion +
         " is supported");
  }
}

// False at the clean end of the data.
bool Reader::read_chunk_header(ChunkInfo *info, uint64_t *left) {
  info->offset = in_.pos();
  const int type = in_.get();
  if (type < 0) {
    const std::string damage = in_.stream_error();
    if (!damage.empty()) fail(damage + " (after byte " + std::to_string(in_.pos()) + ")");
    return false;
  }
  info->type = type;
  chunk_ = info;
  unsigned char sz[4];
  const size_t got = in_.read(sz, 4);
  if (got < 4) fail_short("its header");
  info->size = get_i32(sz);
  if (info->size < 10) {
    fail("has size " + std::to_string(info->size) +
         ", less than its 10-byte description: the file is damaged");
  }
  // A GRIDMAP may be cut short and an OFFLIMITS chunk may end before its
  // size says (CARMEN's layouts): their readers judge what is there, and
  // allocate no more than it.
  const int64_t rem = in_.remaining();
  const bool may_end_early = info->base_type() == kGridmapChunk || info->base_type() == kOfflimitsChunk;
  if (rem >= 0 && info->size > rem && !may_end_early) fail_remain();
  char desc[10];
  const size_t dgot = in_.read(desc, 10);
  if (dgot < 10) fail_short("its description");
  info->description.assign(desc, 10);
  *left = static_cast<uint64_t>(info->size) - 10;
  if (info->named()) {
    std::string name;
    // CARMEN's named off-limits writer leaves the name out of the size:
    // there the name may run past it (decode_offlimits_payload).
    const bool sized_name = info->base_type() != kOfflimitsChunk;
    while (true) {
      if (*left == 0 && sized_name) fail("has a name that runs past the end of the chunk (no NUL)");
      const int c = in_.get();
      if (c < 0) fail_short("its name");
      if (*left > 0) --*left;
      if (c == 0) break;
      if (name.size() + 1 >= kMaxChunkName) {
        fail("has a name longer than " + std::to_string(kMaxChunkName - 1) + " bytes: the file is damaged");
      }
      name.push_back(static_cast<char>(c));
    }
    info->name = std::move(name);
  }
  return true;
}

void Reader::skip(uint64_t n) {
  const uint64_t got = in_.skip(n);
  if (got < n) fail_short("its payload");
}

}  // namespace map_read

using map_read::Input;
using map_read::Reader;
using map_read::ReadMode;
using map_read::kReadPiece;

MapFile read_map_file(const std::string &path) { return read_map_file(path, MapReadOptions{}); }

MapFile read_map_file(const std::string &path, const MapReadOptions &options) {
  Reader r(path, options, ReadMode::Full);
  return r.run();
}

NamedChunk read_named_chunk(const std::string &path, const ChunkInfo &chunk, const MapReadOptions &options) {
  Reader r(path, options, ReadMode::Full);
  return r.read_named_at(chunk);
}

std::vector<ChunkInfo> list_map_chunks(const std::string &path) {
  Reader r(path, MapReadOptions{}, ReadMode::HeadersOnly);
  return r.run().chunks;
}

std::optional<ChunkInfo> find_first_chunk(const std::string &path, int type, const std::string *name) {
  Reader r(path, MapReadOptions{}, ReadMode::HeadersOnly);
  return r.find_first(type & ~kNamedChunkFlag, name);
}

std::optional<FoundChunk> read_first_chunk(const std::string &path, int type, const std::string *name,
                                           const MapReadOptions &options) {
  Reader r(path, options, ReadMode::Full);
  return r.read_first(type & ~kNamedChunkFlag, name);
}

std::optional<GridMapHeader> read_first_gridmap_header(const std::string &path, const std::string *name) {
  Reader r(path, MapReadOptions{}, ReadMode::HeadersOnly);
  return r.read_first_header(name);
}

bool is_map_file(const std::string &path) {
  try {
    Reader r(path, MapReadOptions{}, ReadMode::HeadersOnly);
    return r.check_id_only();
  } catch (...) {
    return false;
  }
}

std::string read_chunk_body(const std::string &path, const ChunkInfo &chunk) {
  if (chunk.size < 10) throw FileError(path, "chunk at offset " + std::to_string(chunk.offset) + " is too short");
  Input in(path);
  const uint64_t start = static_cast<uint64_t>(chunk.offset) + 5;  // type byte and size field
  if (in.skip(start) != start) throw FileError(path, "ends before the chunk at " + std::to_string(chunk.offset));
  const size_t want = static_cast<size_t>(chunk.size);
  // A plain file's size bounds what it can hold; a gzip stream's (or a
  // pipe's) does not, so there the size is held to MapReadOptions'
  // max_kept_bytes, as read_map_file holds it.
  const int64_t rem = in.remaining();
  if (rem >= 0 && uint64_t(chunk.size) > uint64_t(rem)) {
    throw FileError(path, "the chunk at offset " + std::to_string(chunk.offset) + " claims " +
                              std::to_string(chunk.size) + " bytes but only " + std::to_string(rem) +
                              " remain in the file: it is truncated or damaged");
  }
  const uint64_t limit = MapReadOptions{}.max_kept_bytes;
  if (rem < 0 && uint64_t(chunk.size) > limit) {
    throw FileError(path, "the chunk at offset " + std::to_string(chunk.offset) + " claims " +
                              std::to_string(chunk.size) + " bytes, more than the " +
                              std::to_string(limit >> 20) + " MiB read from a " +
                              (in.compressed() ? "gzip file" : "stream") +
                              " whose size cannot vouch for it: refused rather than allocated" +
                              (in.compressed() ? " (gunzip the map to read it)" : ""),
                    ErrorCode::TooLarge);
  }
  // Read in pieces when the size is not known: a gzip stream can still end
  // early, and then only what it held was allocated.
  std::string body;
  if (rem >= 0) body.reserve(want);
  while (body.size() < want) {
    const size_t k = std::min(want - body.size(), kReadPiece);
    const size_t old = body.size();
    body.resize(old + k);
    if (in.read(&body[old], k) != k) {
      const std::string why = in.stream_error();
      throw FileError(path, why.empty() ? "ends inside the chunk at offset " + std::to_string(chunk.offset) : why);
    }
  }
  return body;
}

}  // namespace carmen
