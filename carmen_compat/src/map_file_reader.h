// The map reader (map_file.h's readers): one pass over a map file's bytes,
// its comments, id and chunk headers (map_file_read.cc), and the chunks' data
// (map_file_read_chunks.cc): a GRIDMAP, whole or cut short, an OFFLIMITS chunk
// in either of its layouts, and the payloads of fixed layout
// (map_file_payloads.h). Every size a file claims is checked against what it
// holds before memory is allocated for it.
#ifndef CARMEN_COMPAT_MAP_FILE_READER_H
#define CARMEN_COMPAT_MAP_FILE_READER_H

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "map_file_input.h"
#include "map_file_payloads.h"

namespace carmen::map_read {

constexpr size_t kMaxCommentLine = 4096;         // bytes per comment line
constexpr size_t kMaxCommentBytes = 1 << 20;     // whole comment block
constexpr size_t kMaxChunkName = 256;            // bytes of a chunk name, NUL included
constexpr size_t kReadPiece = size_t{16} << 20;  // growth step when the size is not known

// A GRIDMAP chunk whose data ends inside its cells is read when at least
// half of its cell bytes are there, or all but this many: what is allocated
// for it stays within twice what the file holds (plus 1 MiB).
constexpr uint64_t kShortGridSlack = uint64_t{1} << 20;

// The Input, with bytes given back. An OFFLIMITS chunk in CARMEN's layout
// ends before its size field says; what was read past its end is the next
// chunk's and is read again from here.
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

enum class ReadMode { Full, HeadersOnly };

// The chunk types whose payload is read into a ChunkPayload.
bool is_named_kind(int base);

// One pass over one file: the whole map (run), or its headers only, or up to
// the first chunk of a kind (CARMEN's lookup).
class Reader {
 public:
  Reader(const std::string &path, const MapReadOptions &opts, ReadMode mode)
      : in_(path), opts_(opts), headers_only_(mode == ReadMode::HeadersOnly) {}

  MapFile run();
  NamedChunk read_named_at(const ChunkInfo &listed);
  bool seek_first(int type, const std::string *name, ChunkInfo *info, uint64_t *left);
  std::optional<ChunkInfo> find_first(int type, const std::string *name);
  std::optional<FoundChunk> read_first(int type, const std::string *name);
  std::optional<GridMapHeader> read_first_header(const std::string *name);
  bool check_id_only();

 private:
  template <typename F>
  std::invoke_result_t<F> parse_or_fail(F &&parse) {
    try {
      return parse();
    } catch (const ParseError &e) {
      fail(e.what);
    }
  }

  // The file's layout (map_file_read.cc).
  void read_chunk(ChunkInfo &info, uint64_t left);
  bool read_unnamed(const ChunkInfo &info, uint64_t left);
  bool read_named(const ChunkInfo &info, uint64_t left);
  ChunkPayload named_payload(const ChunkInfo &info, uint64_t left);
  void pass(const ChunkInfo &info, uint64_t left);
  void check_kept_cells();
  void read_comments();
  void read_id();
  bool read_chunk_header(ChunkInfo *info, uint64_t *left);
  void skip(uint64_t n);

  // What went wrong, and where (map_file_read_chunks.cc).
  std::string where() const;
  [[noreturn]] void fail(const std::string &msg, ErrorCode code = ErrorCode::BadInput) const;
  void warn(const std::string &msg) const;
  [[noreturn]] void fail_short(const std::string &what) const;
  [[noreturn]] void fail_remain(const std::string &why = "") const;
  [[noreturn]] void fail_cut(const std::string &what, const std::string &why = "") const;

  // The chunks' data (map_file_read_chunks.cc).
  std::vector<unsigned char> payload(uint64_t n);
  void keep(uint64_t bytes);
  GridMap read_gridmap_header(uint64_t left);
  GridMap gridmap_header(const unsigned char *hdr, uint64_t left);
  GridMap read_gridmap(uint64_t left);
  void check_short(uint64_t present, uint64_t wanted) const;
  void read_short(GridMap &g, uint64_t present) const;
  void pass_gridmap(uint64_t left);
  OffLimits read_offlimits(const ChunkInfo &info, uint64_t left, bool read);
  void warn_carmen_layout(const OffLimitsPayload &d, int64_t start) const;
  void check_cells(const GridMap &g);

  Source in_;
  MapReadOptions opts_;
  uint64_t kept_ = 0;  // chunk bytes kept so far
  bool headers_only_;
  MapFile map_;
  std::optional<CreatorInfo> old_creator_;  // from a code-0 chunk, used when no CREATOR exists
  const ChunkInfo *chunk_ = nullptr;
  std::vector<ChunkInfo> grid_chunks_;  // gridmap chunks read, in file order
};

}  // namespace carmen::map_read

#endif  // CARMEN_COMPAT_MAP_FILE_READER_H
