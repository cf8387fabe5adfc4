// CARMEN map files: a defensive reader and an atomic writer.
#include "carmen_compat/map_file.h"

#include <unistd.h>

#include <sys/stat.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "carmen/carmen_stdio.h"
#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"

namespace carmen {
namespace {

// ---------------------------------------------------------------------------
// Limits
// ---------------------------------------------------------------------------
constexpr size_t kMaxCommentLine = 4096;         // bytes per comment line
constexpr size_t kMaxCommentBytes = 1 << 20;     // whole comment block
constexpr size_t kMaxChunkName = 256;            // bytes of a chunk name, NUL included
constexpr size_t kReadPiece = size_t{16} << 20;  // growth step when the size is not known
constexpr int kCommentTextMax = 97;              // '#' + 97 + '\n' fits CARMEN's fgets(.., 100)

bool host_is_little_endian() {
  const uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

// ---------------------------------------------------------------------------
// Little-endian helpers
// ---------------------------------------------------------------------------
uint32_t get_u32(const unsigned char *p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
uint64_t get_u64(const unsigned char *p) { return uint64_t(get_u32(p)) | uint64_t(get_u32(p + 4)) << 32; }
int32_t get_i32(const unsigned char *p) {
  const uint32_t u = get_u32(p);
  int32_t v;
  std::memcpy(&v, &u, 4);
  return v;
}
float get_f32(const unsigned char *p) {
  const uint32_t u = get_u32(p);
  float v;
  std::memcpy(&v, &u, 4);
  return v;
}
double get_f64(const unsigned char *p) {
  const uint64_t u = get_u64(p);
  double v;
  std::memcpy(&v, &u, 8);
  return v;
}

void put_u32(std::string &s, uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void put_u64(std::string &s, uint64_t v) {
  for (int i = 0; i < 8; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void put_i32(std::string &s, int32_t v) {
  uint32_t u;
  std::memcpy(&u, &v, 4);
  put_u32(s, u);
}
void put_f32(std::string &s, float v) {
  uint32_t u;
  std::memcpy(&u, &v, 4);
  put_u32(s, u);
}
void put_f64(std::string &s, double v) {
  uint64_t u;
  std::memcpy(&u, &v, 8);
  put_u64(s, u);
}
// A fixed-width text field: cut to `width`, padded with `pad`.
void put_field(std::string &s, const std::string &text, size_t width, char pad) {
  const size_t n = std::min(text.size(), width);
  s.append(text, 0, n);
  s.append(width - n, pad);
}

int32_t checked_count(size_t n, const char *what) {
  if (n > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
    throw std::invalid_argument(std::string("too many ") + what + " for a CARMEN map chunk");
  }
  return static_cast<int32_t>(n);
}

// ---------------------------------------------------------------------------
// Input: a buffered byte stream over carmen_FILE that counts its position and
// knows how many bytes remain when the file is a plain regular file.
// ---------------------------------------------------------------------------
class Input {
 public:
  explicit Input(const std::string &path) : path_(path), buf_(1 << 16) {
    struct stat st;
    if (::stat(path.c_str(), &st) != 0) {
      throw FileError(path, std::string("cannot open: ") + std::strerror(errno));
    }
    if (S_ISDIR(st.st_mode)) throw FileError(path, "is a directory, not a map file");
    f_ = carmen_fopen(path.c_str(), "rb");
    if (f_ == nullptr) throw FileError(path, std::string("cannot open: ") + std::strerror(errno));
    if (!f_->compressed && S_ISREG(st.st_mode)) size_ = static_cast<int64_t>(st.st_size);
  }
  ~Input() {
    if (f_ != nullptr) carmen_fclose(f_);
  }
  Input(const Input &) = delete;
  Input &operator=(const Input &) = delete;

  const std::string &path() const { return path_; }
  bool compressed() const { return f_->compressed != 0; }
  int64_t pos() const { return pos_; }
  // Bytes left in a plain regular file; -1 when unknown (gzip, pipes).
  int64_t remaining() const { return size_ < 0 ? -1 : std::max<int64_t>(0, size_ - pos_); }

  int peek() {
    if (head_ == tail_ && !fill()) return -1;
    return buf_[head_];
  }
  int get() {
    const int c = peek();
    if (c >= 0) {
      ++head_;
      ++pos_;
    }
    return c;
  }
  // Reads up to n bytes; fewer only at the end of the data (or on damage).
  size_t read(void *dst, size_t n) {
    auto *out = static_cast<unsigned char *>(dst);
    size_t done = 0;
    while (done < n) {
      if (head_ < tail_) {
        const size_t k = std::min(n - done, tail_ - head_);
        std::memcpy(out + done, buf_.data() + head_, k);
        head_ += k;
        done += k;
        continue;
      }
      if (eof_) break;
      if (n - done >= buf_.size()) {  // large read: straight into the destination
        const size_t want = std::min(n - done, size_t{1} << 30);
        const size_t got = carmen_fread(out + done, 1, want, f_);
        done += got;
        if (got < want) eof_ = true;
        continue;
      }
      if (!fill()) break;
    }
    pos_ += static_cast<int64_t>(done);
    return done;
  }
  // Discards up to n bytes; returns how many were there.
  uint64_t skip(uint64_t n) {
    uint64_t done = 0;
    while (done < n) {
      if (head_ == tail_ && !fill()) break;
      const size_t k = static_cast<size_t>(std::min<uint64_t>(n - done, tail_ - head_));
      head_ += k;
      done += k;
    }
    pos_ += static_cast<int64_t>(done);
    return done;
  }
  // A read error, or for gzip a corrupt/truncated stream; "" when none.
  std::string stream_error() const {
    if (f_->compressed) {
      int err = Z_OK;
      const char *msg = gzerror(f_->comp_fp, &err);
      if (err != Z_OK && err != Z_STREAM_END) {
        return std::string("cannot be read: the gzip data is corrupt or cut short (zlib: ") +
               (msg ? msg : "?") + ")";
      }
      return {};
    }
    return carmen_ferror(f_) ? std::string("cannot be read: ") + std::strerror(errno) : std::string();
  }

 private:
  bool fill() {
    if (eof_) return false;
    const size_t got = carmen_fread(buf_.data(), 1, buf_.size(), f_);
    head_ = 0;
    tail_ = got;
    if (got < buf_.size()) eof_ = true;
    return got > 0;
  }

  std::string path_;
  carmen_FILE *f_ = nullptr;
  std::vector<unsigned char> buf_;
  size_t head_ = 0, tail_ = 0;
  int64_t pos_ = 0;
  int64_t size_ = -1;
  bool eof_ = false;
};

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

// A name for a message: non-printable bytes as '?', at most 40 characters.
std::string printable(const std::string &s) {
  std::string r;
  for (char ch : s.substr(0, 40)) {
    const auto u = static_cast<unsigned char>(ch);
    r.push_back(u >= 32 && u < 127 ? ch : '?');
  }
  if (s.size() > 40) r += "...";
  return r;
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

OffLimits parse_offlimits(const std::vector<unsigned char> &b) {
  Cursor cur(b.data(), b.size());
  OffLimits o;
  const size_t np = cur.count(8, "points");
  o.points.resize(np);
  for (auto &pt : o.points) {
    pt.x = cur.i32("a point");
    pt.y = cur.i32("a point");
  }
  const size_t nl = cur.count(16, "lines");
  o.lines.resize(nl);
  for (auto &l : o.lines) {
    l.x1 = cur.i32("a line");
    l.y1 = cur.i32("a line");
    l.x2 = cur.i32("a line");
    l.y2 = cur.i32("a line");
  }
  const size_t nr = cur.count(16, "rectangles");
  o.rects.resize(nr);
  for (auto &r : o.rects) {
    r.x1 = cur.i32("a rectangle");
    r.y1 = cur.i32("a rectangle");
    r.x2 = cur.i32("a rectangle");
    r.y2 = cur.i32("a rectangle");
  }
  cur.expect_end();
  return o;
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
// The reader
// ---------------------------------------------------------------------------
class Reader {
 public:
  Reader(const std::string &path, const MapReadOptions &opts, bool headers_only)
      : in_(path), opts_(opts), headers_only_(headers_only) {}

  MapFile run() {
    read_comments();
    read_id();
    std::optional<CreatorInfo> old_creator;
    while (true) {
      ChunkInfo info;
      uint64_t left = 0;
      if (!read_chunk_header(&info, &left)) break;
      chunk_ = &info;
      const int base = info.base_type();
      bool used = false;
      try {
        if (headers_only_) {
          skip(left);
        } else if (info.named()) {
          used = read_named(base, info.name, left);
        } else {
          switch (base) {
            case kGridmapChunk: used = !map_.gridmap && (map_.gridmap = read_gridmap(left), true); break;
            case kCreatorChunk:
              used = !map_.creator && (map_.creator = parse_creator(payload(left)), true);
              break;
            case kOldCreatorChunk:
              if (!old_creator && (left == 174 || left == 178)) {
                old_creator = parse_creator(payload(left));
                used = true;
              }
              break;
            case kGlobalOffsetChunk:
              used = !map_.offset && (map_.offset = parse_offset(payload(left)), true);
              break;
            case kPlacesChunk:
              used = !map_.places && (map_.places = parse_places(payload(left)), true);
              break;
            case kOfflimitsChunk:
              used = !map_.offlimits && (map_.offlimits = parse_offlimits(payload(left)), true);
              break;
            case kLaserscansChunk:
              used = !map_.laserscans && (map_.laserscans = parse_laserscans(payload(left)), true);
              break;
            default: break;
          }
          if (!used) skip(left);
        }
      } catch (const ParseError &e) {
        fail(e.what);
      }
      if (!used && !headers_only_) ++map_.unknown_chunks;
      info.used = used;
      chunk_ = nullptr;
      map_.chunks.push_back(info);
    }
    if (!map_.creator && old_creator) {
      map_.creator = std::move(old_creator);
      map_.old_style_creator = true;
    }
    // Cell values last, so that a file damaged in its layout reports that.
    size_t next_named = 0;
    for (const ChunkInfo &info : grid_chunks_) {
      chunk_ = &info;
      const GridMap *g = nullptr;
      if (!info.named()) {
        g = &*map_.gridmap;
      } else {
        while (!std::holds_alternative<GridMap>(map_.named[next_named].payload) ||
               map_.named[next_named].name != info.name) {
          ++next_named;
        }
        g = &std::get<GridMap>(map_.named[next_named++].payload);
      }
      check_cells(*g);
    }
    chunk_ = nullptr;
    return std::move(map_);
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
  [[noreturn]] void fail(const std::string &msg) const {
    std::string where = "the file ";
    if (chunk_ != nullptr) {
      where = "the " + chunk_type_name(chunk_->type) + " chunk at byte " + std::to_string(chunk_->offset) +
              (chunk_->named() ? " (named \"" + printable(chunk_->name) + "\")" : "") + " ";
    }
    throw FileError(in_.path(), where + msg);
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
      std::string v = text.substr(label_len);
      for (char &ch : v) {
        if (static_cast<unsigned char>(ch) < 32 || static_cast<unsigned char>(ch) > 126) ch = '?';
      }
      fail("has map format version \"" + v + "\"; only " + kMapVersion + " is supported");
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
    const int64_t rem = in_.remaining();
    if (rem >= 0 && info->size > rem) {
      fail("claims " + std::to_string(info->size) + " bytes but only " + std::to_string(rem) +
           " remain in the file: it is truncated or damaged");
    }
    char desc[10];
    const size_t dgot = in_.read(desc, 10);
    if (dgot < 10) fail_short("its description");
    info->description.assign(desc, 10);
    *left = static_cast<uint64_t>(info->size) - 10;
    if (info->named()) {
      std::string name;
      while (true) {
        if (*left == 0) fail("has a name that runs past the end of the chunk (no NUL)");
        const int c = in_.get();
        if (c < 0) fail_short("its name");
        --*left;
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
           " MiB of chunk data (MapReadOptions::max_kept_bytes): refused rather than allocated");
  }

  GridMap read_gridmap(uint64_t left) {
    if (left < 12) fail("has " + std::to_string(left) + " payload bytes, too few for the map size");
    keep(left);
    unsigned char hdr[12];
    const size_t hgot = in_.read(hdr, 12);
    if (hgot < 12) fail_short("the map size");
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
    // ncells * 4 + 22 <= INT32_MAX here, so ncells < 2^29.
    const bool known = in_.remaining() >= 0;
    if (known) g.cells.reserve(static_cast<size_t>(ncells));
    const size_t piece = kReadPiece / 4;
    while (g.cells.size() < ncells) {
      const size_t old = g.cells.size();
      const size_t want = known ? static_cast<size_t>(ncells) - old
                                : std::min<size_t>(piece, static_cast<size_t>(ncells) - old);
      g.cells.resize(old + want);
      const size_t got = in_.read(g.cells.data() + old, want * 4);
      if (got < want * 4) {
        fail_short("the cells");
      }
    }
    if (!host_is_little_endian()) {
      for (float &v : g.cells) v = get_f32(reinterpret_cast<const unsigned char *>(&v));
    }
    if (opts_.check_cells) grid_chunks_.push_back(*chunk_);  // checked once the layout is known good
    return g;
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

  bool read_named(int base, const std::string &name, uint64_t left) {
    NamedChunk nc;
    nc.name = name;
    switch (base) {
      case kGridmapChunk: nc.payload = read_gridmap(left); break;
      case kCreatorChunk: nc.payload = parse_creator(payload(left)); break;
      case kGlobalOffsetChunk: nc.payload = parse_offset(payload(left)); break;
      case kPlacesChunk: nc.payload = parse_places(payload(left)); break;
      case kOfflimitsChunk: nc.payload = parse_offlimits(payload(left)); break;
      case kLaserscansChunk: nc.payload = parse_laserscans(payload(left)); break;
      default: skip(left); return false;
    }
    map_.named.push_back(std::move(nc));
    return true;
  }

  Input in_;
  MapReadOptions opts_;
  uint64_t kept_ = 0;  // chunk bytes kept so far
  bool headers_only_;
  MapFile map_;
  const ChunkInfo *chunk_ = nullptr;
  std::vector<ChunkInfo> grid_chunks_;  // gridmap chunks read, in file order
};

// ---------------------------------------------------------------------------
// Encoding
// ---------------------------------------------------------------------------
std::string chunk_bytes(int type, bool named, const std::string &name, const std::string &payload) {
  if (named && name.find('\0') != std::string::npos) {
    throw std::invalid_argument("a chunk name may not contain a NUL byte");
  }
  const uint64_t size = 10 + (named ? name.size() + 1 : 0) + payload.size();
  if (size > static_cast<uint64_t>(std::numeric_limits<int32_t>::max())) {
    throw std::invalid_argument("the " + chunk_type_name(type) + " chunk would be " + std::to_string(size) +
                                " bytes: over the 2 GiB a CARMEN chunk can hold");
  }
  std::string s;
  s.reserve(static_cast<size_t>(size) + 5);
  s.push_back(static_cast<char>((type & 0x7f) | (named ? kNamedChunkFlag : 0)));
  put_i32(s, static_cast<int32_t>(size));
  s += chunk_description(type);
  if (named) {
    s += name;
    s.push_back('\0');
  }
  s += payload;
  return s;
}

std::string gridmap_payload(const GridMap &g) {
  if (g.size_x <= 0 || g.size_y <= 0) {
    throw std::invalid_argument("gridmap size " + std::to_string(g.size_x) + " x " +
                                std::to_string(g.size_y) + " is not positive");
  }
  if (g.cells.size() != size_t(g.size_x) * size_t(g.size_y)) {
    throw std::invalid_argument("gridmap has " + std::to_string(g.cells.size()) + " cells, size says " +
                                std::to_string(size_t(g.size_x) * size_t(g.size_y)));
  }
  if (g.cells.size() > (size_t{1} << 29)) {
    throw std::invalid_argument("gridmap of " + std::to_string(g.cells.size()) +
                                " cells is too large for a CARMEN map chunk");
  }
  std::string s;
  s.reserve(12 + 4 * g.cells.size());
  put_i32(s, g.size_x);
  put_i32(s, g.size_y);
  put_f32(s, static_cast<float>(g.resolution));
  if (host_is_little_endian()) {
    s.append(reinterpret_cast<const char *>(g.cells.data()), 4 * g.cells.size());
  } else {
    for (float v : g.cells) put_f32(s, v);
  }
  return s;
}

std::string creator_payload(const CreatorInfo &c) {
  if (c.time_bytes != 4 && c.time_bytes != 8) {
    throw std::invalid_argument("creator time width must be 4 or 8 bytes, not " +
                                std::to_string(c.time_bytes));
  }
  std::string s;
  put_field(s, c.user, 10, ' ');
  if (c.time_bytes == 4) {
    put_i32(s, static_cast<int32_t>(c.time));  // wraps after 2038, as a 32-bit time_t would
  } else {
    uint64_t u;
    std::memcpy(&u, &c.time, 8);
    put_u64(s, u);
  }
  put_field(s, c.origin, 80, ' ');
  put_field(s, c.description, 80, ' ');
  return s;
}

std::string offset_payload(const GlobalOffset &o) {
  std::string s;
  put_f64(s, o.x);
  put_f64(s, o.y);
  put_f64(s, o.theta);
  return s;
}

std::string places_payload(const PlaceList &places) {
  std::string s;
  put_i32(s, checked_count(places.size(), "places"));
  for (const Place &p : places) {
    if (p.type != kNamedPosition && p.type != kNamedPose && p.type != kLocalizationInit) {
      throw std::invalid_argument("place \"" + p.name + "\" has unknown type " + std::to_string(p.type));
    }
    put_i32(s, p.type);
    put_field(s, p.name, 20, ' ');  // space-padded, as CARMEN's write_fixed_string
    put_f32(s, static_cast<float>(p.x));
    put_f32(s, static_cast<float>(p.y));
    if (p.type != kNamedPosition) put_f32(s, static_cast<float>(p.theta));
    if (p.type == kLocalizationInit) {
      put_f32(s, static_cast<float>(p.x_std));
      put_f32(s, static_cast<float>(p.y_std));
      put_f32(s, static_cast<float>(p.theta_std));
    }
  }
  return s;
}

std::string offlimits_payload(const OffLimits &o) {
  std::string s;
  put_i32(s, checked_count(o.points.size(), "off-limits points"));
  for (const auto &p : o.points) {
    put_i32(s, p.x);
    put_i32(s, p.y);
  }
  for (const auto *list : {&o.lines, &o.rects}) {
    put_i32(s, checked_count(list->size(), "off-limits items"));
    for (const auto &l : *list) {
      put_i32(s, l.x1);
      put_i32(s, l.y1);
      put_i32(s, l.x2);
      put_i32(s, l.y2);
    }
  }
  return s;
}

std::string laserscans_payload(const LaserScanList &scans) {
  std::string s;
  put_i32(s, checked_count(scans.size(), "laser scans"));
  for (const LaserScan &sc : scans) {
    put_f32(s, static_cast<float>(sc.x));
    put_f32(s, static_cast<float>(sc.y));
    put_f32(s, static_cast<float>(sc.theta));
    put_i32(s, checked_count(sc.ranges.size(), "readings"));
    for (float r : sc.ranges) put_f32(s, r);
  }
  return s;
}

struct PayloadEncoder {
  std::pair<int, std::string> operator()(const GridMap &g) const {
    return {kGridmapChunk, gridmap_payload(g)};
  }
  std::pair<int, std::string> operator()(const OffLimits &o) const {
    return {kOfflimitsChunk, offlimits_payload(o)};
  }
  std::pair<int, std::string> operator()(const PlaceList &p) const {
    return {kPlacesChunk, places_payload(p)};
  }
  std::pair<int, std::string> operator()(const LaserScanList &l) const {
    return {kLaserscansChunk, laserscans_payload(l)};
  }
  std::pair<int, std::string> operator()(const CreatorInfo &c) const {
    return {kCreatorChunk, creator_payload(c)};
  }
  std::pair<int, std::string> operator()(const GlobalOffset &o) const {
    return {kGlobalOffsetChunk, offset_payload(o)};
  }
};

// Output to a temporary file, plain or gzip.
class Sink {
 public:
  Sink(AtomicOutput &out, bool gzip) : final_(out.final_path()), gzip_(gzip) {
    if (gzip_) {
      const int fd = out.take_fd();
      gz_ = gzdopen(fd, "wb");
      if (gz_ == nullptr) {
        ::close(fd);
        throw FileError(final_, "cannot write " + out.temp_path() + ": " +
                                    std::strerror(errno != 0 ? errno : ENOMEM));
      }
    } else {
      fp_ = out.take_stdio();
    }
  }
  ~Sink() {
    if (gz_ != nullptr) gzclose(gz_);
    if (fp_ != nullptr) std::fclose(fp_);
  }
  Sink(const Sink &) = delete;
  Sink &operator=(const Sink &) = delete;

  void write(const std::string &bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
      const size_t k = std::min(bytes.size() - done, size_t{1} << 30);
      if (gzip_) {
        if (gzwrite(gz_, bytes.data() + done, static_cast<unsigned>(k)) != static_cast<int>(k)) {
          int err = 0;
          const char *msg = gzerror(gz_, &err);
          throw FileError(final_, std::string("write failed: ") +
                                      (err == Z_ERRNO ? std::strerror(errno) : (msg ? msg : "zlib error")));
        }
      } else if (std::fwrite(bytes.data() + done, 1, k, fp_) != k) {
        throw FileError(final_, std::string("write failed: ") + std::strerror(errno));
      }
      done += k;
    }
  }
  void close() {
    if (gzip_) {
      const int rc = gzclose(gz_);
      gz_ = nullptr;
      if (rc != Z_OK) {
        throw FileError(final_, std::string("write failed on close: ") +
                                    (rc == Z_ERRNO ? std::strerror(errno) : "zlib error"));
      }
    } else {
      const int rc = std::fclose(fp_);
      fp_ = nullptr;
      if (rc != 0) throw FileError(final_, std::string("write failed on close: ") + std::strerror(errno));
    }
  }

 private:
  std::string final_;
  bool gzip_;
  gzFile gz_ = nullptr;
  FILE *fp_ = nullptr;
};

bool ends_with(const std::string &s, const char *suffix) {
  const size_t n = std::strlen(suffix);
  return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
}

}  // namespace

// ---------------------------------------------------------------------------
// Public functions
// ---------------------------------------------------------------------------
std::string chunk_description(int type) {
  switch (type & ~kNamedChunkFlag) {
    case kGridmapChunk: return "GRIDMAP   ";
    case kOfflimitsChunk: return "OFFLIMITS ";
    case kHmapChunk: return "HMAP      ";
    case kPlacesChunk: return "PLACES    ";
    case kExpectedChunk: return "EXPECTED  ";
    case kLaserscansChunk: return "LASERSCANS";
    case kCreatorChunk: return "CREATOR   ";
    case kGlobalOffsetChunk: return "OFFSET    ";
    default: return "UNKNOWN   ";
  }
}

std::string chunk_type_name(int type) {
  const int base = type & ~kNamedChunkFlag;
  switch (base) {
    case kOldCreatorChunk: return "old-style CREATOR";
    case kGridmapChunk: return "GRIDMAP";
    case kOfflimitsChunk: return "OFFLIMITS";
    case kHmapChunk: return "HMAP";
    case kPlacesChunk: return "PLACES";
    case kExpectedChunk: return "EXPECTED";
    case kLaserscansChunk: return "LASERSCANS";
    case kCreatorChunk: return "CREATOR";
    case kGlobalOffsetChunk: return "OFFSET";
    default: return "type-" + std::to_string(base);
  }
}

bool valid_cell_value(float v) {
  return v == kUnknownCell || (v >= 0.0f && v <= 1.0f) || (v >= 2.0f && v <= 3.0f);
}

float GridMap::at(int x, int y) const {
  if (!contains(x, y)) {
    throw std::out_of_range("cell (" + std::to_string(x) + ", " + std::to_string(y) + ") outside a " +
                            std::to_string(size_x) + " x " + std::to_string(size_y) + " map");
  }
  return cells.at(size_t(x) * size_t(size_y) + size_t(y));
}

float &GridMap::at(int x, int y) {
  if (!contains(x, y)) {
    throw std::out_of_range("cell (" + std::to_string(x) + ", " + std::to_string(y) + ") outside a " +
                            std::to_string(size_x) + " x " + std::to_string(size_y) + " map");
  }
  return cells.at(size_t(x) * size_t(size_y) + size_t(y));
}

GridMap GridMap::filled(int size_x, int size_y, double resolution, float value) {
  if (size_x < 0 || size_y < 0) throw std::invalid_argument("negative map size");
  GridMap g;
  g.size_x = size_x;
  g.size_y = size_y;
  g.resolution = resolution;
  g.cells.assign(size_t(size_x) * size_t(size_y), value);
  return g;
}

int NamedChunk::type() const {
  return std::visit(
      [](const auto &p) -> int {
        using T = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<T, GridMap>)
          return kGridmapChunk;
        else if constexpr (std::is_same_v<T, OffLimits>)
          return kOfflimitsChunk;
        else if constexpr (std::is_same_v<T, PlaceList>)
          return kPlacesChunk;
        else if constexpr (std::is_same_v<T, LaserScanList>)
          return kLaserscansChunk;
        else if constexpr (std::is_same_v<T, CreatorInfo>)
          return kCreatorChunk;
        else
          return kGlobalOffsetChunk;
      },
      payload);
}

MapFile read_map_file(const std::string &path) { return read_map_file(path, MapReadOptions{}); }

MapFile read_map_file(const std::string &path, const MapReadOptions &options) {
  Reader r(path, options, false);
  return r.run();
}

std::vector<ChunkInfo> list_map_chunks(const std::string &path) {
  Reader r(path, MapReadOptions{}, true);
  return r.run().chunks;
}

bool is_map_file(const std::string &path) {
  try {
    Reader r(path, MapReadOptions{}, true);
    return r.check_id_only();
  } catch (...) {
    return false;
  }
}

std::string encode_map_id() { return std::string(kMapLabel) + kMapVersion; }

std::string encode_comment_lines(const std::vector<std::string> &comments) {
  std::string s;
  for (const std::string &c : comments) {
    std::string line = c.substr(0, kCommentTextMax);
    for (char &ch : line) {
      if (ch == '\n' || ch == '\r' || ch == '\0') ch = ' ';
    }
    s += '#';
    s += line;
    s += '\n';
  }
  return s;
}

std::string encode_gridmap_chunk(const GridMap &map, const std::string &name) {
  return chunk_bytes(kGridmapChunk, !name.empty(), name, gridmap_payload(map));
}
std::string encode_creator_chunk(const CreatorInfo &creator, const std::string &name) {
  return chunk_bytes(kCreatorChunk, !name.empty(), name, creator_payload(creator));
}
std::string encode_global_offset_chunk(const GlobalOffset &offset, const std::string &name) {
  return chunk_bytes(kGlobalOffsetChunk, !name.empty(), name, offset_payload(offset));
}
std::string encode_places_chunk(const PlaceList &places, const std::string &name) {
  return chunk_bytes(kPlacesChunk, !name.empty(), name, places_payload(places));
}
std::string encode_offlimits_chunk(const OffLimits &offlimits, const std::string &name) {
  return chunk_bytes(kOfflimitsChunk, !name.empty(), name, offlimits_payload(offlimits));
}
std::string encode_laserscans_chunk(const LaserScanList &scans, const std::string &name) {
  return chunk_bytes(kLaserscansChunk, !name.empty(), name, laserscans_payload(scans));
}
std::string encode_chunk(const ChunkPayload &payload, const std::string &name) {
  auto [type, bytes] = std::visit(PayloadEncoder{}, payload);
  return chunk_bytes(type, !name.empty(), name, bytes);
}

void write_map_file(AtomicOutput &out, const MapFile &map) {
  // Encode everything first: an invalid MapFile throws before anything is written.
  std::vector<std::string> parts;
  parts.push_back(encode_comment_lines(map.comments) + encode_map_id());
  if (map.creator) parts.push_back(encode_creator_chunk(*map.creator));
  if (map.gridmap) parts.push_back(encode_gridmap_chunk(*map.gridmap));
  if (map.places) parts.push_back(encode_places_chunk(*map.places));
  if (map.offlimits) parts.push_back(encode_offlimits_chunk(*map.offlimits));
  if (map.laserscans) parts.push_back(encode_laserscans_chunk(*map.laserscans));
  if (map.offset) parts.push_back(encode_global_offset_chunk(*map.offset));
  for (const NamedChunk &nc : map.named) {
    if (nc.name.empty()) throw std::invalid_argument("a named chunk needs a non-empty name");
    parts.push_back(encode_chunk(nc.payload, nc.name));
  }
  Sink sink(out, ends_with(out.final_path(), ".gz"));
  for (const std::string &p : parts) sink.write(p);
  sink.close();
}

void write_map_file(const std::string &path, const MapFile &map) {
  AtomicOutput out(path);
  write_map_file(out, map);
  out.commit();
}

std::vector<std::string> standard_map_comments(int size_x, int size_y, double resolution,
                                               const std::string &origin, const std::string &description,
                                               const std::string &author, int64_t time) {
  const std::string rule(52, '#');
  char date[64] = "unknown";
  const std::time_t t = static_cast<std::time_t>(time);
  std::tm tm_utc;
  if (gmtime_r(&t, &tm_utc) != nullptr) std::strftime(date, sizeof date, "%a %b %e %H:%M:%S %Y UTC", &tm_utc);
  std::ostringstream res;
  res << resolution;
  return {
      rule,
      "",
      " CARMEN map file (format CARMENMAPFILEv020)",
      "",
      " Map author    : " + author,
      std::string(" Creation date : ") + date,
      " Map size      : " + std::to_string(size_x) + " x " + std::to_string(size_y),
      " Resolution    : " + res.str(),
      " Origin        : " + origin,
      " Description   : " + description,
      rule,
  };
}

std::string encode_raw_chunk(int type, const std::string &payload, const std::string &name) {
  return chunk_bytes(type, !name.empty(), name, payload);
}

std::string read_chunk_body(const std::string &path, const ChunkInfo &chunk) {
  if (chunk.size < 10) throw FileError(path, "chunk at offset " + std::to_string(chunk.offset) + " is too short");
  Input in(path);
  const uint64_t start = static_cast<uint64_t>(chunk.offset) + 5;  // type byte and size field
  if (in.skip(start) != start) throw FileError(path, "ends before the chunk at " + std::to_string(chunk.offset));
  // Read in pieces: the size was checked by the listing, but a gzip stream
  // can still end early.
  std::string body;
  const size_t want = static_cast<size_t>(chunk.size);
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
