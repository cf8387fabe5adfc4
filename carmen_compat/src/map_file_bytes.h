// Little-endian number coding shared by the map file reader and writer (the
// format is little-endian whatever the host; see map_file.h).
#ifndef CARMEN_COMPAT_MAP_FILE_BYTES_H
#define CARMEN_COMPAT_MAP_FILE_BYTES_H

#include <cstdint>
#include <cstring>
#include <string>

namespace carmen::map_bytes {

inline bool host_is_little_endian() {
  const uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

inline uint32_t get_u32(const unsigned char *p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
inline uint64_t get_u64(const unsigned char *p) { return uint64_t(get_u32(p)) | uint64_t(get_u32(p + 4)) << 32; }
template <typename T, typename U>
T bit_cast_to(U u) {
  static_assert(sizeof(T) == sizeof(U), "same width");
  T v;
  std::memcpy(&v, &u, sizeof v);
  return v;
}
inline int32_t get_i32(const unsigned char *p) { return bit_cast_to<int32_t>(get_u32(p)); }
inline float get_f32(const unsigned char *p) { return bit_cast_to<float>(get_u32(p)); }
inline double get_f64(const unsigned char *p) { return bit_cast_to<double>(get_u64(p)); }

inline void put_u32(std::string &s, uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
inline void put_u64(std::string &s, uint64_t v) {
  for (int i = 0; i < 8; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
inline void put_i32(std::string &s, int32_t v) { put_u32(s, bit_cast_to<uint32_t>(v)); }
inline void put_f32(std::string &s, float v) { put_u32(s, bit_cast_to<uint32_t>(v)); }
inline void put_f64(std::string &s, double v) { put_u64(s, bit_cast_to<uint64_t>(v)); }

}  // namespace carmen::map_bytes

#endif  // CARMEN_COMPAT_MAP_FILE_BYTES_H
