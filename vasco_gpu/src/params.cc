// The parameter table and what reads it: validation, from_params, the key list.
#include "vasco_gpu/params.h"

#include <cctype>
#include <climits>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "carmen_compat/ini_file.h"
#include "vasco_gpu/internal/oracle.h"

namespace vasco {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kLongMax = static_cast<double>(LONG_MAX);
// Largest distance table per axis: CARMEN's i*i + j*j is an int, and the
// oracle's cut of the walk after table_size steps relies on
// 1e6 >= range_max (see oracle.h).
constexpr double kMaxTableSize = 32767;
// The map file stores the resolution (times the downsample) as a float: it
// must stay a positive, finite float there.
constexpr double kMinResolution = 1e-6, kMaxResolution = 1e6;
constexpr double kMaxRange = 1e5;

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

using P = MapperParams;

// key, name, real, whole, default, lo, hi, lo_open, hi_open, minus_one_ok, rule, meaning.
// Built on first use, so that other units' static initialisers may read it.
const std::vector<ParamSpec> &table() {
  static const std::vector<ParamSpec> rows = {
    {"vasco_resolution", "resolution", &P::resolution, nullptr, 0.025, kMinResolution, kMaxResolution, false,
     false, false, "must be between 1e-6 and 1e6 m per cell", "evidence grid cell size (m; the map's is this x vasco_downsample)"},
    {"vasco_p_prior", "p_prior", &P::p_prior, nullptr, 0.5, 0, 1, true, true, false,
     "must be strictly between 0 and 1", "prior occupancy"},
    {"vasco_p_occ", "p_occ", &P::p_occ, nullptr, 0.55, 0, 1, true, true, false,
     "must be strictly between 0 and 1", "evidence of a hit"},
    {"vasco_p_emp", "p_emp", &P::p_emp, nullptr, 0.45, 0, 1, true, true, false,
     "must be strictly between 0 and 1", "evidence of a free cell"},
    {"vasco_range_sure", "range_sure", &P::range_sure, nullptr, 5.0, 0, kInf, false, false, false,
     "must satisfy 0 <= range_sure <= range_max", "full-confidence range (m)"},
    {"vasco_range_max", "range_max", &P::range_max, nullptr, 10.0, 0, kMaxRange, true, false, false,
     "must be > 0 and at most 100000 m (with 0 no cell is ever updated)", "evidence ends here (m)"},
    {"vasco_wall_size", "wall_size", &P::wall_size, nullptr, 0.2, 0, kInf, false, true, false,
     "must be a finite number >= 0", "thickness marked occupied behind a hit (m)"},
    {"vasco_downsample", "downsample", nullptr, &P::downsample, 4, 1, 1e6, false, false, false,
     "must be between 1 and 1000000", "finish: block size"},
    {"vasco_border", "border", nullptr, &P::border, 20, 0, 1e6, false, false, false,
     "must be between 0 and 1000000", "finish: cells kept around the known area"},
    {"vasco_first_scan", "first_scan", nullptr, &P::first_scan, 0, 0, kLongMax, false, false, false,
     "must be >= 0", "first laser message used"},
    {"vasco_num_scans", "num_scans", nullptr, &P::num_scans, -1, 1, kLongMax, false, false, true,
     "must be >= 1 (or -1 for all)", "number of laser messages used"},
  };
  return rows;
}

[[noreturn]] void refuse(const ParamSpec &s, const MapperParams &p, const std::string &rule) {
  const double v = s.get(p);
  throw ParamError(s.key, std::string(s.key) + " = " + (s.integer() ? std::to_string(p.*s.whole) : fmt(v)) +
                              ": " + rule);
}

// The rules that join two keys, after each value is in its own bounds.
void check_joint_rules(const MapperParams &p) {
  if (p.range_sure > p.range_max)
    refuse(*find_param("range_sure"), p, std::string(find_param("range_sure")->rule) + " (" + fmt(p.range_max) + ")");
  if (p.range_max / p.resolution > kMaxTableSize)
    throw ParamError("vasco_range_max", "vasco_range_max / vasco_resolution = " + fmt(p.range_max / p.resolution) +
                                            " cells: must not exceed " + fmt(kMaxTableSize));
}

// The key a failed check is to be reported at: the file's line of it, and for
// the range_max / resolution ratio whichever of the two the file defines.
std::string key_in_file(const carmen::ParamFile &params, const std::string &key) {
  if (!params.has(key) && key == "vasco_range_max") return "vasco_resolution";
  return key;
}

// vasco's own keys in CARMEN's carmen.ini (scan matching, not the evidence
// grid) are not typos.
bool carmens_own_vasco_key(std::string name) {
  for (char &c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return name.rfind("vasco_local_map_", 0) == 0 || name == "vasco_max_usable_laser_range";
}

}  // namespace

void ParamSpec::set(MapperParams &p, double v) const {
  if (integer())
    p.*whole = static_cast<long>(v);
  else
    p.*real = v;
}

bool ParamSpec::valid(double v) const {
  if (minus_one_ok && v == -1) return true;
  const bool above = lo_open ? v > lo : v >= lo;
  const bool below = hi_open ? v < hi : v <= hi;
  return above && below;  // false for NaN
}

const std::vector<ParamSpec> &param_table() { return table(); }

const ParamSpec *find_param(const std::string &key_or_name) {
  for (const ParamSpec &s : table())
    if (key_or_name == s.key || key_or_name == s.name) return &s;
  return nullptr;
}

const std::vector<std::string> &mapper_param_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k;
    for (const ParamSpec &s : table()) k.push_back(s.key);
    return k;
  }();
  return keys;
}

int MapperParams::table_size() const {
  return oracle::distance_table_size(range_max, resolution);
}

void MapperParams::set_map_resolution(double cell, bool keep_downsample) {
  const std::string what = "map resolution " + fmt(cell) + " m";
  if (!(std::isfinite(cell) && cell > 0)) throw ParamError("map_resolution", what + ": must be a finite number > 0");
  MapperParams p = *this;
  if (!keep_downsample) {
    const double blocks = std::round(cell / resolution);  // resolution is valid: > 0
    const ParamSpec &ds = *find_param("downsample");
    p.downsample = static_cast<long>(std::min(std::max(blocks, ds.lo), ds.hi));
  }
  p.resolution = cell / static_cast<double>(p.downsample);
  try {
    p.validate();
  } catch (const ParamError &e) {
    throw ParamError("map_resolution", what + " (vasco_resolution = " + fmt(p.resolution) + " m per cell x vasco_downsample " +
                                           std::to_string(p.downsample) + "): " + e.what());
  }
  *this = p;
}

void MapperParams::validate() const {
  for (const ParamSpec &s : table())
    if (!s.valid(s.get(*this))) refuse(s, *this, s.rule);
  check_joint_rules(*this);
}

MapperParams MapperParams::from_params(const carmen::ParamFile &params, std::vector<std::string> *warnings) {
  MapperParams p;
  for (const ParamSpec &s : table()) {
    if (!params.has(s.key)) continue;
    if (s.integer())
      p.*s.whole = params.get_int(s.key);
    else
      p.*s.real = params.get_double(s.key);
  }
  try {
    p.validate();
  } catch (const ParamError &e) {  // where the bad value came from
    const auto where = params.find(key_in_file(params, e.key()));
    if (!where) throw;
    const carmen::ErrorCode code = where->line > 0 ? carmen::ErrorCode::BadInput : carmen::ErrorCode::Usage;
    throw carmen::FileError(where->file, where->line, e.what(), code);
  }
  if (warnings != nullptr) {
    for (const auto &u : params.unknown_in_module("vasco", mapper_param_keys())) {
      if (carmens_own_vasco_key(u.name)) continue;
      warnings->push_back(u.where() + ": unknown parameter " + u.name + " (ignored; a typo?)");
    }
  }
  return p;
}

}  // namespace vasco
