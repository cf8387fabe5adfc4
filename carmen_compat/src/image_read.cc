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
#include <sstream>
#include <string>

#include "carmen_compat/error.h"
#include "carmen_compat/image_io.h"

namespace carmen {
namespace {

// Images larger than this are refused before their pixels are allocated
// (the bound of CARMEN's own grids: 2^30 cells of 4 bytes).
constexpr uint64_t kMaxImagePixels = uint64_t(1) << 30;
constexpr uint64_t kMaxYamlBytes = 1 << 20;

void check_image_size(const std::string &path, uint64_t width, uint64_t height) {
  if (width == 0 || height == 0 || width > uint64_t(std::numeric_limits<int>::max()) ||
      height > uint64_t(std::numeric_limits<int>::max()) || width * height > kMaxImagePixels)
    throw FileError(path, "image of " + std::to_string(width) + " x " + std::to_string(height) +
                              " pixels: not a map this reader takes (1 to 2^30 pixels)",
                    width * height > kMaxImagePixels ? ErrorCode::TooLarge : ErrorCode::BadInput);
}

// Cells from rows of grey levels (row 0 at the top; image_io.h's orientation).
template <typename CellFn>
GridMap cells_from_rows(const std::vector<uint8_t> &rows, int width, int height, double resolution, CellFn cell) {
  GridMap g;
  g.size_x = width;
  g.size_y = height;
  g.resolution = resolution;
  g.cells.resize(size_t(width) * size_t(height));
  for (size_t x = 0; x < size_t(width); ++x)
    for (size_t y = 0; y < size_t(height); ++y)
      g.cells[x * size_t(height) + y] = cell(rows[(size_t(height) - 1 - y) * size_t(width) + x]);
  return g;
}

std::string whole_file(const std::string &path, uint64_t limit) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0)
    throw FileError(path, std::string("cannot open: ") + std::strerror(errno), ErrorCode::Io);
  if (!S_ISREG(st.st_mode)) throw FileError(path, "is not a regular file", ErrorCode::Io);
  if (uint64_t(st.st_size) > limit)
    throw FileError(path, "is " + std::to_string(st.st_size) + " bytes, more than a map's " +
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
  PgmImage img{int(width), int(height), std::vector<uint8_t>(bytes.begin() + long(at), bytes.begin() + long(at + width * height))};
  if (maxval != 255)
    for (uint8_t &v : img.rows) v = uint8_t(std::lround(255.0 * std::min<uint64_t>(v, maxval) / double(maxval)));
  return img;
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
  std::istringstream in(text);
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

struct YamlMeta {
  double resolution = 0;
  GlobalOffset origin;
  PgmMode mode = PgmMode::Trinary;
  bool negate = false;
  double occupied_thresh = kOccupiedThresh, free_thresh = kFreeThresh;
};

const YamlValue &required(const std::string &path, const std::map<std::string, YamlValue> &keys, const char *key) {
  const auto it = keys.find(key);
  if (it == keys.end()) throw FileError(path, std::string("map_server YAML without the \"") + key + "\" key");
  return it->second;
}

YamlMeta read_yaml_meta(const std::string &path) {
  const auto keys = parse_flat_yaml(path, whole_file(path, kMaxYamlBytes));
  YamlMeta m;
  const YamlValue &res = required(path, keys, "resolution");
  m.resolution = yaml_number(path, res, "resolution");
  if (!(m.resolution > 0)) throw FileError(path, res.line, "resolution must be positive");
  m.origin = yaml_origin(path, required(path, keys, "origin"));
  if (auto it = keys.find("mode"); it != keys.end() && !parse_pgm_mode(it->second.text, &m.mode))
    throw FileError(path, it->second.line, "mode \"" + printable(it->second.text) + "\": expected trinary, scale or raw");
  if (auto it = keys.find("negate"); it != keys.end()) {
    const double n = yaml_number(path, it->second, "negate");
    if (n != 0 && n != 1) throw FileError(path, it->second.line, "negate must be 0 or 1");
    m.negate = n == 1;
  }
  if (auto it = keys.find("occupied_thresh"); it != keys.end())
    m.occupied_thresh = yaml_number(path, it->second, "occupied_thresh");
  if (auto it = keys.find("free_thresh"); it != keys.end()) m.free_thresh = yaml_number(path, it->second, "free_thresh");
  return m;
}

// One grey level as map_server reads it (see image_io.h).
float pgm_cell(uint8_t v, const YamlMeta &m) {
  const double occ = m.negate ? v / 255.0 : (255 - v) / 255.0;
  switch (m.mode) {
    case PgmMode::Trinary: return occ > m.occupied_thresh ? 1.0f : occ < m.free_thresh ? 0.0f : kUnknownCell;
    case PgmMode::Scale: return v == kPgmUnknown ? kUnknownCell : static_cast<float>(occ);
    case PgmMode::Raw: return v == kPgmRawUnknown ? kUnknownCell : static_cast<float>(v / 100.0);
  }
  return kUnknownCell;
}

void check_raw_levels(const std::string &path, const std::vector<uint8_t> &rows) {
  for (size_t i = 0; i < rows.size(); ++i)
    if (rows[i] > 100 && rows[i] != kPgmRawUnknown)
      throw FileError(path, "pixel " + std::to_string(i) + " has level " + std::to_string(rows[i]) +
                                ": a raw-mode map holds 0..100 or 255 (unknown)");
}

}  // namespace

GridMap read_png(const std::string &path) {
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path.c_str()))
    throw FileError(path, std::string("cannot read PNG: ") + img.message);
  img.format = PNG_FORMAT_GRAY;
  try {
    check_image_size(path, img.width, img.height);
  } catch (...) {
    png_image_free(&img);
    throw;
  }
  std::vector<uint8_t> px(PNG_IMAGE_SIZE(img));
  if (!png_image_finish_read(&img, nullptr, px.data(), 0, nullptr)) {
    const std::string msg = img.message;
    png_image_free(&img);
    throw FileError(path, "cannot read PNG: " + msg);
  }
  return cells_from_rows(px, int(img.width), int(img.height), 0.0, [](uint8_t v) {
    return v == kPngUnknown ? kUnknownCell : 1.0f - static_cast<float>(v) / 255.0f;
  });
}

PgmMap read_pgm_with_yaml(const std::string &pgm_path) {
  const std::string yaml_path = yaml_path_for(pgm_path);
  const YamlMeta meta = read_yaml_meta(yaml_path);
  const PgmImage img = read_pgm(pgm_path);
  if (meta.mode == PgmMode::Raw) check_raw_levels(pgm_path, img.rows);
  PgmMap out;
  out.grid = cells_from_rows(img.rows, img.width, img.height, meta.resolution,
                             [&meta](uint8_t v) { return pgm_cell(v, meta); });
  out.origin = meta.origin;
  out.mode = meta.mode;
  return out;
}

}  // namespace carmen
