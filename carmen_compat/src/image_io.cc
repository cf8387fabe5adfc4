// PGM + YAML (map_server) and PNG output of a grid map.
#include "carmen_compat/image_io.h"

#include <png.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"

namespace carmen {
namespace {

void check_map(const GridMap &map) {
  if (map.size_x <= 0 || map.size_y <= 0) {
    throw std::invalid_argument("cannot make an image of a " + std::to_string(map.size_x) + " x " +
                                std::to_string(map.size_y) + " map");
  }
  if (map.cells.size() != size_t(map.size_x) * size_t(map.size_y)) {
    throw std::invalid_argument("map has " + std::to_string(map.cells.size()) + " cells, its size says " +
                                std::to_string(size_t(map.size_x) * size_t(map.size_y)));
  }
}

template <typename PixelFn>
std::vector<uint8_t> render(const GridMap &map, PixelFn pixel) {
  check_map(map);
  const size_t w = size_t(map.size_x), h = size_t(map.size_y);
  std::vector<uint8_t> img(w * h);
  for (size_t r = 0; r < h; ++r) {
    const size_t y = h - 1 - r;
    uint8_t *row = img.data() + r * w;
    for (size_t x = 0; x < w; ++x) row[x] = pixel(map.cells[x * h + y]);
  }
  return img;
}

bool is_unknown(float v) { return std::isnan(v) || v < 0.0f; }
bool is_offlimits(float v) { return v >= 2.0f; }
double clamp01(double p) { return p < 0.0 ? 0.0 : (p > 1.0 ? 1.0 : p); }

// Shortest decimal text that reads back as the same double (and, when the
// value is exactly a float, the shortest that reads back as that float:
// a resolution of 0.1f prints as 0.1).
std::string number_text(double v) {
  if (v == 0.0) return "0";
  const bool is_float = static_cast<double>(static_cast<float>(v)) == v;
  char buf[64];
  for (int prec = 1; prec <= 17; ++prec) {
    std::snprintf(buf, sizeof buf, "%.*g", prec, v);
    const double back = std::strtod(buf, nullptr);
    if (is_float ? static_cast<float>(back) == static_cast<float>(v) : back == v) break;
  }
  return buf;
}

std::string file_name_of(const std::string &path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

void write_all(const std::string &final_path, const std::string &temp_path, const std::string &header,
               const std::vector<uint8_t> &body) {
  FILE *f = std::fopen(temp_path.c_str(), "wb");
  if (f == nullptr) throw FileError(final_path, "cannot create " + temp_path + ": " + std::strerror(errno));
  bool ok = std::fwrite(header.data(), 1, header.size(), f) == header.size();
  if (ok && !body.empty()) ok = std::fwrite(body.data(), 1, body.size(), f) == body.size();
  const int err = errno;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) {
    throw FileError(final_path, std::string("write failed: ") + std::strerror(ok ? errno : err));
  }
}

}  // namespace

const char *pgm_mode_name(PgmMode mode) {
  switch (mode) {
    case PgmMode::Trinary: return "trinary";
    case PgmMode::Scale: return "scale";
    case PgmMode::Raw: return "raw";
  }
  return "trinary";
}

bool parse_pgm_mode(const std::string &name, PgmMode *mode) {
  for (PgmMode m : {PgmMode::Trinary, PgmMode::Scale, PgmMode::Raw}) {
    if (name == pgm_mode_name(m)) {
      *mode = m;
      return true;
    }
  }
  return false;
}

uint8_t pgm_pixel(float value, PgmMode mode) {
  const bool unknown = is_unknown(value);
  const bool offlimits = !unknown && is_offlimits(value);
  const double p = clamp01(value);
  switch (mode) {
    case PgmMode::Trinary:
      if (unknown) return kPgmUnknown;
      if (offlimits || p > kOccupiedThresh) return kPgmOccupied;
      if (p < kFreeThresh) return kPgmFree;
      return kPgmUnknown;
    case PgmMode::Scale:
      if (unknown) return kPgmUnknown;
      if (offlimits) return 0;
      return static_cast<uint8_t>(std::lround(255.0 * (1.0 - p)));
    case PgmMode::Raw:
      if (unknown) return kPgmRawUnknown;
      if (offlimits) return 100;
      return static_cast<uint8_t>(std::lround(100.0 * p));
  }
  return kPgmUnknown;
}

uint8_t png_pixel(float value) {
  if (is_unknown(value)) return kPngUnknown;
  if (is_offlimits(value)) return 0;
  return static_cast<uint8_t>(std::lround(255.0 * (1.0 - clamp01(value))));
}

std::vector<uint8_t> map_to_pgm_pixels(const GridMap &map, PgmMode mode) {
  return render(map, [mode](float v) { return pgm_pixel(v, mode); });
}

std::vector<uint8_t> map_to_png_pixels(const GridMap &map) { return render(map, png_pixel); }

std::string yaml_path_for(const std::string &pgm_path) {
  const size_t slash = pgm_path.find_last_of('/');
  const size_t dot = pgm_path.find_last_of('.');
  const size_t name_start = slash == std::string::npos ? 0 : slash + 1;
  if (dot == std::string::npos || dot <= name_start) return pgm_path + ".yaml";
  return pgm_path.substr(0, dot) + ".yaml";
}

void write_pgm_with_yaml(const std::string &pgm_path, const GridMap &map,
                         const GlobalOffset &origin_of_cell00, PgmMode mode) {
  const std::vector<uint8_t> pixels = map_to_pgm_pixels(map, mode);
  const std::string yaml_path = yaml_path_for(pgm_path);
  if (yaml_path == pgm_path)
    throw std::invalid_argument(pgm_path + ": the image and its YAML would be one file");

  const std::string header =
      "P5\n" + std::to_string(map.size_x) + " " + std::to_string(map.size_y) + "\n255\n";
  std::string yaml;
  yaml += "image: " + file_name_of(pgm_path) + "\n";
  yaml += "mode: " + std::string(pgm_mode_name(mode)) + "\n";
  yaml += "resolution: " + number_text(map.resolution) + "\n";
  yaml += "origin: [" + number_text(origin_of_cell00.x) + ", " + number_text(origin_of_cell00.y) + ", " +
          number_text(origin_of_cell00.theta) + "]\n";
  yaml += "negate: 0\n";
  yaml += "occupied_thresh: " + number_text(kOccupiedThresh) + "\n";
  yaml += "free_thresh: " + number_text(kFreeThresh) + "\n";

  AtomicOutput pgm_out(pgm_path);
  AtomicOutput yaml_out(yaml_path);
  write_all(pgm_path, pgm_out.temp_path(), header, pixels);
  write_all(yaml_path, yaml_out.temp_path(), yaml, {});
  pgm_out.commit();
  yaml_out.commit();
}

void write_png(const std::string &path, const GridMap &map) {
  const std::vector<uint8_t> pixels = map_to_png_pixels(map);
  AtomicOutput out(path);
  FILE *f = std::fopen(out.temp_path().c_str(), "wb");
  if (f == nullptr) throw FileError(path, "cannot create " + out.temp_path() + ": " + std::strerror(errno));
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(map.size_x);
  image.height = static_cast<png_uint_32>(map.size_y);
  image.format = PNG_FORMAT_GRAY;
  const int ok =
      png_image_write_to_stdio(&image, f, 0, pixels.data(), static_cast<png_int_32>(map.size_x), nullptr);
  const std::string message = ok ? std::string() : std::string(image.message);
  png_image_free(&image);
  const bool closed = std::fclose(f) == 0;
  if (!ok) throw FileError(path, "PNG write failed: " + message);
  if (!closed) throw FileError(path, std::string("write failed: ") + std::strerror(errno));
  out.commit();
}

}  // namespace carmen
