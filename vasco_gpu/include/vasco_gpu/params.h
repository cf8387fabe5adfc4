// params.h — the mapper's parameters (DESIGN §2), from a carmen.ini, a log's
// PARAM lines and command-line overrides, validated once.
#ifndef VASCO_GPU_PARAMS_H
#define VASCO_GPU_PARAMS_H

#include <string>
#include <tuple>
#include <vector>

#include "carmen_compat/error.h"

namespace carmen {
class ParamFile;
}

namespace vasco {

struct MapperParams {
  // vasco's defaults (vegrid.c); param_table() lists the same values, and
  // params_test checks that the two agree.
  double resolution = 0.025;  // vasco_resolution, m per cell
  double p_prior = 0.5;       // vasco_p_prior
  double p_occ = 0.55;        // vasco_p_occ
  double p_emp = 0.45;        // vasco_p_emp
  double range_sure = 5.0;    // vasco_range_sure, m
  double range_max = 10.0;    // vasco_range_max, m
  double wall_size = 0.2;     // vasco_wall_size, m
  long downsample = 4;        // vasco_downsample
  long border = 20;           // vasco_border, cells (of the downsampled map)
  long first_scan = 0;        // vasco_first_scan: index of the first laser message used
  long num_scans = -1;        // vasco_num_scans: how many (-1: all)
  double max_prob = 0.95;     // stored as CARMEN does; never used

  // Reads every vasco_* key present in `params` (the rest keep their
  // defaults) and validates; errors name the key and FILE:LINE. Unknown
  // vasco_* keys are appended to `warnings` (typos).
  static MapperParams from_params(const carmen::ParamFile &params, std::vector<std::string> *warnings);

  // Checks every value against param_table()'s bounds and the two rules
  // that join keys (0 <= range_sure <= range_max, range_max / resolution at
  // most 32767 cells); throws ParamError naming the key.
  void validate() const;

  // What the backends' per-(i, j) distance and evidence tables depend on:
  // a table built for one key serves every grid with the same key.
  using TableKey = std::tuple<int, double, double, double, double, double, double>;
  TableKey table_key() const {
    return {table_size(), resolution, p_prior, p_occ, p_emp, range_sure, range_max};
  }

  // Number of distance-table entries per axis: (int)(range_max / resolution).
  int table_size() const;

  // The written map's cell size in metres, resolution × downsample: what a
  // map_server YAML, an OccupancyGrid and ROS's `resolution` call resolution.
  double map_resolution() const { return resolution * static_cast<double>(downsample); }

  // Makes the written map's cells `cell` metres: the one rule from ROS's
  // resolution to CARMEN's two keys (docs/cli.md, "Map resolution"). A downsample that
  // was given (keep_downsample) stays and resolution = cell / downsample;
  // otherwise the evidence grid stays as near `resolution` as a whole block
  // allows: downsample = max(1, round(cell / resolution)), then resolution =
  // cell / downsample. With vasco's defaults, 0.1 gives exactly 0.025 × 4
  // and 0.05 gives 0.025 × 2. Throws ParamError (key "map_resolution") for a
  // cell that is not a finite number > 0 or whose evidence cell breaks the
  // table's rules; *this is unchanged then.
  void set_map_resolution(double cell, bool keep_downsample);
};

// A parameter value out of its range: code Usage, and the key (vasco_p_occ)
// that is wrong. from_params turns it into a FileError at the key's line.
class ParamError : public carmen::Error {
 public:
  ParamError(std::string key, const std::string &message)
      : carmen::Error(carmen::ErrorCode::Usage, message), key_(std::move(key)) {}
  const std::string &key() const { return key_; }

 private:
  std::string key_;
};

// One vasco_* parameter: the one place its key, member, default, bounds and
// meaning are written. Exactly one of `real` and `whole` is set.
struct ParamSpec {
  const char *key;   // carmen.ini key: vasco_resolution
  const char *name;  // the member's and the keyword's name: resolution
  double MapperParams::*real;
  long MapperParams::*whole;
  double default_value;  // vasco's default (num_scans: -1, all)
  double lo, hi;         // bounds of a valid value
  bool lo_open, hi_open; // whether lo, hi themselves are outside
  bool minus_one_ok;     // -1 is valid too (num_scans: all)
  const char *rule;      // the bounds in words, for the error message
  const char *meaning;   // what it is, with its unit (README's parameter table)

  bool integer() const { return whole != nullptr; }
  double get(const MapperParams &p) const { return integer() ? static_cast<double>(p.*whole) : p.*real; }
  void set(MapperParams &p, double v) const;
  bool valid(double v) const;
};

// Every parameter, in the README's order.
const std::vector<ParamSpec> &param_table();

// The row of a key (vasco_p_occ) or a name (p_occ); null when there is none.
const ParamSpec *find_param(const std::string &key_or_name);

// The names of all keys MapperParams understands (vasco_resolution, ...).
const std::vector<std::string> &mapper_param_keys();

}  // namespace vasco

#endif  // VASCO_GPU_PARAMS_H
