// Reading map images back: PNG (libpng) and map_server's PGM + YAML pair.
#include <png.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <new>
#include <sstream>
#include <string>

#include "carmen_compat/error.h"
#include "carmen_compat/input_file.h"
#include "carmen_compat/image_io.h"
#include "carmen_compat/map_file.h"

namespace carmen {
namespace {

// Images larger than this are refused before their pixels are allocated
// (the bound of CARMEN's own grids: 2^30 cells of 4 bytes).
constexpr uint64_t kMaxImagePixels = uint64_t(1) << 30;
// A map read from an image holds 4 bytes a pixel as a grid, and as much
// again while a PNG is decoded (RGBA): the grid may take what a CARMEN map's
// chunks may (MapReadOptions::max_kept_bytes, 1 GiB), checked against the
// declared size before anything is allocated. A 1-bit 32768 x 32768 PNG of
// 130 KB is a valid image (deflate does shrink zeros that far), but not one
// to decode into 4 GiB.
constexpr uint64_t kBytesPerMapCell = sizeof(float);
constexpr uint64_t kMaxYamlBytes = 1 << 20;

// Deflate's largest expansion: a compressed stream of n bytes inflates to at
// most about 1032 n (zlib's figure), so a PNG's pixel data cannot outgrow
// its file by more than that.
constexpr uint64_t kMaxDeflateRatio = 1032;

void check_image_size(const std::string &path, uint64_t width, uint64_t height) {
  // width * height > 2^30, without the product (a PGM's dimensions go up to
  // 10^12 - 1 each, so it could wrap).
  const bool empty = width == 0 || height == 0;
  const bool too_many = !empty && (width > kMaxImagePixels || height > kMaxImagePixels / width);
  if (empty || too_many || width > uint64_t(std::numeric_limits<int>::max()) ||
      height > uint64_t(std::numeric_limits<int>::max()))
    throw FileError(path, "image of " + std::to_string(width) + " x " + std::to_string(height) +
                              " pixels: not a map this reader takes (1 to 2^30 pixels)",
                    too_many ? ErrorCode::TooLarge : ErrorCode::BadInput);
}

// An image of a plausible size whose grid would still pass the map budget
// (kBytesPerMapCell); after check_image_size (no wrap: at most 2^30 pixels).
void check_map_budget(const std::string &path, uint64_t width, uint64_t height) {
  const uint64_t budget = MapReadOptions{}.max_kept_bytes;
  if (width * height > budget / kBytesPerMapCell)
    throw FileError(path, "image of " + std::to_string(width) + " x " + std::to_string(height) + " pixels: as a map " +
                              std::to_string(width * height * kBytesPerMapCell >> 20) + " MiB, more than the " +
                              std::to_string(budget >> 20) + " MiB a map may hold (as a CARMEN map's chunks): "
                              "refused before its pixels are decoded",
                    ErrorCode::TooLarge);
}

// The size of a file to be read, which must be a regular one (a FIFO or a
// device would block or never end). Throws FileError (Io).
uint64_t regular_file_size(const std::string &path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0)
    throw FileError(path, std::string("cannot open: ") + std::strerror(errno), ErrorCode::Io);
  return require_regular_file(path, "an image");
}

// std::bad_alloc from `read` as a FileError naming the file.
template <typename F>
auto with_memory_error(const std::string &path, F &&read) -> decltype(read()) {
  try {
    return read();
  } catch (const std::bad_alloc &) {
    throw FileError(path, "out of memory while reading the image", ErrorCode::OutOfMemory);
  }
}

std::string whole_file(const std::string &path, uint64_t limit) {
  const uint64_t size = regular_file_size(path);
  if (size > limit)
    throw FileError(path, "is " + std::to_string(size) + " bytes, more than a map's " +
                              std::to_string(limit) + " allow");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(path, std::string("cannot open: ") + std::strerror(errno), ErrorCode::Io);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// ---------------------------------------------------------------------------
// PGM (P5): header fields separated by whitespace, '#' comments to the end
// of a line, then one whitespace byte and width * height bytes.
// ---------------------------------------------------------------------------
struct PgmImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rows;
};

class PgmHeader {
 public:
  PgmHeader(const std::string &path, const std::string &bytes) : path_(path), b_(bytes) {}
  uint64_t number(const char *what) {
    skip_space_and_comments();
    uint64_t v = 0;
    size_t digits = 0;
    for (; i_ < b_.size() && b_[i_] >= '0' && b_[i_] <= '9' && digits < 12; ++i_, ++digits) v = v * 10 + (b_[i_] - '0');
    if (digits == 0 || digits == 12) throw FileError(path_, std::string("PGM header: bad or missing ") + what);
    return v;
  }
  size_t pixels_start() {  // the single whitespace byte after maxval
    if (i_ >= b_.size() || !std::isspace(static_cast<unsigned char>(b_[i_])))
      throw FileError(path_, "PGM header: no whitespace before the pixels");
    return i_ + 1;
  }

 private:
  void skip_space_and_comments() {
    while (i_ < b_.size()) {
      if (b_[i_] == '#') {
        while (i_ < b_.size() && b_[i_] != '\n') ++i_;
      } else if (std::isspace(static_cast<unsigned char>(b_[i_]))) {
        ++i_;
      } else {
        break;
      }
    }
  }
  const std::string &path_;
  const std::string &b_;
  size_t i_ = 2;  // after the magic
};

PgmImage read_pgm(const std::string &path) {
  const std::string bytes = whole_file(path, kMaxImagePixels + 4096);
  if (bytes.compare(0, 2, "P5") != 0)
    throw FileError(path, "is not a binary PGM (P5): map_server images are written as P5");
  PgmHeader h(path, bytes);
  const uint64_t width = h.number("width"), height = h.number("height"), maxval = h.number("maxval");
  check_image_size(path, width, height);
  if (maxval == 0 || maxval > 255)
    throw FileError(path, "PGM maxval " + std::to_string(maxval) + ": only 8-bit images (1 to 255) are read");
  const size_t at = h.pixels_start();
  if (bytes.size() - at < width * height)
    throw FileError(path, "is cut short: " + std::to_string(width) + " x " + std::to_string(height) +
                              " pixels need " + std::to_string(width * height) + " bytes, " +
                              std::to_string(bytes.size() - at) + " follow the header");
  check_map_budget(path, width, height);
  PgmImage img{int(width), int(height), std::vector<uint8_t>(bytes.begin() + long(at), bytes.begin() + long(at + width * height))};
  if (maxval != 255)
    for (uint8_t &v : img.rows) v = uint8_t(std::lround(255.0 * std::min<uint64_t>(v, maxval) / double(maxval)));
  return img;
}

// Either image as map_server sees it: per pixel the sum of its three colour
// channels (a grey pixel v: 3 v) and, when the image has one, its alpha.
struct MapImage {
  int width = 0, height = 0;
  std::vector<uint16_t> rgb_sum;
  std::vector<uint8_t> alpha;  // empty: no alpha channel
};

MapImage pgm_as_map_image(PgmImage &&p) {
  MapImage m{p.width, p.height, std::vector<uint16_t>(p.rows.size()), {}};
  for (size_t i = 0; i < p.rows.size(); ++i) m.rgb_sum[i] = uint16_t(3 * p.rows[i]);
  return m;
}

// Any PNG through libpng's simplified API as 8-bit RGBA (grey expanded to
// three equal channels, no alpha read as opaque).
struct Rgba {
  int width = 0, height = 0;
  bool has_alpha = false, has_colour = false;
  std::vector<uint8_t> px;  // 4 bytes a pixel, row 0 at the top
};

// The bits a pixel takes in the file, from its IHDR (bit depth and colour
// type, bytes 24 and 25); 1, the least, when they cannot be read.
uint64_t png_file_bits_per_pixel(const std::string &path) {
  unsigned char h[26] = {};
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char *>(h), sizeof h);
  if (in.gcount() != std::streamsize(sizeof h) || std::memcmp(h + 12, "IHDR", 4) != 0) return 1;
  const uint64_t depth = h[24];
  switch (h[25]) {
    case 0: return depth;      // grey
    case 2: return 3 * depth;  // RGB
    case 3: return depth;      // palette index
    case 4: return 2 * depth;  // grey and alpha
    case 6: return 4 * depth;  // RGBA
    default: return 1;
  }
}

Rgba read_png_file_rgba(const std::string &path) {
  const uint64_t file_size = regular_file_size(path);
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path.c_str()))
    throw FileError(path, std::string("cannot read PNG: ") + img.message);
  Rgba out;
  out.has_alpha = (img.format & PNG_FORMAT_FLAG_ALPHA) != 0;
  out.has_colour = (img.format & PNG_FORMAT_FLAG_COLOR) != 0;
  img.format = PNG_FORMAT_RGBA;
  try {
    check_image_size(path, img.width, img.height);
    // The pixel data inflated from the file's IDAT chunks holds at least
    // width * height * bits-per-pixel / 8 bytes: more than the file's bytes
    // could inflate to is a damaged or hostile header, refused before the
    // 4 bytes a pixel are allocated.
    const uint64_t bits = std::max<uint64_t>(1, png_file_bits_per_pixel(path));
    const uint64_t min_data = uint64_t(img.width) * img.height * bits / 8;
    if (min_data / kMaxDeflateRatio > file_size)
      throw FileError(path, "PNG of " + std::to_string(img.width) + " x " + std::to_string(img.height) +
                                " pixels in only " + std::to_string(file_size) +
                                " bytes: more than its compressed data can hold (the header is damaged)",
                      ErrorCode::BadInput);
    check_map_budget(path, img.width, img.height);
    out.px.resize(size_t(img.width) * size_t(img.height) * 4);  // PNG_IMAGE_SIZE is 32-bit: wraps at 2^30
  } catch (...) {
    png_image_free(&img);
    throw;
  }
  if (!png_image_finish_read(&img, nullptr, out.px.data(), 0, nullptr)) {
    const std::string msg = img.message;
    png_image_free(&img);
    throw FileError(path, "cannot read PNG: " + msg);
  }
  out.width = int(img.width);
  out.height = int(img.height);
  return out;
}

MapImage read_png_rgba(const std::string &path) {
  const Rgba r = read_png_file_rgba(path);
  const size_t n = size_t(r.width) * size_t(r.height);
  MapImage m{r.width, r.height, std::vector<uint16_t>(n), {}};
  if (r.has_alpha) m.alpha.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t *p = r.px.data() + 4 * i;
    m.rgb_sum[i] = uint16_t(p[0] + p[1] + p[2]);
    if (r.has_alpha) m.alpha[i] = p[3];
  }
  return m;
}

// A PGM or a PNG, told apart by the first bytes.
MapImage read_map_image(const std::string &path) {
  regular_file_size(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(path, std::string("cannot open: ") + std::strerror(errno), ErrorCode::Io);
  char magic[8] = {};
  in.read(magic, sizeof magic);
  const std::streamsize got = in.gcount();
  in.close();
  if (got == 8 && std::memcmp(magic, "\x89PNG\r\n\x1a\n", 8) == 0) return read_png_rgba(path);
  if (got >= 2 && magic[0] == 'P' && magic[1] == '5') return pgm_as_map_image(read_pgm(path));
  if (got >= 2 && magic[0] == 'P' && (magic[1] == '2' || magic[1] == '1' || magic[1] == '4'))
    throw FileError(path, std::string("is a P") + magic[1] + " image: only binary greyscale PGMs (P5) are read");
  throw FileError(path, "is neither a binary PGM (P5) nor a PNG: the map images this reader takes");
}

// ---------------------------------------------------------------------------
// map_server's YAML: flat "key: value" lines.
// ---------------------------------------------------------------------------
struct YamlValue {
  std::string text;
  long line = 0;
};

std::string trim(const std::string &s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// A value without its trailing comment; a double-quoted one keeps its '#'.
std::string value_text(const std::string &raw) {
  const std::string v = trim(raw);
  if (!v.empty() && v[0] == '"') return v;
  const size_t hash = v.find(" #");
  return trim(hash == std::string::npos ? v : v.substr(0, hash));
}

std::map<std::string, YamlValue> parse_flat_yaml(const std::string &path, const std::string &text) {
  std::map<std::string, YamlValue> keys;
  // A UTF-8 byte order mark (some Windows editors write one) is no part of the first key.
  const bool bom = text.compare(0, 3, "\xEF\xBB\xBF") == 0;
  std::istringstream in(bom ? text.substr(3) : text);
  std::string line;
  for (long n = 1; std::getline(in, line); ++n) {
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#' || t == "---") continue;
    const size_t colon = t.find(':');
    if (colon == std::string::npos || colon == 0)
      throw FileError(path, n, "not a \"key: value\" line of map_server's YAML: " + printable(t.substr(0, 60)));
    const std::string key = trim(t.substr(0, colon));
    if (keys.count(key)) throw FileError(path, n, "key \"" + printable(key) + "\" given twice");
    keys[key] = YamlValue{value_text(t.substr(colon + 1)), n};
  }
  return keys;
}

double yaml_number(const std::string &path, const YamlValue &v, const char *key) {
  char *end = nullptr;
  errno = 0;
  const double d = std::strtod(v.text.c_str(), &end);
  if (v.text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(d))
    throw FileError(path, v.line, std::string(key) + ": \"" + printable(v.text) + "\" is not a finite number");
  return d;
}

GlobalOffset yaml_origin(const std::string &path, const YamlValue &v) {
  const std::string &t = v.text;
  if (t.size() < 2 || t.front() != '[' || t.back() != ']')
    throw FileError(path, v.line, "origin: expected [x, y, theta], got \"" + printable(t) + "\"");
  std::vector<double> xyz;
  std::istringstream parts(t.substr(1, t.size() - 2));
  for (std::string part; std::getline(parts, part, ',');)
    xyz.push_back(yaml_number(path, YamlValue{trim(part), v.line}, "origin"));
  if (xyz.size() != 3) throw FileError(path, v.line, "origin: expected 3 numbers [x, y, theta]");
  return GlobalOffset{xyz[0], xyz[1], xyz[2]};
}

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

struct YamlMeta {
  double resolution = 0;
  GlobalOffset origin;
  MapServerOptions options;
  std::string image;  // the image key, unquoted; empty when absent
  long image_line = 0;
};

const YamlValue &required(const std::string &path, const std::map<std::string, YamlValue> &keys, const char *key) {
  const auto it = keys.find(key);
  if (it == keys.end()) throw FileError(path, std::string("map_server YAML without the \"") + key + "\" key");
  return it->second;
}

// A YAML scalar without its quotes: "..." with backslash escapes (\" \\ \n
// \t \xNN, what write_map_server_pair writes), '...' with '' for a quote,
// or plain.
std::string yaml_unquoted(const std::string &path, const YamlValue &v, const char *key) {
  const std::string &t = v.text;
  if (t.empty() || (t[0] != '"' && t[0] != '\'')) return t;
  const char q = t[0];
  std::string out;
  size_t i = 1;
  for (; i < t.size(); ++i) {
    const char c = t[i];
    if (q == '\'' && c == '\'') {
      if (i + 1 < t.size() && t[i + 1] == '\'') {
        out += '\'';
        ++i;
        continue;
      }
      break;
    }
    if (q == '"' && c == '"') break;
    if (q == '"' && c == '\\' && i + 1 < t.size()) {
      const char e = t[++i];
      if (e == 'n') {
        out += '\n';
      } else if (e == 't') {
        out += '\t';
      } else if (e == 'x' && i + 2 < t.size() && std::isxdigit(static_cast<unsigned char>(t[i + 1])) &&
                 std::isxdigit(static_cast<unsigned char>(t[i + 2]))) {
        out += static_cast<char>(std::stoi(t.substr(i + 1, 2), nullptr, 16));
        i += 2;
      } else {
        out += e;
      }
      continue;
    }
    out += c;
  }
  if (i >= t.size()) throw FileError(path, v.line, std::string(key) + ": the quoted string is not closed");
  if (!trim(t.substr(i + 1)).empty() && trim(t.substr(i + 1))[0] != '#')
    throw FileError(path, v.line, std::string(key) + ": text after the closing quote");
  return out;
}

YamlMeta read_yaml_meta(const std::string &path) {
  const auto keys = parse_flat_yaml(path, whole_file(path, kMaxYamlBytes));
  YamlMeta m;
  const YamlValue &res = required(path, keys, "resolution");
  m.resolution = yaml_number(path, res, "resolution");
  if (!(m.resolution > 0)) throw FileError(path, res.line, "resolution must be positive");
  m.origin = yaml_origin(path, required(path, keys, "origin"));
  MapServerOptions &o = m.options;
  if (auto it = keys.find("mode"); it != keys.end() && !parse_pgm_mode(yaml_unquoted(path, it->second, "mode"), &o.mode))
    throw FileError(path, it->second.line, "mode \"" + printable(it->second.text) + "\": expected trinary, scale or raw");
  if (auto it = keys.find("negate"); it != keys.end()) {
    const std::string &t = it->second.text;
    if (t == "true" || t == "false") {  // nav2 takes a boolean too
      o.negate = t == "true";
    } else {
      const double n = yaml_number(path, it->second, "negate");
      if (n != 0 && n != 1) throw FileError(path, it->second.line, "negate must be 0 or 1");
      o.negate = n == 1;
    }
  }
  long thresh_line = 0;
  if (auto it = keys.find("occupied_thresh"); it != keys.end()) {
    o.occupied_thresh = yaml_number(path, it->second, "occupied_thresh");
    thresh_line = it->second.line;
  }
  if (auto it = keys.find("free_thresh"); it != keys.end()) {
    o.free_thresh = yaml_number(path, it->second, "free_thresh");
    thresh_line = std::max(thresh_line, it->second.line);
  }
  if (!(o.free_thresh >= 0 && o.free_thresh < o.occupied_thresh && o.occupied_thresh <= 1))
    throw FileError(path, thresh_line, "free_thresh " + short_number(o.free_thresh) + " and occupied_thresh " +
                                           short_number(o.occupied_thresh) +
                                           ": expected 0 <= free_thresh < occupied_thresh <= 1");
  if (auto it = keys.find("image"); it != keys.end()) {
    m.image = yaml_unquoted(path, it->second, "image");
    m.image_line = it->second.line;
  }
  return m;
}

// One pixel as map_server reads it (see image_io.h).
float map_cell(const MapImage &img, size_t i, const MapServerOptions &o) {
  const bool has_alpha = !img.alpha.empty();
  const double mean = has_alpha && o.mode == PgmMode::Trinary ? (img.rgb_sum[i] + img.alpha[i]) / 4.0
                                                               : img.rgb_sum[i] / 3.0;
  const double occ = o.negate ? mean / 255.0 : (255.0 - mean) / 255.0;
  switch (o.mode) {
    case PgmMode::Trinary: return occ > o.occupied_thresh ? 1.0f : occ < o.free_thresh ? 0.0f : kUnknownCell;
    case PgmMode::Scale: {
      if (has_alpha) return img.alpha[i] != 255 ? kUnknownCell : static_cast<float>(occ);
      const double level = o.negate ? 255.0 - mean : mean;
      return level == kPgmUnknown ? kUnknownCell : static_cast<float>(occ);
    }
    case PgmMode::Raw: {
      const long v = std::lround(mean);
      return v == kPgmRawUnknown ? kUnknownCell : static_cast<float>(double(v) / 100.0);
    }
  }
  return kUnknownCell;
}

void check_raw_levels(const std::string &path, const MapImage &img) {
  for (size_t i = 0; i < img.rgb_sum.size(); ++i) {
    const long v = std::lround(img.rgb_sum[i] / 3.0);
    if (v > 100 && v != kPgmRawUnknown)
      throw FileError(path, "pixel " + std::to_string(i) + " has level " + std::to_string(v) +
                                ": a raw-mode map holds 0..100 or 255 (unknown)");
  }
}

PgmMap map_from(const std::string &image_path, const MapImage &img, const YamlMeta &meta) {
  if (meta.options.mode == PgmMode::Raw) check_raw_levels(image_path, img);
  PgmMap out;
  GridMap &g = out.grid;
  g.size_x = img.width;
  g.size_y = img.height;
  g.resolution = meta.resolution;
  g.cells.resize(size_t(img.width) * size_t(img.height));
  const size_t w = size_t(img.width), h = size_t(img.height);
  for (size_t x = 0; x < w; ++x)
    for (size_t y = 0; y < h; ++y) g.cells[x * h + y] = map_cell(img, (h - 1 - y) * w + x, meta.options);
  out.origin = meta.origin;
  out.mode = meta.options.mode;
  out.options = meta.options;
  out.image_path = image_path;
  return out;
}

std::string resolved_image(const std::string &yaml_path, const YamlMeta &meta) {
  if (meta.image.empty()) throw FileError(yaml_path, "map_server YAML without the \"image\" key");
  if (meta.image[0] == '/') return meta.image;
  const size_t slash = yaml_path.find_last_of('/');
  return slash == std::string::npos ? meta.image : yaml_path.substr(0, slash + 1) + meta.image;
}

GridMap png_grid(const std::string &path) {
  const Rgba img = read_png_file_rgba(path);
  GridMap g;
  g.size_x = img.width;
  g.size_y = img.height;
  g.resolution = 0.0;
  g.cells.resize(size_t(img.width) * size_t(img.height));
  const size_t w = size_t(img.width), h = size_t(img.height);
  for (size_t x = 0; x < w; ++x) {
    for (size_t y = 0; y < h; ++y) {
      const uint8_t *p = img.px.data() + 4 * ((h - 1 - y) * w + x);
      float cell;
      if (img.has_colour) {  // a picture: its unknown colour, else the channels' mean
        const bool unknown = p[0] == kPictureUnknown.r && p[1] == kPictureUnknown.g && p[2] == kPictureUnknown.b;
        const bool grey = p[0] == p[1] && p[1] == p[2];
        cell = unknown ? kUnknownCell
                       : grey ? 1.0f - static_cast<float>(p[0]) / 255.0f
                              : 1.0f - static_cast<float>((p[0] + p[1] + p[2]) / 3.0 / 255.0);
      } else {  // grey: the older pictures' rule
        cell = p[0] == kPngUnknown ? kUnknownCell : 1.0f - static_cast<float>(p[0]) / 255.0f;
      }
      g.cells[x * h + y] = cell;
    }
  }
  return g;
}

}  // namespace

GridMap read_png(const std::string &path) {
  return with_memory_error(path, [&] { return png_grid(path); });
}

PgmMap read_image_with_yaml(const std::string &image_path, const std::string &yaml_path) {
  const YamlMeta meta = read_yaml_meta(yaml_path);
  return with_memory_error(image_path, [&] { return map_from(image_path, read_map_image(image_path), meta); });
}

PgmMap read_pgm_with_yaml(const std::string &pgm_path) {
  const std::string yaml_path = yaml_path_for(pgm_path);
  const YamlMeta meta = read_yaml_meta(yaml_path);
  return with_memory_error(pgm_path,
                           [&] { return map_from(pgm_path, pgm_as_map_image(read_pgm(pgm_path)), meta); });
}

std::string map_server_image_of(const std::string &yaml_path) {
  return resolved_image(yaml_path, read_yaml_meta(yaml_path));
}

PgmMap read_map_server_yaml(const std::string &yaml_path) {
  const YamlMeta meta = read_yaml_meta(yaml_path);
  const std::string image = resolved_image(yaml_path, meta);
  struct stat st;
  if (::stat(image.c_str(), &st) != 0)
    throw FileError(yaml_path, meta.image_line,
                    "image \"" + printable(meta.image) + "\": cannot open " + printable(image) + ": " +
                        std::strerror(errno), ErrorCode::Io);
  return with_memory_error(image, [&] { return map_from(image, read_map_image(image), meta); });
}

}  // namespace carmen
