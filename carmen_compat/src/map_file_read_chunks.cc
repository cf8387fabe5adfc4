// The map reader's work on a chunk's data (map_file_reader.h): payload bytes
// counted against MapReadOptions::max_kept_bytes, a GRIDMAP (whole, cut short
// as CARMEN reads it, or passed), an OFFLIMITS chunk in either layout, the
// check of cell values, and the messages that name the chunk being read.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "map_file_bytes.h"
#include "map_file_reader.h"

namespace carmen::map_read {
namespace {

using namespace map_bytes;

std::string byte_count(uint64_t n) { return std::to_string(n) + (n == 1 ? " byte" : " bytes"); }

}  // namespace

// "the GRIDMAP chunk at byte 540 " (with its name), or "the file ".
std::string Reader::where() const {
  if (chunk_ == nullptr) return "the file ";
  return "the " + chunk_type_name(chunk_->type) + " chunk at byte " + std::to_string(chunk_->offset) +
         (chunk_->named() && !chunk_->name.empty() ? " (named \"" + printable(chunk_->name) + "\")" : "") + " ";
}

[[noreturn]] void Reader::fail(const std::string &msg, ErrorCode code) const {
  throw FileError(in_.path(), where() + msg, code);
}

// A warning about the chunk being read: to MapReadOptions::on_warning, or stderr.
void Reader::warn(const std::string &msg) const {
  const std::string text = FileError::format(in_.path(), 0, "warning: " + where() + msg);
  if (opts_.on_warning) {
    opts_.on_warning(text);
  } else {
    std::fprintf(stderr, "%s\n", text.c_str());
  }
}

// Called when fewer bytes came than were needed.
[[noreturn]] void Reader::fail_short(const std::string &what) const {
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
[[noreturn]] void Reader::fail_remain(const std::string &why) const {
  const int64_t rem = in_.pos() + in_.remaining() - (chunk_->offset + 5);
  fail("claims " + std::to_string(chunk_->size) + " bytes but only " + std::to_string(rem) +
       " remain in the file: it is truncated or damaged" + why);
}

// Data that ends inside the chunk being read: the message of a plain
// file's size check, or (a stream) where the data ended.
[[noreturn]] void Reader::fail_cut(const std::string &what, const std::string &why) const {
  if (!in_.stream_error().empty() || in_.remaining() < 0) fail_short(what + why);
  fail_remain(why);
}

// Reads `n` bytes in bounded pieces: a short file fails before the
// claimed size is allocated (the size was already checked for plain files).
std::vector<unsigned char> Reader::payload(uint64_t n) {
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
void Reader::keep(uint64_t bytes) {
  kept_ += bytes;
  if (kept_ > opts_.max_kept_bytes)
    fail("makes the map hold more than " + std::to_string(opts_.max_kept_bytes >> 20) +
         " MiB of chunk data (MapReadOptions::max_kept_bytes): refused rather than allocated",
         ErrorCode::TooLarge);
}

// The size and resolution, checked against the chunk size; the cells are
// left unread.
GridMap Reader::read_gridmap_header(uint64_t left) {
  if (left < 12) fail("has " + std::to_string(left) + " payload bytes, too few for the map size");
  unsigned char hdr[12];
  const size_t hgot = in_.read(hdr, 12);
  if (hgot < 12) fail_short("the map size");
  return gridmap_header(hdr, left);
}

GridMap Reader::gridmap_header(const unsigned char *hdr, uint64_t left) {
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

GridMap Reader::read_gridmap(uint64_t left) {
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
void Reader::check_short(uint64_t present, uint64_t wanted) const {
  if (wanted - present <= std::max(present, kShortGridSlack)) return;
  fail_cut("the cells", "; fewer than half of its cells are there, too few to read the rest as unknown");
}

// The cells the file lacks, as CARMEN renders a gridmap cut short: its
// reader fread()s into a calloc()ed grid, so a missing byte is a zero: the
// missing cells are 0 (free), and a cell only partly there keeps the bytes
// that came (the readers' check of cell values judges it like any other).
void Reader::read_short(GridMap &g, uint64_t present) const {
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
void Reader::pass_gridmap(uint64_t left) {
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
OffLimits Reader::read_offlimits(const ChunkInfo &info, uint64_t left, bool read) {
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

void Reader::warn_carmen_layout(const OffLimitsPayload &d, int64_t start) const {
  std::string msg = "is laid out as CARMEN 0.7.4's writer lays it out, not as its size field (" +
                    std::to_string(chunk_->size) + ") says";
  if (d.lines_left_out > 0) {
    msg += ": " + std::to_string(d.lines_left_out) + " of its " +
           std::to_string(d.lines_left_out + d.offlimits.lines.size()) +
           " lines were counted but never written (the writer's line loop skips them)";
  }
  warn(msg + "; it ends at byte " + std::to_string(start + int64_t(d.length)));
}

void Reader::check_cells(const GridMap &g) {
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

}  // namespace carmen::map_read
