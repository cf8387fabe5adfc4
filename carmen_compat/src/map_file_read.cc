// CARMEN map files: the defensive reader (map_file.h). Every size a file
// claims is checked against what it holds before memory is allocated for it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "map_file_bytes.h"
#include "map_file_input.h"

namespace carmen {
namespace {

using namespace map_bytes;
using map_read::Input;

constexpr size_t kMaxCommentLine = 4096;         // bytes per comment line
constexpr size_t kMaxCommentBytes = 1 << 20;     // whole comment block
constexpr size_t kMaxChunkName = 256;            // bytes of a chunk name, NUL included
constexpr size_t kReadPiece = size_t{16} << 20;  // growth step when the size is not known

// ---------------------------------------------------------------------------
// Cursor: bounds-checked parsing of a chunk payload held in memory.
// ---------------------------------------------------------------------------
struct ParseError {
  std::string what;
};

class Cursor {
 public:
  Cursor(const unsigned char *p, size_t n) : p_(p), n_(n) {}
  size_t left() const { return n_ - i_; }
  const unsigned char *take(size_t k, const char *what) {
    if (k > left()) {
      throw ParseError{std::string("ends inside ") + what + " (needs " + std::to_string(k) + " more bytes, " +
                       std::to_string(left()) + " left)"};
    }
    const unsigned char *r = p_ + i_;
    i_ += k;
    return r;
  }
  int32_t i32(const char *what) { return get_i32(take(4, what)); }
  float f32(const char *what) { return get_f32(take(4, what)); }
  double f64(const char *what) { return get_f64(take(8, what)); }
  // A count whose items take at least `item_bytes` each: checked against what is left.
  size_t count(size_t item_bytes, const char *what) {
    const int32_t n = i32(what);
    if (n < 0) throw ParseError{std::string("has a negative ") + what + " (" + std::to_string(n) + ")"};
    if (item_bytes > 0 && static_cast<uint64_t>(n) * item_bytes > left()) {
      throw ParseError{std::string("claims ") + std::to_string(n) + " " + what + " but holds only " +
                       std::to_string(left()) + " more bytes"};
    }
    return static_cast<size_t>(n);
  }
  void expect_end() const {
    if (left() != 0) {
      throw ParseError{"has " + std::to_string(left()) + " unexpected bytes at its end"};
    }
  }

 private:
  const unsigned char *p_;
  size_t n_;
  size_t i_ = 0;
};

// Text of a fixed-width field: up to the first NUL, trailing spaces removed.
std::string field_text(const unsigned char *p, size_t width) {
  size_t n = 0;
  while (n < width && p[n] != 0) ++n;
  while (n > 0 && p[n - 1] == ' ') --n;
  return std::string(reinterpret_cast<const char *>(p), n);
}

// ---------------------------------------------------------------------------
// Payload parsers (payload = the bytes after description and name)
// ---------------------------------------------------------------------------
CreatorInfo parse_creator(const std::vector<unsigned char> &b) {
  // user[10], time_t, origin[80], description[80]
  if (b.size() != 174 && b.size() != 178) {
    throw ParseError{"has " + std::to_string(b.size()) +
                     " payload bytes; a creator needs 174 (32-bit time_t) or 178 (64-bit time_t)"};
  }
  CreatorInfo c;
  c.time_bytes = static_cast<int>(b.size()) - 170;
  Cursor cur(b.data(), b.size());
  c.user = field_text(cur.take(10, "the user name"), 10);
  if (c.time_bytes == 4) {
    c.time = get_i32(cur.take(4, "the time"));
  } else {
    const uint64_t u = get_u64(cur.take(8, "the time"));
    std::memcpy(&c.time, &u, 8);
  }
  c.origin = field_text(cur.take(80, "the origin"), 80);
  c.description = field_text(cur.take(80, "the description"), 80);
  return c;
}

GlobalOffset parse_offset(const std::vector<unsigned char> &b) {
  if (b.size() != 24) {
    throw ParseError{"has " + std::to_string(b.size()) + " payload bytes; an offset needs 24 (3 doubles)"};
  }
  Cursor cur(b.data(), b.size());
  GlobalOffset o;
  o.x = cur.f64("x");
  o.y = cur.f64("y");
  o.theta = cur.f64("theta");
  return o;
}

PlaceList parse_places(const std::vector<unsigned char> &b) {
  Cursor cur(b.data(), b.size());
  const size_t n = cur.count(4 + 20 + 8, "places");
  PlaceList places;
  places.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    Place p;
    p.type = cur.i32("a place type");
    p.name = field_text(cur.take(20, "a place name"), 20);
    p.x = cur.f32("a place");
    p.y = cur.f32("a place");
    if (p.type == kNamedPose || p.type == kLocalizationInit) p.theta = cur.f32("a place");
    if (p.type == kLocalizationInit) {
      p.x_std = cur.f32("a place");
      p.y_std = cur.f32("a place");
      p.theta_std = cur.f32("a place");
    }
    if (p.type != kNamedPosition && p.type != kNamedPose && p.type != kLocalizationInit) {
      throw ParseError{"has place " + std::to_string(i) + " with unknown type " + std::to_string(p.type) +
                       " (expected 0 position, 1 pose or 2 localization init, as CARMEN's map.h)"};
    }
    places.push_back(std::move(p));
  }
  cur.expect_end();
  return places;
}

LaserScanList parse_laserscans(const std::vector<unsigned char> &b) {
  Cursor cur(b.data(), b.size());
  const size_t n = cur.count(16, "scans");
  LaserScanList scans;
  scans.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    LaserScan s;
    s.x = cur.f32("a scan pose");
    s.y = cur.f32("a scan pose");
    s.theta = cur.f32("a scan pose");
    const size_t nr = cur.count(4, "readings");
    s.ranges.resize(nr);
    const unsigned char *p = cur.take(4 * nr, "the readings");
    for (size_t k = 0; k < nr; ++k) s.ranges[k] = get_f32(p + 4 * k);
    scans.push_back(std::move(s));
  }
  cur.expect_end();
  return scans;
}

// ---------------------------------------------------------------------------
// Source: the Input, with bytes given back. An OFFLIMITS chunk in CARMEN's
// layout ends before its size field says; what was read past its end is the
// next chunk's and is read again from here.
// ---------------------------------------------------------------------------
class Source {
 public:
  explicit Source(const std::string &path) : in_(path) {}
  const std::string &path() const { return in_.path(); }
  bool compressed() const { return in_.compressed(); }
  std::string stream_error() const { return in_.stream_error(); }
  int64_t pos() const { return in_.pos() - int64_t(held()); }
  int64_t remaining() const {
    const int64_t r = in_.remaining();
    return r < 0 ? r : r + int64_t(held());
  }
  int peek() { return held() > 0 ? back_[at_] : in_.peek(); }
  int get() { return held() > 0 ? back_[at_++] : in_.get(); }
  size_t read(void *dst, size_t n) {
    const size_t k = std::min(n, held());
    if (k > 0) std::memcpy(dst, back_.data() + at_, k);
    at_ += k;
    return k + (n > k ? in_.read(static_cast<unsigned char *>(dst) + k, n - k) : 0);
  }
  uint64_t skip(uint64_t n) {
    const size_t k = static_cast<size_t>(std::min<uint64_t>(n, held()));
    at_ += k;
    return k + (n > k ? in_.skip(n - k) : 0);
  }
  // The bytes [p, p + n) are read again before anything else.
  void give_back(const unsigned char *p, size_t n) {
    std::vector<unsigned char> b(p, p + n);
    b.insert(b.end(), back_.begin() + static_cast<std::ptrdiff_t>(at_), back_.end());
    back_ = std::move(b);
    at_ = 0;
  }

 private:
  size_t held() const { return back_.size() - at_; }
  Input in_;
  std::vector<unsigned char> back_;
  size_t at_ = 0;
};

// A GRIDMAP chunk whose data ends inside its cells is read when at least
// half of its cell bytes are there, or all but this many: what is allocated
// for it stays within twice what the file holds (plus 1 MiB).
constexpr uint64_t kShortGridSlack = uint64_t{1} << 20;

std::string byte_count(uint64_t n) { return std::to_string(n) + (n == 1 ? " byte" : " bytes"); }

// ---------------------------------------------------------------------------
// The reader
// ---------------------------------------------------------------------------
enum class ReadMode { Full, HeadersOnly };

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

class Reader {
 public:
  Reader(const std::string &path, const MapReadOptions &opts, ReadMode mode)
      : in_(path), opts_(opts), headers_only_(mode == ReadMode::HeadersOnly) {}

  MapFile run() {
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
  NamedChunk read_named_at(const ChunkInfo &listed) {
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
  bool seek_first(int type, const std::string *name, ChunkInfo *info, uint64_t *left) {
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

  std::optional<ChunkInfo> find_first(int type, const std::string *name) {
    ChunkInfo info;
    uint64_t left = 0;
    if (!seek_first(type, name, &info, &left)) return std::nullopt;
    chunk_ = nullptr;
    return info;
  }

  std::optional<FoundChunk> read_first(int type, const std::string *name) {
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

  std::optional<GridMapHeader> read_first_header(const std::string *name) {
    ChunkInfo info;
    uint64_t left = 0;
    if (!seek_first(kGridmapChunk, name, &info, &left)) return std::nullopt;
    chunk_ = &info;
    const GridMap g = read_gridmap_header(left);
    chunk_ = nullptr;
    return GridMapHeader{std::move(info), g.size_x, g.size_y, g.resolution};
  }

  // The comments and id only; true when the id is CARMEN's.
  bool check_id_only() {
    try {
      read_comments();
      read_id();
      return true;
    } catch (...) {
      return false;
    }
  }

 private:
  template <typename F>
  std::invoke_result_t<F> parse_or_fail(F &&parse) {
    try {
      return parse();
    } catch (const ParseError &e) {
      fail(e.what);
    }
  }

  // One chunk whose header was read: parsed into map_, deferred or skipped.
  void read_chunk(ChunkInfo &info, uint64_t left) {
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
  bool read_unnamed(const ChunkInfo &info, uint64_t left) {
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

  bool read_named(const ChunkInfo &info, uint64_t left) {
    if (!is_named_kind(info.base_type())) return false;
    map_.named.push_back(NamedChunk{info.name, named_payload(info, left)});
    return true;
  }

  ChunkPayload named_payload(const ChunkInfo &info, uint64_t left) {
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
  void pass(const ChunkInfo &info, uint64_t left) {
    switch (info.base_type()) {
      case kOfflimitsChunk: read_offlimits(info, left, false); break;
      case kGridmapChunk: pass_gridmap(left); break;
      default: skip(left);
    }
  }

  // The cells of every gridmap read, in file order.
  void check_kept_cells() {
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

  // "the GRIDMAP chunk at byte 540 " (with its name), or "the file ".
  std::string where() const {
    if (chunk_ == nullptr) return "the file ";
    return "the " + chunk_type_name(chunk_->type) + " chunk at byte " + std::to_string(chunk_->offset) +
           (chunk_->named() && !chunk_->name.empty() ? " (named \"" + printable(chunk_->name) + "\")" : "") + " ";
  }

  [[noreturn]] void fail(const std::string &msg, ErrorCode code = ErrorCode::BadInput) const {
    throw FileError(in_.path(), where() + msg, code);
  }

  // A warning about the chunk being read: to MapReadOptions::on_warning, or stderr.
  void warn(const std::string &msg) const {
    const std::string text = FileError::format(in_.path(), 0, "warning: " + where() + msg);
    if (opts_.on_warning) {
      opts_.on_warning(text);
    } else {
      std::fprintf(stderr, "%s\n", text.c_str());
    }
  }

  // Called when fewer bytes came than were needed.
  [[noreturn]] void fail_short(const std::string &what) const {
    const std::string damage = in_.stream_error();
    if (!damage.empty()) fail(damage + " (at byte " + std::to_string(in_.pos()) + ", inside " + what + ")");
    if (chunk_ != nullptr && chunk_->size > 0) {
      const int64_t present = in_.pos() - (chunk_->offset + 5);
      fail("is cut short: it claims " + std::to_string(chunk_->size) + " bytes but the file ends after " +
           std::to_string(present) + " of them (inside " + what + ")");
    }
    fail("is cut short: the file ends inside " + what);
  }

  // A plain file that ends before the chunk does: what is in it, from the
  // chunk's size field on.
  [[noreturn]] void fail_remain(const std::string &why = "") const {
    const int64_t rem = in_.pos() + in_.remaining() - (chunk_->offset + 5);
    fail("claims " + std::to_string(chunk_->size) + " bytes but only " + std::to_string(rem) +
         " remain in the file: it is truncated or damaged" + why);
  }

  // Data that ends inside the chunk being read: the message of a plain
  // file's size check, or (a stream) where the data ended.
  [[noreturn]] void fail_cut(const std::string &what, const std::string &why = "") const {
    if (!in_.stream_error().empty() || in_.remaining() < 0) fail_short(what + why);
    fail_remain(why);
  }

  void read_comments() {
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

  void read_id() {
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
  bool read_chunk_header(ChunkInfo *info, uint64_t *left) {
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

  void skip(uint64_t n) {
    const uint64_t got = in_.skip(n);
    if (got < n) fail_short("its payload");
  }

  // Reads `n` bytes in bounded pieces: a short file fails before the
  // claimed size is allocated (the size was already checked for plain files).
  std::vector<unsigned char> payload(uint64_t n) {
    keep(n);
    std::vector<unsigned char> out;
    const bool known = in_.remaining() >= 0;
    if (known) out.reserve(static_cast<size_t>(n));
    while (out.size() < n) {
      const size_t want = known ? static_cast<size_t>(n - out.size())
                                : static_cast<size_t>(std::min<uint64_t>(kReadPiece, n - out.size()));
      const size_t old = out.size();
      out.resize(old + want);
      const size_t got = in_.read(out.data() + old, want);
      if (got < want) {
        fail_short("its payload");
      }
    }
    return out;
  }

  // Counts bytes about to be kept against MapReadOptions::max_kept_bytes.
  void keep(uint64_t bytes) {
    kept_ += bytes;
    if (kept_ > opts_.max_kept_bytes)
      fail("makes the map hold more than " + std::to_string(opts_.max_kept_bytes >> 20) +
           " MiB of chunk data (MapReadOptions::max_kept_bytes): refused rather than allocated",
           ErrorCode::TooLarge);
  }

  // The size and resolution, checked against the chunk size; the cells are
  // left unread.
  GridMap read_gridmap_header(uint64_t left) {
    if (left < 12) fail("has " + std::to_string(left) + " payload bytes, too few for the map size");
    unsigned char hdr[12];
    const size_t hgot = in_.read(hdr, 12);
    if (hgot < 12) fail_short("the map size");
    return gridmap_header(hdr, left);
  }

  GridMap gridmap_header(const unsigned char *hdr, uint64_t left) {
    GridMap g;
    g.size_x = get_i32(hdr);
    g.size_y = get_i32(hdr + 4);
    const float res = get_f32(hdr + 8);
    g.resolution = res;
    if (g.size_x <= 0 || g.size_y <= 0) {
      fail("has an invalid map size " + std::to_string(g.size_x) + " x " + std::to_string(g.size_y));
    }
    if (!std::isfinite(res) || res <= 0) {
      std::ostringstream os;
      os << "has an invalid resolution " << res << " (must be a positive number of metres per cell)";
      fail(os.str());
    }
    const uint64_t ncells = uint64_t(g.size_x) * uint64_t(g.size_y);
    if (ncells > (left - 12) / 4 || ncells * 4 != left - 12) {  // (the first test avoids overflow)
      const uint64_t needed = uint64_t(chunk_->size) - left + 12 + ncells * 4;  // ncells < 2^62
      fail("has size " + std::to_string(chunk_->size) + " but its " + std::to_string(g.size_x) + " x " +
           std::to_string(g.size_y) + " cells need a size of " + std::to_string(needed) +
           ": the file is damaged");
    }
    return g;
  }

  GridMap read_gridmap(uint64_t left) {
    if (left >= 12) keep(left);
    GridMap g = read_gridmap_header(left);
    const uint64_t ncells = uint64_t(g.size_x) * uint64_t(g.size_y);
    // ncells * 4 + 22 <= INT32_MAX here, so ncells < 2^29.
    const int64_t rem = in_.remaining();
    const bool known = rem >= 0;
    if (known && uint64_t(rem) < ncells * 4) check_short(uint64_t(rem), ncells * 4);  // before allocating
    if (known) g.cells.reserve(static_cast<size_t>(ncells));
    const size_t piece = kReadPiece / 4;
    uint64_t present = ncells * 4;  // cell bytes in the file
    while (g.cells.size() < ncells) {
      const size_t old = g.cells.size();
      const size_t want = known ? static_cast<size_t>(ncells) - old
                                : std::min<size_t>(piece, static_cast<size_t>(ncells) - old);
      g.cells.resize(old + want);
      const size_t got = in_.read(g.cells.data() + old, want * 4);
      if (got < want * 4) {
        if (!in_.stream_error().empty()) fail_short("the cells");
        present = uint64_t(old) * 4 + got;
        check_short(present, ncells * 4);
        // The bytes that came stay where they are and the rest are zero (resize's
        // 0.0f), as in CARMEN's calloc()ed grid after its one fread().
        break;
      }
    }
    if (!host_is_little_endian()) {
      for (float &v : g.cells) v = get_f32(reinterpret_cast<const unsigned char *>(&v));
    }
    if (present < ncells * 4) read_short(g, present);
    if (opts_.check_cells) grid_chunks_.push_back(*chunk_);  // checked once the layout is known good
    return g;
  }

  // Refuses a gridmap cut short of which too little is there to read the
  // rest as unknown (kShortGridSlack): a few bytes claiming gigabytes.
  void check_short(uint64_t present, uint64_t wanted) const {
    if (wanted - present <= std::max(present, kShortGridSlack)) return;
    fail_cut("the cells", "; fewer than half of its cells are there, too few to read the rest as unknown");
  }

  // The cells the file lacks, as CARMEN renders a gridmap cut short: its
  // reader fread()s into a calloc()ed grid, so a missing byte is a zero: the
  // missing cells are 0 (free), and a cell only partly there keeps the bytes
  // that came (the readers' check of cell values judges it like any other).
  void read_short(GridMap &g, uint64_t present) const {
    const uint64_t ncells = uint64_t(g.size_x) * uint64_t(g.size_y);
    const uint64_t missing = ncells * 4 - present;
    const uint64_t unread = ncells - present / 4;
    g.cells.resize(static_cast<size_t>(ncells), 0.0f);
    warn("is " + byte_count(missing) + " short: it claims " + std::to_string(chunk_->size) +
         " bytes but the file ends after " + std::to_string(uint64_t(chunk_->size) - missing) +
         " of them; its last " + std::to_string(unread) + " of " + std::to_string(ncells) +
         " cells (x-major order) are missing and read as CARMEN's reader leaves them: zero bytes (0, free)" +
         (present % 4 != 0 ? ", the first after the bytes that came" : ""));
  }

  // Past a GRIDMAP chunk that is not read: a chunk cut short passes as
  // read_gridmap would read it (its header sound, enough of its cells there).
  void pass_gridmap(uint64_t left) {
    unsigned char hdr[12];
    const size_t head = static_cast<size_t>(std::min<uint64_t>(left, 12));
    if (in_.read(hdr, head) < head) fail_short("its payload");
    const uint64_t got = in_.skip(left - head);
    if (got == left - head) return;
    if (!in_.stream_error().empty() || head < 12) fail_short("its payload");
    gridmap_header(hdr, left);
    check_short(got, left - 12);
  }

  // An OFFLIMITS chunk, in the layout its size field gives or in CARMEN's
  // (decode_offlimits_payload); the input is left where it really ends.
  // `read`: the chunk is asked for, so damage is an error and CARMEN's
  // layout a warning. Otherwise it is passed, and passed by its size when it
  // is in neither layout, as any chunk; one larger than 16 MiB is passed by
  // its size (CARMEN's layouts are looked for within 16 MiB).
  OffLimits read_offlimits(const ChunkInfo &info, uint64_t left, bool read) {
    if (read) {
      keep(left);
    } else if (left > kReadPiece) {
      skip(left);
      return {};
    }
    const int64_t start = in_.pos();
    // Damage past the size field's end (a look at the next chunk) is left
    // for the reader of that chunk to report.
    const PayloadFetch fetch = [&](std::vector<unsigned char> &b, uint64_t want) {
      while (b.size() < want) {
        const size_t k = static_cast<size_t>(std::min<uint64_t>(want - b.size(), kReadPiece));
        const size_t old = b.size();
        b.resize(old + k);
        const size_t got = in_.read(b.data() + old, k);
        b.resize(old + got);
        if (got < k) {
          if (b.size() < left && !in_.stream_error().empty()) fail_short("its payload");
          return;
        }
      }
    };
    std::vector<unsigned char> bytes;
    const OffLimitsPayload d = decode_offlimits_payload(bytes, left, info.named(), fetch);
    const uint64_t end = d.ok ? d.length : left;
    if (!d.ok && (bytes.size() < left || !in_.stream_error().empty())) fail_cut("its payload");
    if (!d.ok && read) fail(d.error);
    if (bytes.size() > end) in_.give_back(bytes.data() + end, static_cast<size_t>(bytes.size() - end));
    if (read && d.carmen_layout) warn_carmen_layout(d, start);
    return d.offlimits;
  }

  void warn_carmen_layout(const OffLimitsPayload &d, int64_t start) const {
    std::string msg = "is laid out as CARMEN 0.7.4's writer lays it out, not as its size field (" +
                      std::to_string(chunk_->size) + ") says";
    if (d.lines_left_out > 0) {
      msg += ": " + std::to_string(d.lines_left_out) + " of its " +
             std::to_string(d.lines_left_out + d.offlimits.lines.size()) +
             " lines were counted but never written (the writer's line loop skips them)";
    }
    warn(msg + "; it ends at byte " + std::to_string(start + int64_t(d.length)));
  }

  void check_cells(const GridMap &g) {
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < g.cells.size(); ++i) {
      if (!valid_cell_value(g.cells[i])) {
        if (bad++ == 0) first = i;
      }
    }
    if (bad == 0) return;
    std::ostringstream os;
    os.precision(9);
    os << "holds invalid cell values: " << bad << " of " << g.cells.size()
       << " cells are not -1 (unknown), a probability in [0, 1] or an off-limits value in [2, 3]"
       << "; the first is cell (" << first / size_t(g.size_y) << ", " << first % size_t(g.size_y)
       << ") = " << g.cells[first] << ". The map is damaged";
    fail(os.str());
  }
  Source in_;
  MapReadOptions opts_;
  uint64_t kept_ = 0;  // chunk bytes kept so far
  bool headers_only_;
  MapFile map_;
  std::optional<CreatorInfo> old_creator_;  // from a code-0 chunk, used when no CREATOR exists
  const ChunkInfo *chunk_ = nullptr;
  std::vector<ChunkInfo> grid_chunks_;  // gridmap chunks read, in file order
};

}  // namespace

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
