// PGM + YAML (map_server) and PNG output of a grid map.
#include "carmen_compat/image_io.h"

#include <png.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"
#include "carmen_compat/yaml_number.h"

namespace carmen {

void check_map_size(const GridMap &map, const char *what) {
  if (map.size_x <= 0 || map.size_y <= 0) {
    throw std::invalid_argument(std::string("cannot make ") + what + " of a " + std::to_string(map.size_x) + " x " +
                                std::to_string(map.size_y) + " map");
  }
  if (map.cells.size() != size_t(map.size_x) * size_t(map.size_y)) {
    throw std::invalid_argument("map has " + std::to_string(map.cells.size()) + " cells, its size says " +
                                std::to_string(size_t(map.size_x) * size_t(map.size_y)));
  }
}

namespace {

template <typename PixelFn>
std::vector<uint8_t> render(const GridMap &map, PixelFn pixel) {
  check_map_size(map, "an image");
  const size_t w = size_t(map.size_x), h = size_t(map.size_y);
  std::vector<uint8_t> img(w * h);
  for (size_t r = 0; r < h; ++r) {
    const size_t y = h - 1 - r;
    uint8_t *row = img.data() + r * w;
    for (size_t x = 0; x < w; ++x) row[x] = pixel(map.cells[x * h + y]);
  }
  return img;
}

// How map_server reads a grey level (negate 0): occupancy (255 - v) / 255.
double level_occupancy(int v) { return (255 - v) / 255.0; }
// Levels are kept this far inside a threshold: map_servers compute the
// occupancy in their own floating point (nav2 through GraphicsMagick).
constexpr double kLevelMargin = 1e-9;

// The trinary unknown level for o's thresholds (before negation): 205, or
// the level nearest it that reads as unknown (neither below free_thresh nor
// above occupied_thresh); -1 when there is none.
int unknown_level(const MapServerOptions &o) {
  int best = -1;
  for (int pass = 0; pass < 2 && best < 0; ++pass) {  // strictly inside first, then on a threshold
    const double margin = pass == 0 ? kLevelMargin : 0.0;
    for (int v = 0; v <= 255; ++v) {
      const double occ = level_occupancy(v);
      if (occ < o.free_thresh + margin || occ > o.occupied_thresh - margin) continue;
      if (best < 0 || std::abs(v - int(kPgmUnknown)) < std::abs(best - int(kPgmUnknown))) best = v;
    }
  }
  return best;
}

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

void write_all(AtomicOutput &out, const std::string &header, const std::vector<uint8_t> &body) {
  const std::string &final_path = out.final_path();
  FILE *f = out.take_stdio();
  bool ok = std::fwrite(header.data(), 1, header.size(), f) == header.size();
  if (ok && !body.empty()) ok = std::fwrite(body.data(), 1, body.size(), f) == body.size();
  const int err = errno;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) {
    throw FileError(final_path, std::string("write failed: ") + std::strerror(ok ? errno : err));
  }
}

// One PNG through libpng's simplified API: grey (1 byte a pixel) or RGB (3).
void write_png_pixels(AtomicOutput &out, int width, int height, png_uint_32 format, const uint8_t *pixels) {
  const std::string &path = out.final_path();
  FILE *f = out.take_stdio();
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = format;
  const auto stride = static_cast<png_int_32>(PNG_IMAGE_PIXEL_CHANNELS(format) * width);
  const int ok = png_image_write_to_stdio(&image, f, 0, pixels, stride, nullptr);
  const std::string message = ok ? std::string() : std::string(image.message);
  png_image_free(&image);
  const bool closed = std::fclose(f) == 0;
  if (!ok) throw FileError(path, "PNG write failed: " + message, ErrorCode::Io);
  if (!closed) throw FileError(path, std::string("write failed: ") + std::strerror(errno), ErrorCode::Io);
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

std::string map_server_options_problem(const MapServerOptions &o, const std::string &free_name,
                                       const std::string &occupied_name, const std::string &negate_name) {
  const auto text = [](double v) { return number_text(v); };
  if (!(o.free_thresh >= 0.0 && o.free_thresh <= 1.0))
    return free_name + " " + text(o.free_thresh) + ": must be a number from 0 to 1";
  if (!(o.occupied_thresh >= 0.0 && o.occupied_thresh <= 1.0))
    return occupied_name + " " + text(o.occupied_thresh) + ": must be a number from 0 to 1";
  if (!(o.free_thresh < o.occupied_thresh))
    return free_name + " " + text(o.free_thresh) + " must be below " + occupied_name + " " + text(o.occupied_thresh);
  if (o.negate && o.mode == PgmMode::Raw)
    return negate_name + " does not go with mode raw: ROS 1's map_server negates a raw image and nav2's does not, "
                         "so the two would read it differently";
  if (o.mode == PgmMode::Trinary && unknown_level(o) < 0)
    return free_name + " " + text(o.free_thresh) + " and " + occupied_name + " " + text(o.occupied_thresh) +
           " leave no grey level between them for unknown cells (map_server reads level v as occupancy "
           "(255 - v) / 255)";
  return {};
}

TrinaryLevels trinary_levels(const MapServerOptions &o) {
  const std::string problem = map_server_options_problem(o);
  if (!problem.empty()) throw std::invalid_argument(problem);
  TrinaryLevels t;
  t.occupied = kPgmOccupied;  // occupancy 1: occupied under any occupied_thresh below 1
  // 254 reads as 1/255; under a smaller free_thresh only 255 (occupancy 0) is free.
  t.free = level_occupancy(kPgmFree) < o.free_thresh - kLevelMargin || o.free_thresh == 0.0 ? kPgmFree : 255;
  t.unknown = static_cast<uint8_t>(unknown_level(o));
  return t;
}

uint8_t map_server_pixel(float value, const MapServerOptions &o) {
  const bool unknown = is_unknown(value);
  const bool offlimits = !unknown && is_offlimits(value);
  const double p = clamp01(value);
  uint8_t level = kPgmUnknown;
  switch (o.mode) {
    case PgmMode::Trinary: {
      const TrinaryLevels t = trinary_levels(o);
      if (unknown) {
        level = t.unknown;
      } else if (offlimits || p > o.occupied_thresh) {
        level = t.occupied;
      } else if (p < o.free_thresh) {
        level = t.free;
      } else {
        level = t.unknown;
      }
      break;
    }
    case PgmMode::Scale:
      level = unknown ? kPgmUnknown : offlimits ? 0 : static_cast<uint8_t>(std::lround(255.0 * (1.0 - p)));
      break;
    case PgmMode::Raw:
      return unknown ? kPgmRawUnknown : offlimits ? 100 : static_cast<uint8_t>(std::lround(100.0 * p));
  }
  return o.negate ? static_cast<uint8_t>(255 - level) : level;
}

uint8_t pgm_pixel(float value, PgmMode mode) {
  MapServerOptions o;
  o.mode = mode;
  return map_server_pixel(value, o);
}

uint8_t png_pixel(float value) {
  if (is_unknown(value)) return kPngUnknown;
  if (is_offlimits(value)) return 0;
  return static_cast<uint8_t>(std::lround(255.0 * (1.0 - clamp01(value))));
}

std::vector<uint8_t> map_to_pgm_pixels(const GridMap &map, PgmMode mode) {
  MapServerOptions o;
  o.mode = mode;
  return map_to_pgm_pixels(map, o);
}

std::vector<uint8_t> map_to_pgm_pixels(const GridMap &map, const MapServerOptions &o) {
  if (o.mode != PgmMode::Trinary) return render(map, [&o](float v) { return map_server_pixel(v, o); });
  // Trinary: the levels once, not a cell at a time.
  const TrinaryLevels t = trinary_levels(o);
  const auto neg = [&o](uint8_t v) { return o.negate ? static_cast<uint8_t>(255 - v) : v; };
  const uint8_t occ = neg(t.occupied), fr = neg(t.free), unk = neg(t.unknown);
  return render(map, [&](float v) {
    if (is_unknown(v)) return unk;
    if (is_offlimits(v) || double(v) > o.occupied_thresh) return occ;
    return clamp01(v) < o.free_thresh ? fr : unk;
  });
}

std::vector<uint8_t> map_to_picture_rgb(const GridMap &map) {
  const std::vector<uint8_t> grey = render(map, png_pixel);
  // Which cells are unknown, in the same row order.
  const std::vector<uint8_t> unknown = render(map, [](float v) { return uint8_t(is_unknown(v) ? 1 : 0); });
  std::vector<uint8_t> rgb(grey.size() * 3);
  for (size_t i = 0; i < grey.size(); ++i) {
    uint8_t *px = rgb.data() + 3 * i;
    if (unknown[i]) {
      px[0] = kPictureUnknown.r;
      px[1] = kPictureUnknown.g;
      px[2] = kPictureUnknown.b;
    } else {
      px[0] = px[1] = px[2] = grey[i];
    }
  }
  return rgb;
}

std::string yaml_path_for(const std::string &pgm_path) {
  const size_t slash = pgm_path.find_last_of('/');
  const size_t dot = pgm_path.find_last_of('.');
  const size_t name_start = slash == std::string::npos ? 0 : slash + 1;
  if (dot == std::string::npos || dot <= name_start) return pgm_path + ".yaml";
  return pgm_path.substr(0, dot) + ".yaml";
}

// A file name as a YAML scalar: plain when it is made of letters, digits and
// "._+-/" only, else double-quoted with escapes, so that a name with quotes,
// colons or line breaks cannot add keys.
std::string yaml_quoted(const std::string &text) {
  bool plain = !text.empty() && text[0] != '-' && text[0] != '.';
  for (unsigned char c : text) plain = plain && (std::isalnum(c) || c == '.' || c == '_' || c == '+' || c == '-' || c == '/');
  if (plain) return text;
  std::string q = "\"";
  for (unsigned char c : text) {
    if (c == '"' || c == '\\') {
      q += '\\';
      q += static_cast<char>(c);
    } else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      q += buf;
    } else {
      q += static_cast<char>(c);
    }
  }
  return q + "\"";
}

void write_map_server_pair(AtomicOutput &image, AtomicOutput &yaml_out, const GridMap &map,
                           const GlobalOffset &origin_of_cell00, const MapServerOptions &o, MapImageKind kind) {
  const std::string problem = map_server_options_problem(o);
  if (!problem.empty()) throw std::invalid_argument(yaml_out.final_path() + ": " + problem);
  const std::vector<uint8_t> pixels = map_to_pgm_pixels(map, o);
  std::string yaml;
  yaml += "image: " + yaml_quoted(file_name_of(image.final_path())) + "\n";
  yaml += "mode: " + std::string(pgm_mode_name(o.mode)) + "\n";
  // The resolution as the float it is in a CARMEN map and in ROS's
  // MapMetaData (0.05, not 0.05000000074505806); the origin keeps its
  // double, as the .map's OFFSET and the tf tree do (a UTM northing of
  // 5.4e6 m as a float is off by up to 0.25 m).
  yaml += "resolution: " + yaml_float_text_of_float(map.resolution) + "\n";
  yaml += "origin: [" + yaml_float_text(origin_of_cell00.x) + ", " + yaml_float_text(origin_of_cell00.y) + ", " +
          yaml_float_text(origin_of_cell00.theta) + "]\n";
  yaml += std::string("negate: ") + (o.negate ? "1" : "0") + "\n";
  yaml += "occupied_thresh: " + yaml_float_text(o.occupied_thresh) + "\n";
  yaml += "free_thresh: " + yaml_float_text(o.free_thresh) + "\n";
  if (kind == MapImageKind::Pgm) {
    write_all(image, "P5\n" + std::to_string(map.size_x) + " " + std::to_string(map.size_y) + "\n255\n", pixels);
  } else if (o.mode == PgmMode::Scale) {
    // Grey + alpha: unknown transparent, every known cell opaque.
    const std::vector<uint8_t> unknown = render(map, [](float v) { return uint8_t(is_unknown(v) ? 1 : 0); });
    std::vector<uint8_t> ga(pixels.size() * 2);
    for (size_t i = 0; i < pixels.size(); ++i) {
      ga[2 * i] = pixels[i];
      ga[2 * i + 1] = unknown[i] ? 0 : 255;
    }
    write_png_pixels(image, map.size_x, map.size_y, PNG_FORMAT_GA, ga.data());
  } else {
    write_png_pixels(image, map.size_x, map.size_y, PNG_FORMAT_GRAY, pixels.data());
  }
  write_all(yaml_out, yaml, {});
}

void write_pgm_with_yaml(AtomicOutput &pgm, AtomicOutput &yaml_out, const GridMap &map,
                         const GlobalOffset &origin_of_cell00, PgmMode mode) {
  MapServerOptions o;
  o.mode = mode;
  write_map_server_pair(pgm, yaml_out, map, origin_of_cell00, o, MapImageKind::Pgm);
}

void write_pgm_with_yaml(const std::string &pgm_path, const GridMap &map,
                         const GlobalOffset &origin_of_cell00, PgmMode mode) {
  const std::string yaml_path = yaml_path_for(pgm_path);
  if (yaml_path == pgm_path)
    throw std::invalid_argument(pgm_path + ": the image and its YAML would be one file");
  OutputTransaction tx;  // both files, or neither; the pair from one run
  AtomicOutput &pgm = tx.add(pgm_path);
  AtomicOutput &yaml = tx.add(yaml_path);
  write_pgm_with_yaml(pgm, yaml, map, origin_of_cell00, mode);
  tx.commit();
}

void write_png(AtomicOutput &out, const GridMap &map) {
  const std::vector<uint8_t> rgb = map_to_picture_rgb(map);
  write_png_pixels(out, map.size_x, map.size_y, PNG_FORMAT_RGB, rgb.data());
}

void write_rgb_png(AtomicOutput &out, int width, int height, const std::vector<uint8_t> &rgb) {
  if (width <= 0 || height <= 0 || rgb.size() != size_t(width) * size_t(height) * 3)
    throw std::invalid_argument(out.final_path() + ": an RGB picture of " + std::to_string(width) + " x " +
                                std::to_string(height) + " needs 3 bytes a pixel, not " +
                                std::to_string(rgb.size()) + " bytes");
  write_png_pixels(out, width, height, PNG_FORMAT_RGB, rgb.data());
}

void write_rgb_png(const std::string &path, int width, int height, const std::vector<uint8_t> &rgb) {
  AtomicOutput out(path);
  write_rgb_png(out, width, height, rgb);
  out.commit();
}

void write_png(const std::string &path, const GridMap &map) {
  AtomicOutput out(path);
  write_png(out, map);
  out.commit();
}

}  // namespace carmen
