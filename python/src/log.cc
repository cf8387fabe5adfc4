// The class Log and load_log: a CARMEN log read as log2map reads it.
#include <nanobind/nanobind.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <filesystem>
#include <cstdint>
#include <optional>
#include <string>

#include "arrays.h"
#include "bindings.h"
#include "inputs.h"
#include "param_keys.h"
#include "vasco_gpu/pipeline/log_input.h"
#include "vasco_gpu/pipeline/pose_source_options.h"

namespace vasco_py {

using namespace nb::literals;
namespace fs = std::filesystem;
using vasco::LogInput;

namespace {

// Counts by name, only those above zero.
template <typename Name>
nb::dict nonzero_counts(const uint64_t *counts, int n, Name name) {
  nb::dict d;
  for (int i = 0; i < n; ++i)
    if (counts[i] > 0) d[name(i)] = counts[i];
  return d;
}

nb::dict load_stats_dict(const vasco::LogLoadStats &l) {
  nb::dict d;
  const carmen::LogStats &s = l.log;
  d["lines"] = s.lines;
  d["laser_messages"] = l.laser_messages;
  d["scans_used"] = l.scans_used;
  d["messages"] = nonzero_counts(s.messages.data(), carmen::kNumMessageTypes, [](int t) {
    return carmen::message_type_name(static_cast<carmen::MessageType>(t));
  });
  d["blank_lines"] = s.blank_lines;
  d["comment_lines"] = s.comment_lines;
  d["unknown_lines"] = s.unknown_lines;
  d["bad_lines"] = nonzero_counts(s.bad_lines.data(), carmen::kNumBadLineClasses, [](int b) {
    return carmen::bad_line_name(static_cast<carmen::BadLine>(b));
  });
  d["nan_ranges"] = s.nan_ranges;
  d["inf_ranges"] = s.inf_ranges;
  d["negative_ranges"] = s.negative_ranges;
  return d;
}

LogInput load_log(const fs::path &path, std::optional<fs::path> param_file, const std::string &robot,
                  std::optional<nb::dict> overrides, bool lenient, nb::kwargs kwargs) {
  vasco::LogInputOptions o;
  fill_input_options(o, path.string(), param_file, robot, overrides, kwargs);
  o.lenient = lenient;
  nb::gil_scoped_release release;
  return vasco::load_log_input(o);
}

constexpr const char *kLogDoc =
    "A CARMEN log read by load_log: the selected scans, the effective parameters\n"
    "(keywords > ini > the log's PARAM lines > defaults), the PROTOCOL frame and\n"
    "what the reader counted.";

// The pose keywords, one line each from its row (pose_source_options.h).
std::string pose_keywords_doc() {
  std::string text;
  for (const vasco::OptionSpec &row : vasco::pipeline::pose_source_option_table())
    text += "\n- ``" + row.name + "``: " + (row.type == vasco::OptionType::Flag ? row.help : row.help_with_default());
  return text;
}

// Log.added_sessions: log2map --json's "added_sessions", as dicts.
nb::list added_sessions_list(const std::vector<vasco::AddedSession> &added) {
  nb::list out;
  for (const vasco::AddedSession &a : added) {
    nb::dict d;
    const vasco::AlignResult &r = a.result;
    d["input"] = a.input;
    d["transform"] = nb::make_tuple(a.transform.x, a.transform.y, a.transform.theta);
    d["aligned"] = a.aligned ? "auto" : "given";
    d["score"] = a.aligned ? nb::object(nb::float_(r.best.score)) : nb::none();
    d["second_score"] = a.aligned && r.has_second ? nb::object(nb::float_(r.second.score)) : nb::none();
    d["second_transform"] = a.aligned && r.has_second ? nb::object(nb::make_tuple(r.second.x, r.second.y, r.second.theta))
                                                      : nb::none();
    d["overlap"] = a.aligned ? nb::object(nb::float_(r.overlap)) : nb::none();
    out.append(d);
  }
  return out;
}

// The docs name the scan messages from the pipeline's list (vasco_gpu/pipeline/log_scans.h).
const char *load_log_doc() {
  static const std::string doc =
    "Reads a CARMEN log (" + vasco::pipeline::carmen_log_extensions_text(", ") +
    ", gzipped if the name ends in .gz) as log2map does.\n\n"
    "Every " + vasco::scan_message_names(" and ") + " line is a scan; ``param_file`` is a carmen.ini (``robot`` its\n"
    "section), ``overrides`` keys as in Params (they win over the ini, which wins over the log's\n"
    "PARAM lines). Strict by default: a bad line raises FileError with ``.file`` and ``.line``;\n"
    "``lenient=True`` skips bad lines and counts them in ``Log.stats['bad_lines']``. The GIL is\n"
    "released while the log is read.\n\n"
    "Poses from a SLAM back end (log2map --poses), the other pose keywords only with ``poses``\n"
    "(None: the default; a pose keyword without ``poses`` is a UsageError):" + pose_keywords_doc() + "\n\n"
    "Several sessions into one grid: ``transform`` (x, y, theta) of this log into the shared\n"
    "frame, ``add`` further logs, each a path or (path, (x, y, theta)), or (path, \"auto\") to find its\n"
    "transform by aligning the log to those before it (log2map --add LOG@auto; (path, (\"auto\", (x, y,\n"
    "theta, radius_m, radius_rad))) searches near a guess). A log the alignment refuses raises FileError\n"
    "naming it. ``Log.added_sessions`` says what each added log was mapped at.\n\n"
    "``map_resolution``: the written map's cell in metres (log2map --resolution; ROS's resolution), set over\n"
    "the keys by Params.map_resolution's rule (vasco_downsample kept where the ini, the log or overrides set\n"
    "it). None: CARMEN's keys alone (0.025 x 4 = 0.1 m).";
  return doc.c_str();
}

const char *scans_doc() {
  static const std::string doc =
      "The selected scans (" + vasco::scan_message_names(" and ") + " lines, in log order); its arrays are views.";
  return doc.c_str();
}

}  // namespace

void bind_log(nb::module_ &m) {
  nb::class_<LogInput>(m, "Log", kLogDoc)
      .def_prop_ro(
          "scans", [](LogInput &in) -> vasco::ScanBatch & { return in.batch; }, nb::rv_policy::reference_internal,
          scans_doc())
      .def_prop_ro(
          "params", [](const LogInput &in) { return in.params; }, "The effective parameters (a copy).")
      .def_prop_ro(
          "frame", [](const LogInput &in) { return in.geo; },
          "The PROTOCOL frame of the selected scans (a copy): what Mapper uses by default.")
      .def_prop_ro(
          "poses", [](const LogInput &in) { return poses_of(in.batch); }, nb::rv_policy::reference,
          "(n, 3) float64 laser poses (x, y, theta): a new array.")
      .def_prop_ro(
          "ranges",
          [](nb::handle_t<LogInput> self) {
            vasco::ScanBatch &b = nb::cast<LogInput &>(self).batch;  // counted as Log.scans' views are
            return counted_view1(b.range.data(), b.range.size(), &b, self);
          },
          nb::rv_policy::reference, "All ranges, float32 (a view; see Scans).")
      .def_prop_ro(
          "stamps", [](const LogInput &in) { return owned(std::vector<double>(in.stamps), {in.stamps.size()}); },
          nb::rv_policy::reference, "Each selected scan's timestamp in seconds, float64 (a new array; NaN where unknown).")
      .def_ro("posed_from_file", &LogInput::posed_from_file, "Scans whose pose came from ``poses`` (0 without).")
      .def_ro("unposed_skipped", &LogInput::unposed_skipped, "Scans left out for want of a pose (``skip_unposed``).")
      .def_ro("warnings", &LogInput::warnings, "Unknown vasco_* keys and the like.")
      .def_prop_ro(
          "added_sessions", [](const LogInput &in) { return added_sessions_list(in.added_sessions); },
          "One dict per ``add`` log, in order: ``input``, ``transform`` (x, y, theta) it was mapped at,\n"
          "``aligned`` (\"auto\" or \"given\"), and for \"auto\" the alignment's ``score``, ``second_score``,\n"
          "``second_transform`` (None without a second candidate) and ``overlap`` (None where given).")
      .def_prop_ro(
          "stats", [](const LogInput &in) { return load_stats_dict(in.load); },
          "What the reader counted: lines, messages by type, bad lines by class (lenient mode), odd\n"
          "ranges, scans used.")
      .def("__len__", [](const LogInput &in) { return in.batch.num_scans(); })
      .def("__repr__", [](const LogInput &in) {
        return nb::str("Log({} scans, {} beams)").format(in.batch.num_scans(), in.batch.num_beams());
      });

  m.def("load_log", &load_log, "path"_a, "param_file"_a = nb::none(), "robot"_a = "", "overrides"_a = nb::none(),
        "lenient"_a = false, "kwargs"_a,
        nb::sig("def load_log(path: str | os.PathLike, param_file: str | os.PathLike | None = None, "
                "robot: str = '', overrides: dict[str, float | int] | None = None, lenient: bool = False, *, "
                "poses: str | os.PathLike | None = None, pose_format: str | None = None, pose_match: str | None = None, "
                "pose_tolerance: float | None = None, pose_max_gap: float | None = None, pose_ids: str | os.PathLike | None = None, "
                "skip_unposed: bool | None = None, pose_frame: str | None = None, "
                "laser_mount: tuple[float, float, float] | None = None, "
                "transform: tuple[float, float, float] | None = None, "
                "add: list[str | os.PathLike | tuple[str | os.PathLike, tuple[float, float, float] | str | tuple]] | None = None, "
                "map_resolution: float | None = None) -> Log"),
        load_log_doc());
}

}  // namespace vasco_py
