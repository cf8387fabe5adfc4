// Helpers shared by the map, image, mapconvert and gzip tests: temporary
// directories, whole-file I/O and little-endian byte builders that do not use
// the library under test.
#ifndef VASCO_TESTS_MAP_TEST_SUPPORT_H
#define VASCO_TESTS_MAP_TEST_SUPPORT_H

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace maptest {

inline std::string map_fixture(const std::string &rel) {
  return std::string(VASCO_TEST_DATA_DIR) + "/maps/" + rel;
}

// A fresh directory, removed with everything in it at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string base = ::testing::TempDir();
    if (base.empty()) base = "/tmp/";
    if (base.back() != '/') base += '/';
    std::string templ = base + "vasco_maps_XXXXXX";
    std::vector<char> buf(templ.begin(), templ.end());
    buf.push_back('\0');
    if (::mkdtemp(buf.data()) == nullptr) ADD_FAILURE() << "mkdtemp failed for " << templ;
    path_ = buf.data();
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir &) = delete;
  TempDir &operator=(const TempDir &) = delete;
  const std::string &path() const { return path_; }
  std::string file(const std::string &name) const { return path_ + "/" + name; }
  // Names of the entries in the directory, sorted (hidden ones included).
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto &e : std::filesystem::directory_iterator(path_))
      names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::string path_;
};

inline std::string read_bytes(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void write_bytes(const std::string &path, const std::string &data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
}

inline std::string gunzip_file(const std::string &path) {
  std::string out;
  gzFile f = gzopen(path.c_str(), "rb");
  if (f == nullptr) return out;
  char buf[1 << 15];
  int n;
  while ((n = gzread(f, buf, sizeof buf)) > 0) out.append(buf, static_cast<size_t>(n));
  gzclose(f);
  return out;
}

inline void gzip_to_file(const std::string &path, const std::string &data) {
  gzFile f = gzopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  if (!data.empty()) {
    ASSERT_EQ(gzwrite(f, data.data(), static_cast<unsigned>(data.size())), int(data.size()));
  }
  ASSERT_EQ(gzclose(f), Z_OK);
}

inline bool file_exists(const std::string &path) { return std::filesystem::exists(path); }

// ---- Little-endian builders (independent of the library) -----------------
inline std::string le32(uint32_t v) {
  std::string s(4, '\0');
  for (int i = 0; i < 4; ++i) s[size_t(i)] = static_cast<char>((v >> (8 * i)) & 0xff);
  return s;
}
inline std::string i32(int32_t v) { return le32(static_cast<uint32_t>(v)); }
inline std::string f32(float v) {
  uint32_t u;
  std::memcpy(&u, &v, 4);
  return le32(u);
}
inline std::string f64(double v) {
  uint64_t u;
  std::memcpy(&u, &v, 8);
  return le32(static_cast<uint32_t>(u)) + le32(static_cast<uint32_t>(u >> 32));
}
inline uint32_t read_le32(const std::string &s, size_t at) {
  return uint32_t(uint8_t(s[at])) | uint32_t(uint8_t(s[at + 1])) << 8 | uint32_t(uint8_t(s[at + 2])) << 16 |
         uint32_t(uint8_t(s[at + 3])) << 24;
}
// The cells CARMEN's reader leaves of `cell_bytes` (little-endian floats)
// when only the first `present` bytes are in the file: it fread()s into a
// calloc()ed grid, so every missing byte is a zero.
inline std::vector<float> cells_cut_short(std::string cell_bytes, size_t present) {
  for (size_t i = present; i < cell_bytes.size(); ++i) cell_bytes[i] = '\0';
  std::vector<float> cells(cell_bytes.size() / 4);
  for (size_t i = 0; i < cells.size(); ++i) {
    const uint32_t b = uint32_t(uint8_t(cell_bytes[4 * i])) | uint32_t(uint8_t(cell_bytes[4 * i + 1])) << 8 |
                       uint32_t(uint8_t(cell_bytes[4 * i + 2])) << 16 | uint32_t(uint8_t(cell_bytes[4 * i + 3])) << 24;
    std::memcpy(&cells[i], &b, 4);
  }
  return cells;
}

inline int32_t read_i32(const std::string &s, size_t at) { return static_cast<int32_t>(read_le32(s, at)); }
inline float read_f32(const std::string &s, size_t at) {
  const uint32_t u = read_le32(s, at);
  float v;
  std::memcpy(&v, &u, 4);
  return v;
}
// A text field of `width` bytes padded with `pad`.
inline std::string field(const std::string &text, size_t width, char pad = ' ') {
  std::string s = text.substr(0, width);
  s.append(width - s.size(), pad);
  return s;
}
// A whole chunk: type, size (= 10 + name part + payload), description, [name NUL], payload.
inline std::string chunk(int type, const std::string &desc, const std::string &payload,
                         const std::string &name = "", bool named = false) {
  const std::string name_part = named ? name + std::string(1, '\0') : std::string();
  return std::string(1, static_cast<char>(type | (named ? 0x80 : 0))) +
         i32(static_cast<int32_t>(10 + name_part.size() + payload.size())) + field(desc, 10) + name_part +
         payload;
}
inline const std::string kId = "CARMENMAPFILEv020";

// ---- CARMEN 0.7.4's off-limits writers, as the format notes describe them --
// An item of CARMEN's off-limits list: type 0 point (x1 y1), 1 line, 2
// rectangle (x1 y1 x2 y2).
struct CarmenOffItem {
  int type, x1, y1, x2, y2;
};
// The OFFLIMITS chunk carmen_map_write_offlimits_chunk writes: the point,
// line and rectangle counts, each followed by its items, but the line loop
// runs over the first `lines` items of the list rather than all of them, so
// a line further down is counted and not written; the size field counts
// every item. named: carmen_map_write_named_offlimits_chunk, which writes the
// same payload after the name but sizes the chunk with the unnamed size
// function given the name as the list: its size field says 10 + 12 = 22
// (when the count it then reads from a pointer is negative; otherwise it
// reads past the name and crashes).
inline std::string carmen_offlimits_chunk(const std::vector<CarmenOffItem> &items, const std::string &name = "",
                                          bool named = false) {
  int counts[3] = {0, 0, 0};
  for (const auto &it : items) ++counts[it.type];
  auto quad = [](const CarmenOffItem &it) { return i32(it.x1) + i32(it.y1) + i32(it.x2) + i32(it.y2); };
  std::string payload = i32(counts[0]);
  for (const auto &it : items)
    if (it.type == 0) payload += i32(it.x1) + i32(it.y1);
  payload += i32(counts[1]);
  for (size_t i = 0; i < items.size() && i < size_t(counts[1]); ++i)
    if (items[i].type == 1) payload += quad(items[i]);
  payload += i32(counts[2]);
  for (const auto &it : items)
    if (it.type == 2) payload += quad(it);
  const int32_t size = named ? 22 : 10 + 12 + 8 * counts[0] + 16 * (counts[1] + counts[2]);
  return std::string(1, static_cast<char>(named ? 0x82 : 0x02)) + i32(size) + "OFFLIMITS " +
         (named ? name + std::string(1, '\0') : std::string()) + payload;
}

}  // namespace maptest

#endif  // VASCO_TESTS_MAP_TEST_SUPPORT_H
