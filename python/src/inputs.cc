// Where a Log's scans and poses come from, besides one CARMEN log: pose files
// of SLAM back ends, several sessions into one grid, scans read elsewhere (a
// ROS bag, by vasco_gpu.bags), and the log -> map command line run on them
// (bag2map). The keywords are log2map's options, spelt as Python names.
#include "inputs.h"

#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "arrays.h"
#include "bindings.h"
#include "carmen_compat/error.h"
#include "log2map_app.h"
#include "param_keys.h"
#include "vasco_gpu/pipeline/pose_source_options.h"

namespace vasco_py {

using namespace nb::literals;
using carmen::Error;
using carmen::ErrorCode;

namespace {

std::string as_path(nb::handle h) {
  return nb::cast<std::string>(nb::module_::import_("os").attr("fsdecode")(nb::module_::import_("os").attr("fspath")(h)));
}

vasco::Pose2 pose_triple(nb::handle h, const char *what) {
  std::vector<double> v;
  try {
    v = nb::cast<std::vector<double>>(nb::module_::import_("builtins").attr("list")(
        nb::module_::import_("numpy").attr("asarray")(h, "dtype"_a = "float64").attr("ravel")()));
  } catch (const nb::python_error &) {
    v.clear();
  } catch (const nb::cast_error &) {
    v.clear();
  }
  if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    throw Error(ErrorCode::Usage, std::string(what) + ": expected (x, y, theta), three finite numbers");
  return vasco::Pose2{v[0], v[1], v[2]};
}

// map_resolution=M: a finite number > 0 (the written map's cell in metres).
double map_resolution_of(nb::handle v) {
  double cell = 0;
  if (!nb::try_cast(v, cell) || PyBool_Check(v.ptr()) || !std::isfinite(cell) || !(cell > 0))
    throw Error(ErrorCode::Usage, "map_resolution: expected the written map's cell size in metres, a finite number > 0, "
                                  "not " + nb::cast<std::string>(nb::repr(v)));
  return cell;
}

// The pose-source rows' names (pose_source_options.h) and the sessions' own.
const std::set<std::string> &input_keywords() {
  static const std::set<std::string> k = [] {
    std::set<std::string> names = {"transform", "add", "map_resolution"};
    for (const vasco::OptionSpec &row : vasco::pipeline::pose_source_option_table()) names.insert(row.name);
    return names;
  }();
  return k;
}

// A Choice row's value, checked by the row (UsageError naming the keyword).
std::string choice_of(const std::string &key, nb::handle v) {
  const std::string text = nb::cast<std::string>(v);
  vasco::check_option_choice(vasco::option_row(vasco::pipeline::pose_source_option_table(), key), text, key);
  return text;
}

// A Real row's value, checked by the row.
double number_of(const std::string &key, nb::handle v) {
  const double d = nb::cast<double>(v);
  vasco::check_option_number(vasco::option_row(vasco::pipeline::pose_source_option_table(), key), d, key);
  return d;
}

// One pose-source keyword, `key` a row of the table.
void set_pose_options(vasco::PoseSource &p, const std::string &key, nb::handle v) {
  if (key == "poses") p.file = as_path(v);
  else if (key == "pose_format") p.format = vasco::pose_file_format_from_name(choice_of(key, v));
  else if (key == "pose_match") p.match.matching = vasco::pose_matching_from_name(choice_of(key, v));
  else if (key == "pose_tolerance") p.match.tolerance = number_of(key, v);
  else if (key == "pose_max_gap") p.match.max_gap = number_of(key, v);
  else if (key == "pose_ids") p.id_map_file = as_path(v);
  else if (key == "skip_unposed") p.match.skip_unmatched = nb::cast<bool>(v);
  else if (key == "pose_frame") p.robot_frame = choice_of(key, v) == "robot";
  else if (key == "laser_mount") {
    p.mount = pose_triple(v, "laser_mount");
    p.has_mount = true;
  }
}

}  // namespace

void session_transform_of(nb::handle what, vasco::SessionInput &s, const std::string &name) {
  const bool is_str = nb::isinstance<nb::str>(what);
  if (is_str && nb::cast<std::string>(what) == "auto") {
    s.auto_transform = true;
    return;
  }
  if (nb::isinstance<nb::tuple>(what) && nb::len(what) == 2 && nb::isinstance<nb::str>(what[0]) &&
      nb::cast<std::string>(what[0]) == "auto") {
    s.auto_transform = true;  // with a guess the alignment searches near (log2map's @auto:X,Y,THETA+-R,RTHETA)
    s.hint = align_hint_of(what[1], name + ": (\"auto\", hint)");
    return;
  }
  if (is_str) throw Error(ErrorCode::Usage, name + ": a session's transform is (x, y, theta) or \"auto\"");
  s.transform = pose_triple(what, (name + ": transform").c_str());
}

namespace {

// add=[path, (path, (x, y, theta)), (path, "auto"), (path, ("auto", hint)), ...]
std::vector<vasco::SessionInput> sessions_of(nb::handle add) {
  std::vector<vasco::SessionInput> out;
  for (nb::handle item : add) {
    vasco::SessionInput s;
    if (nb::isinstance<nb::tuple>(item) && nb::len(item) == 2) {
      s.path = as_path(item[0]);
      session_transform_of(item[1], s, "add");
    } else {
      s.path = as_path(item);
    }
    out.push_back(s);
  }
  return out;
}

// Scans from the bag reader's dict: {"scans": Scans, "stamps": (n,), "mounts": (n, 3) or None}.
vasco::StampedScans stamped_scans_of(nb::handle d) {
  vasco::StampedScans s;
  s.batch = nb::cast<vasco::ScanBatch>(d["scans"]);
  const size_t n = s.batch.num_scans();
  auto stamps = as_array<double>(d["stamps"], "float64", "stamps", 1);
  if (stamps.shape(0) != n)
    throw Error(ErrorCode::BadInput, "stamps: " + std::to_string(stamps.shape(0)) + " for " + std::to_string(n) + " scans");
  s.stamps.assign(stamps.data(), stamps.data() + n);
  s.mounts.resize(n);
  s.has_mount.assign(n, 0);
  nb::object unposed = d.attr("get")("unposed");
  if (!unposed.is_none()) s.unposed = nb::cast<uint64_t>(unposed);
  nb::object mounts = d.attr("get")("mounts");
  if (!mounts.is_none()) {
    auto m = as_array<double>(mounts, "float64", "mounts", 2);
    if (m.shape(0) != n || m.shape(1) != 3) throw Error(ErrorCode::BadInput, "mounts: expected shape (n, 3)");
    for (size_t i = 0; i < n; ++i) {
      s.mounts[i] = vasco::Pose2{m.data()[3 * i], m.data()[3 * i + 1], m.data()[3 * i + 2]};
      s.has_mount[i] = std::isfinite(s.mounts[i].x) && std::isfinite(s.mounts[i].y) && std::isfinite(s.mounts[i].theta);
    }
  }
  return s;
}

vasco::LogInput log_from_scans(nb::handle scans, const std::string &source, std::optional<std::filesystem::path> param_file,
                               const std::string &robot, std::optional<nb::dict> overrides, nb::kwargs kwargs) {
  vasco::LogInputOptions o;
  fill_input_options(o, source, param_file, robot, overrides, kwargs);
  o.default_map_resolution = vasco::kRosMapResolution;  // scans read elsewhere come from ROS (bags)
  if (!o.more_logs.empty()) throw Error(ErrorCode::Usage, "add: not for scans read elsewhere: append the scans first");
  vasco::StampedScans s = stamped_scans_of(scans);
  nb::gil_scoped_release release;
  return vasco::log_input_from_scans(std::move(s), o);
}

// The reader bag2map hands to the command line: a Python callable
// reader(path, options: dict, progress) -> dict as stamped_scans_of takes.
// Called with the GIL; a Python exception becomes a FileError naming the
// input, so that the tool reports it and exits 1.
vasco::StampedScans call_reader(nb::handle reader, const std::string &path, const std::map<std::string, std::string> &values,
                                const std::function<void(uint64_t, uint64_t)> &progress) {
  nb::gil_scoped_acquire acquire;
  std::string message;
  try {
    nb::object progress_fn = nb::cpp_function([progress](uint64_t done, uint64_t total) {
      if (progress) progress(done, total);
    });
    nb::object d = reader(path, values, progress_fn);
    return stamped_scans_of(d);
  } catch (nb::python_error &e) {
    if (e.matches(PyExc_KeyboardInterrupt)) throw Error(ErrorCode::Usage, "interrupted");
    message = nb::cast<std::string>(nb::str(e.value()));
  }
  throw carmen::FileError(path, message);
}

int run_tool(const std::vector<std::string> &argv, const std::string &name, const std::string &summary,
             const std::string &input_name, const std::string &input_help,
             const std::vector<std::tuple<std::string, std::string, std::string>> &extra, nb::object reader,
             double default_map_resolution) {
  log2map::ToolSpec spec;
  spec.default_map_resolution = default_map_resolution;
  spec.name = name;
  spec.summary = summary;
  spec.input_name = input_name;
  spec.input_help = input_help;
  for (const auto &[n, help, type] : extra) spec.extra_options.push_back({n, help, type});
  spec.read = [reader](const std::string &path, const std::map<std::string, std::string> &values,
                       const std::function<void(uint64_t, uint64_t)> &progress) {
    return call_reader(reader, path, values, progress);
  };
  std::vector<const char *> args;
  for (const std::string &a : argv) args.push_back(a.c_str());
  nb::gil_scoped_release release;
  return log2map::run_tool(static_cast<int>(args.size()), args.data(), spec);
}

}  // namespace

void fill_input_options(vasco::LogInputOptions &o, const std::string &path, std::optional<std::filesystem::path> param_file,
                        const std::string &robot, std::optional<nb::dict> overrides, nb::kwargs kwargs) {
  o.log = path;
  if (param_file) o.param_file = param_file->string();
  o.robot = robot;
  if (overrides) {
    for (auto [k, v] : *overrides) {
      std::string name = nb::cast<std::string>(k);
      check_param(name, v);
      if (name.rfind("vasco_", 0) != 0) name = "vasco_" + name;
      o.overrides[name] = nb::cast<std::string>(nb::str(v));
    }
  }
  std::vector<std::string> pose_options;  // the pose-source keywords given
  for (auto [k, v] : kwargs) {
    const std::string key = nb::cast<std::string>(k);
    if (!input_keywords().count(key)) throw nb::type_error(("unexpected keyword argument '" + key + "'").c_str());
    if (v.is_none()) continue;
    if (key == "transform") o.transform = pose_triple(v, "transform");
    else if (key == "map_resolution") o.map_resolution = map_resolution_of(v);
    else if (key == "add") o.more_logs = sessions_of(v);
    else {
      set_pose_options(o.poses, key, v);
      pose_options.push_back(key);
    }
  }
  vasco::pipeline::check_pose_options_given(pose_options, false, vasco::pipeline::OptionNaming::Keyword);
}

void bind_inputs(nb::module_ &m) {
  m.def("_log_from_scans", &log_from_scans, "scans"_a, "source"_a, "param_file"_a = nb::none(), "robot"_a = "",
        "overrides"_a = nb::none(), "kwargs"_a,
        "A Log from scans read elsewhere (a bag): {'scans': Scans, 'stamps': (n,), 'mounts': (n, 3) or None};\n"
        "the parameters from param_file and overrides, the pose keywords of load_log; the map cell\n"
        "ROS_MAP_RESOLUTION unless map_resolution or vasco_resolution says otherwise.");
  m.attr("ROS_MAP_RESOLUTION") = vasco::kRosMapResolution;
  m.def("_run_tool", &run_tool, "argv"_a, "name"_a, "summary"_a, "input_name"_a, "input_help"_a, "extra"_a,
        "reader"_a, "default_map_resolution"_a = vasco::kRosMapResolution,
        "log2map's command line with another reader of its inputs (ROS's: default --resolution\n"
        "ROS_MAP_RESOLUTION unless vasco_resolution is set); returns the exit status.");
}

}  // namespace vasco_py
