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

}  // namespace maptest

#endif  // VASCO_TESTS_MAP_TEST_SUPPORT_H
