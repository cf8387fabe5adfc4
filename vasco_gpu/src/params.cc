#include "vasco_gpu/params.h"

#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "carmen_compat/error.h"
#include "carmen_compat/ini_file.h"
#include "vasco_gpu/oracle.h"

namespace vasco {
namespace {

// Largest distance table per axis: CARMEN's i*i + j*j is an int, and the
// oracle's cut of the walk after table_size steps relies on
// 1e6 >= range_max (see oracle.h).
constexpr double kMaxTableSize = 32767;
constexpr double kMaxRange = 1e5;

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

// Returns an empty string when the values are valid, else what is wrong
// with which key.
std::string check(const MapperParams &p) {
  auto prob = [](const char *key, double v) -> std::string {
    if (!(v > 0 && v < 1)) return std::string(key) + " = " + fmt(v) + ": must be strictly between 0 and 1";
    return "";
  };
  std::string e;
  if (!(e = prob("vasco_p_prior", p.p_prior)).empty()) return e;
  if (!(e = prob("vasco_p_occ", p.p_occ)).empty()) return e;
  if (!(e = prob("vasco_p_emp", p.p_emp)).empty()) return e;
  // The map file stores the resolution (times the downsample) as a float:
  // it must stay a positive, finite float there.
  if (!(p.resolution >= 1e-6) || !(p.resolution <= 1e6))
    return "vasco_resolution = " + fmt(p.resolution) + ": must be between 1e-6 and 1e6 m per cell";
  if (!(p.range_max > 0) || !(p.range_max <= kMaxRange))
    return "vasco_range_max = " + fmt(p.range_max) + ": must be > 0 and at most " + fmt(kMaxRange) +
           " m (with 0 no cell is ever updated)";
  if (!(p.range_sure >= 0) || !(p.range_sure <= p.range_max))
    return "vasco_range_sure = " + fmt(p.range_sure) + ": must satisfy 0 <= range_sure <= range_max (" +
           fmt(p.range_max) + ")";
  if (!std::isfinite(p.wall_size) || p.wall_size < 0)
    return "vasco_wall_size = " + fmt(p.wall_size) + ": must be a finite number >= 0";
  if (p.range_max / p.resolution > kMaxTableSize)
    return "vasco_range_max / vasco_resolution = " + fmt(p.range_max / p.resolution) +
           " cells: must not exceed " + fmt(kMaxTableSize);
  if (p.downsample < 1 || p.downsample > 1000000)
    return "vasco_downsample = " + std::to_string(p.downsample) + ": must be >= 1";
  if (p.border < 0 || p.border > 1000000)
    return "vasco_border = " + std::to_string(p.border) + ": must be >= 0";
  if (p.first_scan < 0) return "vasco_first_scan = " + std::to_string(p.first_scan) + ": must be >= 0";
  if (p.num_scans < -1 || p.num_scans == 0)
    return "vasco_num_scans = " + std::to_string(p.num_scans) + ": must be >= 1 (or -1 for all)";
  return "";
}

}  // namespace

const std::vector<std::string> &mapper_param_keys() {
  static const std::vector<std::string> keys = {
      "vasco_resolution", "vasco_p_prior",   "vasco_p_occ",     "vasco_p_emp",
      "vasco_range_sure", "vasco_range_max", "vasco_wall_size", "vasco_downsample",
      "vasco_border",     "vasco_first_scan", "vasco_num_scans"};
  return keys;
}

int MapperParams::table_size() const {
  return oracle::distance_table_size(range_max, resolution);
}

void MapperParams::validate() const {
  const std::string e = check(*this);
  if (!e.empty()) throw std::invalid_argument(e);
}

MapperParams MapperParams::from_params(const carmen::ParamFile &params,
                                       std::vector<std::string> *warnings) {
  MapperParams p;
  struct Key {
    const char *name;
    double *d;
    long *l;
  };
  const Key keys[] = {
      {"vasco_resolution", &p.resolution, nullptr}, {"vasco_p_prior", &p.p_prior, nullptr},
      {"vasco_p_occ", &p.p_occ, nullptr},           {"vasco_p_emp", &p.p_emp, nullptr},
      {"vasco_range_sure", &p.range_sure, nullptr}, {"vasco_range_max", &p.range_max, nullptr},
      {"vasco_wall_size", &p.wall_size, nullptr},   {"vasco_downsample", nullptr, &p.downsample},
      {"vasco_border", nullptr, &p.border},         {"vasco_first_scan", nullptr, &p.first_scan},
      {"vasco_num_scans", nullptr, &p.num_scans},
  };
  for (const Key &k : keys) {
    if (!params.has(k.name)) continue;
    if (k.d != nullptr) *k.d = params.get_double(k.name);
    if (k.l != nullptr) *k.l = params.get_int(k.name);
  }
  // Validate key by key so that the error names where the bad value came from.
  const std::string e = check(p);
  if (!e.empty()) {
    // The key is the message's first word; for the range_max / resolution
    // ratio, whichever of the two the file defines.
    std::string key = e.substr(0, e.find(' '));
    if (!params.has(key) && key == "vasco_range_max") key = "vasco_resolution";
    const auto where = params.find(key);
    if (where && where->line > 0) throw carmen::FileError(where->file, where->line, e);
    if (where) throw std::invalid_argument(where->file + ": " + e);
    throw std::invalid_argument(e);
  }
  if (warnings != nullptr) {
    for (const auto &u : params.unknown_in_module("vasco", mapper_param_keys())) {
      // vasco's own keys in CARMEN's carmen.ini (scan matching, not the
      // evidence grid) are not typos: no warning for them.
      std::string lower = u.name;
      for (char &c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (lower.rfind("vasco_local_map_", 0) == 0 || lower == "vasco_max_usable_laser_range") continue;
      warnings->push_back(u.where() + ": unknown parameter " + u.name + " (ignored; a typo?)");
    }
  }
  return p;
}

}  // namespace vasco
