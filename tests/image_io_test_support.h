// What the map image tests share: a 4 x 2 map whose grey levels are worked
// out by hand, the pixels each mode gives it, and strict readers of the PGM
// and YAML we write that do not use the library under test.
#ifndef VASCO_TESTS_IMAGE_IO_TEST_SUPPORT_H
#define VASCO_TESTS_IMAGE_IO_TEST_SUPPORT_H

#include <cstdint>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "carmen_compat/map_file.h"
#include "map_test_support.h"

namespace imagetest {

using maptest::read_bytes;
using maptest::TempDir;

// A 4 x 2 map; each value's grey levels are worked out by hand below.
//   y=1 (top row):    0.5   0.0   1.0   0.65f
//   y=0 (bottom row): -1    0.75  0.125 2.5 (off-limits overlay)
inline carmen::GridMap tiny_map() {
  carmen::GridMap g = carmen::GridMap::filled(4, 2, 0.05);
  g.at(0, 1) = 0.5f;
  g.at(1, 1) = 0.0f;
  g.at(2, 1) = 1.0f;
  g.at(3, 1) = 0.65f;
  g.at(0, 0) = -1.0f;
  g.at(1, 0) = 0.75f;
  g.at(2, 0) = 0.125f;
  g.at(3, 0) = 2.5f;
  return g;
}

// Trinary: > 0.65 black, < 0.196 254, else 205. 0.65f is 0.6499999762 (not
// above 0.65), 0.125 is free, 0.5 in between, 2.5 off-limits -> occupied.
inline const std::vector<uint8_t> kTrinary = {205, 254, 0, 205, /**/ 205, 0, 254, 0};
// Scale: round(255 (1 - p)): 127.5->128, 255, 0, 89.25->89; unknown 205,
// 63.75->64, 223.125->223, off-limits 0.
inline const std::vector<uint8_t> kScale = {128, 255, 0, 89, /**/ 205, 64, 223, 0};
// Raw: round(100 p): 50, 0, 100, 64.99999762->65; unknown 255, 75, 12.5->13, 100.
inline const std::vector<uint8_t> kRaw = {50, 0, 100, 65, /**/ 255, 75, 13, 100};
// PNG (RGB): grey round(255 (1 - p)); unknown -1 (0 below) is #708986.
inline const std::vector<uint8_t> kPng = {128, 255, 0, 89, /**/ 0, 64, 223, 0};
inline constexpr uint8_t kUnknownRgb[3] = {0x70, 0x89, 0x86};

struct Pgm {
  std::string magic;
  int width = 0, height = 0, maxval = 0;
  std::vector<uint8_t> pixels;
};

// A strict reader for the header form we write: "P5\nW H\n255\n" + pixels.
inline Pgm read_pgm(const std::string &path) {
  const std::string raw = read_bytes(path);
  std::istringstream in(raw);
  Pgm p;
  in >> p.magic >> p.width >> p.height >> p.maxval;
  in.get();  // the single whitespace byte before the pixels
  const size_t at = static_cast<size_t>(in.tellg());
  p.pixels.assign(raw.begin() + static_cast<long>(at), raw.end());
  return p;
}

inline std::map<std::string, std::string> read_yaml(const std::string &path) {
  std::map<std::string, std::string> kv;
  std::istringstream in(read_bytes(path));
  std::string line;
  while (std::getline(in, line)) {
    const size_t colon = line.find(": ");
    if (colon != std::string::npos) kv[line.substr(0, colon)] = line.substr(colon + 2);
  }
  return kv;
}

}  // namespace imagetest

#endif  // VASCO_TESTS_IMAGE_IO_TEST_SUPPORT_H
