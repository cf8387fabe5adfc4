// OFFLIMITS payloads: the layout the size field gives, and the ones CARMEN
// 0.7.4's writers produce (map_file.h, decode_offlimits_payload).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "carmen_compat/map_file.h"
#include "map_file_bytes.h"

namespace carmen {
namespace {

using map_bytes::get_i32;

// CARMEN's layouts are looked for in this many bytes at most: an off-limits
// list is a handful of items, and the look-ahead a named chunk needs (its
// size field says nothing) stays bounded.
constexpr uint64_t kLayoutWindow = uint64_t{16} << 20;
constexpr uint64_t kHeaderBytes = 15;  // type, size, description of the next chunk

struct Bad {
  std::string what;
};

// Bounds-checked reading of the payload held in `b`, from its start.
class Cursor {
 public:
  Cursor(const std::vector<unsigned char> &b, size_t n) : b_(b), n_(n) {}
  size_t left() const { return n_ - i_; }
  int32_t i32(const char *what) {
    if (left() < 4) {
      throw Bad{std::string("ends inside ") + what + " (needs 4 more bytes, " + std::to_string(left()) +
                " left)"};
    }
    const int32_t v = get_i32(b_.data() + i_);
    i_ += 4;
    return v;
  }
  // A count of items of `item_bytes` each, checked against what is left.
  size_t count(size_t item_bytes, const char *what) {
    const int32_t n = i32(what);
    if (n < 0) throw Bad{std::string("has a negative ") + what + " (" + std::to_string(n) + ")"};
    if (uint64_t(n) * item_bytes > left()) {
      throw Bad{std::string("claims ") + std::to_string(n) + " " + what + " but holds only " +
                std::to_string(left()) + " more bytes"};
    }
    return size_t(n);
  }
  void expect_end() const {
    if (left() != 0) throw Bad{"has " + std::to_string(left()) + " unexpected bytes at its end"};
  }

 private:
  const std::vector<unsigned char> &b_;
  size_t n_;
  size_t i_ = 0;
};

void read_segments(Cursor &cur, size_t n, const char *item, std::vector<OffLimits::Segment> *out) {
  out->resize(n);
  for (auto &sg : *out) {
    sg.x1 = cur.i32(item);
    sg.y1 = cur.i32(item);
    sg.x2 = cur.i32(item);
    sg.y2 = cur.i32(item);
  }
}

// The points: their count, then (x y) each.
void read_points(Cursor &cur, OffLimits *o) {
  o->points.resize(cur.count(8, "points"));
  for (auto &pt : o->points) {
    pt.x = cur.i32("a point");
    pt.y = cur.i32("a point");
  }
}

// The layout the size field gives: the first n bytes of b, every count's
// items all there, nothing after the rectangles.
OffLimits parse_sized(const std::vector<unsigned char> &b, size_t n) {
  Cursor cur(b, n);
  OffLimits o;
  read_points(cur, &o);
  read_segments(cur, cur.count(16, "lines"), "a line", &o.lines);
  read_segments(cur, cur.count(16, "rectangles"), "a rectangle", &o.rects);
  cur.expect_end();
  return o;
}

// True when b holds, at `at`, the header of a chunk CARMEN writes: a type it
// knows (named or not), a size of at least 10 and that type's description.
bool chunk_header_at(const std::vector<unsigned char> &b, uint64_t at) {
  if (at + kHeaderBytes > b.size()) return false;
  const int type = b[at] & ~kNamedChunkFlag;
  const std::string desc = chunk_description(type);
  if (type == kOldCreatorChunk || desc == chunk_description(0x7f)) return false;  // "UNKNOWN   "
  return get_i32(b.data() + at + 1) >= 10 && std::memcmp(b.data() + at + 5, desc.data(), 10) == 0;
}

// CARMEN's layouts: of the lines counted, the first k written, then the
// rectangles. Reads through the caller's fetch, in the buffer the sized
// attempt filled.
class CarmenLayout {
 public:
  CarmenLayout(std::vector<unsigned char> &bytes, uint64_t declared, bool named, const PayloadFetch &fetch)
      : bytes_(bytes), declared_(declared), named_(named), fetch_(fetch) {}

  // True when the data holds n bytes (fetched as needed).
  bool have(uint64_t n) {
    if (bytes_.size() < n && !ended_) {
      fetch_(bytes_, n);
      ended_ = bytes_.size() < n;
    }
    return bytes_.size() >= n;
  }

  // Whether a chunk ending at `end` is followed by the end of the data or by
  // the header of a chunk CARMEN writes.
  bool ends_at(uint64_t end) {
    if (have(end + kHeaderBytes)) return chunk_header_at(bytes_, end);
    return bytes_.size() == end;
  }

  bool find(OffLimitsPayload *out) {
    if (!have(4)) return false;
    const int32_t np = get_i32(bytes_.data());
    if (np < 0) return false;
    lines_at_ = 8 + 8 * uint64_t(np);  // after the point count, the points and the line count
    if (lines_at_ + 4 > kLayoutWindow || !have(lines_at_)) return false;
    const int32_t nl = get_i32(bytes_.data() + lines_at_ - 4);
    if (nl < 0) return false;
    int64_t nr = -1;  // the rectangle count, when the size field gives it
    if (!named_) {
      // The unnamed writer's size counts every item, so it gives the
      // rectangle count; its layout differs from the sized one only when a
      // line was left out.
      if (nl == 0 || declared_ < lines_at_ + 4 || (declared_ - lines_at_ - 4) % 16 != 0) return false;
      const uint64_t items = (declared_ - lines_at_ - 4) / 16;
      if (items < uint64_t(nl)) return false;
      nr = int64_t(items - uint64_t(nl));
    }
    const uint64_t most = (kLayoutWindow - lines_at_ - 4) / 16;
    for (uint64_t k = std::min<uint64_t>(named_ ? uint64_t(nl) : uint64_t(nl) - 1, most);; --k) {
      if (fits(k, nr)) {
        fill(uint64_t(nl) - k, k, out);
        return true;
      }
      if (k == 0) return false;
    }
  }

 private:
  // Whether k lines, then a rectangle count (nr, when known) and its
  // rectangles end where the data ends or a chunk begins.
  bool fits(uint64_t k, int64_t nr) {
    const uint64_t at = lines_at_ + 16 * k;
    if (!have(at + 4)) return false;
    const int32_t rects = get_i32(bytes_.data() + at);
    if (rects < 0 || (nr >= 0 && rects != nr)) return false;
    end_ = at + 4 + 16 * uint64_t(rects);
    return end_ <= kLayoutWindow && ends_at(end_);
  }

  void fill(uint64_t left_out, uint64_t k, OffLimitsPayload *out) {
    Cursor cur(bytes_, size_t(end_));
    OffLimits &o = out->offlimits;
    read_points(cur, &o);
    cur.i32("the line count");
    read_segments(cur, size_t(k), "a line", &o.lines);
    read_segments(cur, cur.count(16, "rectangles"), "a rectangle", &o.rects);
    out->ok = true;
    out->length = end_;
    out->lines_left_out = left_out;
    out->carmen_layout = true;
  }

  std::vector<unsigned char> &bytes_;
  uint64_t declared_;
  bool named_;
  const PayloadFetch &fetch_;
  bool ended_ = false;
  uint64_t lines_at_ = 0;
  uint64_t end_ = 0;
};

}  // namespace

// The layout the size field gives, when it parses and the chunk is followed
// by the end of the data or a chunk header; else CARMEN's, when one fits;
// else the sized one, when it parses (what follows is then not a chunk
// CARMEN writes: left for the reader of the next chunk to judge).
OffLimitsPayload decode_offlimits_payload(std::vector<unsigned char> &bytes, uint64_t declared, bool named,
                                          const PayloadFetch &fetch) {
  CarmenLayout carmen(bytes, declared, named, fetch);
  OffLimitsPayload sized;
  if (carmen.have(declared)) {
    try {
      sized.offlimits = parse_sized(bytes, size_t(declared));
      sized.ok = true;
      sized.length = declared;
    } catch (const Bad &e) {
      sized.error = e.what;
    }
  } else {
    sized.error = "is cut short: the data ends after " + std::to_string(bytes.size()) + " of its " +
                  std::to_string(declared) + " payload bytes";
  }
  if (sized.ok && (declared > kLayoutWindow || carmen.ends_at(declared))) return sized;
  OffLimitsPayload out;
  if (carmen.find(&out)) return out;
  return sized;
}

}  // namespace carmen
