// registries.cc — the engine's lists as Python reads them: the backends
// (backend.h), the option tables
// (option_schema.h), the map formats (map_format.h) and the pipeline's rules
// for outputs (vasco_gpu/pipeline/outputs.h), so that no Python file lists a
// backend, an option, a format or an output rule of its own.
#include <nanobind/nanobind.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "carmen_compat/error.h"
#include "carmen_compat/map_format.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/option_schema.h"
#include "vasco_gpu/pipeline/map_output_options.h"
#include "vasco_gpu/pipeline/outputs.h"
#include "vasco_gpu/pipeline/pose_source_options.h"

namespace vasco_py {

namespace {

using namespace nb::literals;

const char *exactness_name(vasco::Exactness e) {
  switch (e) {
    case vasco::Exactness::Exact: return "exact";
    case vasco::Exactness::Float: return "float";
    case vasco::Exactness::ByCudaMode: return "by_cuda_mode";
  }
  return "?";
}

const char *kind_name(carmen::MapFormatKind k) {
  switch (k) {
    case carmen::MapFormatKind::Carmen: return "carmen";
    case carmen::MapFormatKind::MapServer: return "map_server";
    case carmen::MapFormatKind::Picture: return "picture";
  }
  return "?";
}

nb::list backend_rows() {
  nb::list rows;
  for (const vasco::BackendInfo &b : vasco::backend_registry()) {
    nb::list aliases;
    for (const vasco::BackendAlias &a : b.aliases) {
      nb::object mode = nb::none();  // an alias that keeps the mode (gpu)
      if (a.sets_cuda_mode) mode = nb::str(a.cuda_mode == vasco::CudaMode::Exact ? "exact" : "float");
      aliases.append(nb::make_tuple(a.name, mode));
    }
    nb::dict row;
    row["name"] = b.name;
    row["aliases"] = aliases;
    row["exactness"] = exactness_name(b.exactness);
    row["grid_on_device"] = b.grid_on_device;
    row["compiled"] = b.compiled;
    row["summary"] = b.summary;
    row["uses_gpus"] = b.uses_gpus;
    row["uses_threads"] = b.uses_threads;
    row["chooses"] = b.chooses;
    rows.append(row);
  }
  return rows;
}

nb::list format_rows() {
  nb::list rows;
  for (const carmen::MapFormatEntry &f : carmen::map_formats()) {
    nb::dict row;
    row["name"] = f.extension + 1;
    row["extension"] = f.extension;
    row["what"] = f.what;
    row["kind"] = kind_name(f.kind);
    rows.append(row);
  }
  return rows;
}

// A row's default as a Python value of its type (None: none; the text itself
// where it is not a number, a computed default).
nb::object typed_default(const vasco::OptionSpec &o) {
  const std::string &t = o.default_text;
  if (t.empty()) return nb::none();
  char *end = nullptr;
  switch (o.type) {
    case vasco::OptionType::Flag: return nb::bool_(t == "true");
    case vasco::OptionType::Whole: {
      const long long v = std::strtoll(t.c_str(), &end, 10);
      return *end == '\0' ? nb::object(nb::int_(v)) : nb::object(nb::str(t.c_str()));
    }
    case vasco::OptionType::Bytes: {  // default_text in MiB, Python's value in bytes
      const unsigned long long mib = std::strtoull(t.c_str(), &end, 10);
      return *end == '\0' ? nb::object(nb::int_(uint64_t(mib) << 20)) : nb::object(nb::str(t.c_str()));
    }
    case vasco::OptionType::Real: {
      const double v = std::strtod(t.c_str(), &end);
      return *end == '\0' ? nb::object(nb::float_(v)) : nb::object(nb::str(t.c_str()));
    }
    default: return nb::str(t.c_str());
  }
}

nb::dict option_dict(const vasco::OptionSpec &o) {
  const bool bounded = !(o.lo == 0 && o.hi == 0);
  nb::dict d;
  d["name"] = o.name;
  d["type"] = vasco::option_type_name(o.type);
  d["default"] = typed_default(o);
  d["default_text"] = o.default_text;
  d["help"] = o.help;
  d["choices"] = o.choices;
  d["lo"] = bounded ? nb::object(nb::float_(o.lo)) : nb::none();
  d["hi"] = bounded ? nb::object(nb::float_(o.hi)) : nb::none();
  d["lo_open"] = o.lo_open;
  d["hi_open"] = o.hi_open;
  d["flag"] = o.flag();
  d["rule"] = o.rule();
  return d;
}

const vasco::OptionTable &option_table(const std::string &component) {
  if (component == "session") return vasco::session_option_table();
  if (component == "pose_source") return vasco::pipeline::pose_source_option_table();
  if (component == "map_output") return vasco::pipeline::map_output_option_table();
  throw carmen::Error(carmen::ErrorCode::Usage, "option_schema: no component '" + carmen::printable(component) +
                                                    "' (known: session, pose_source, map_output)");
}

nb::list option_rows(const std::string &component) {
  nb::list rows;
  for (const vasco::OptionSpec &o : option_table(component)) rows.append(option_dict(o));
  return rows;
}

}  // namespace

void bind_registries(nb::module_ &m) {
  m.def("option_schema", &option_rows, "component"_a,
        nb::sig("def option_schema(component: str) -> list[dict[str, typing.Any]]"),
        "The options of ``component`` ('session': a Mapper's backend, cuda_mode, threads, ...;\n"
        "'pose_source': poses from a file; 'map_output': how a map is written), one dict per option\n"
        "in the order of its table: 'name' (the keyword), 'type' ('flag', 'whole', 'real', 'bytes',\n"
        "'choice', 'text' or 'whole_list'), 'default' (a value of the type, None for none; 'bytes'\n"
        "in bytes), 'default_text' (as --help prints it; 'bytes' in MiB), 'help', 'choices', 'lo' and\n"
        "'hi' (None: unbounded), 'lo_open', 'hi_open', 'flag' (log2map's: --max-memory) and 'rule'\n"
        "(the accepted values in words). UsageError for another component.");
  m.def("backend_registry", &backend_rows,
        nb::sig("def backend_registry() -> list[dict[str, typing.Any]]"),
        "Every backend of the engine's registry, compiled into this build or not, in the order the\n"
        "help lists them: a dict each with 'name', 'aliases' (a list of (alias, cuda mode), the mode\n"
        "None for an alias that keeps it), 'exactness' ('exact', 'float' or 'by_cuda_mode'),\n"
        "'grid_on_device', 'compiled', 'summary', and what the options mean for it: 'uses_gpus',\n"
        "'uses_threads', 'chooses' (auto: picks another per input).");
  m.def("backend_names", &vasco::backend_names,
        "Every name and alias Mapper(backend=...) takes, compiled into this build or not.");
  m.def("map_formats", &format_rows, nb::sig("def map_formats() -> list[dict[str, str]]"),
        "Every map format of the engine's table, in the order the help lists them: a dict each with\n"
        "'name' (what map_logs' formats and log2map --formats take: 'map.gz'), 'extension' ('.map.gz'),\n"
        "'what' and 'kind' ('carmen', 'map_server' or 'picture'). A path's extension (any case) picks\n"
        "its format in read_map and write_map.");
  m.def("carmen_log_extensions", &vasco::pipeline::carmen_log_extensions,
        "The extensions of a CARMEN log (``.log``, ``.clf``), each also gzipped (``.gz`` after it),\n"
        "as log2map and load_log take them.");
  m.def(
      "output_stem", [](const std::filesystem::path &path) { return vasco::pipeline::output_stem(path.string()); },
      "path"_a, nb::sig("def output_stem(path: str | os.PathLike) -> str"),
        "The name of an input's outputs, as log2map's batch mode makes it: the file name less a\n"
        "trailing ``.gz`` and then less one extension (``fr079-complete.gfs.log.gz`` ->\n"
        "``fr079-complete.gfs``; a ROS 2 bag's directory ``run/`` -> ``run``).");
  m.def("_check_map_formats", &vasco::pipeline::check_map_formats, "names"_a, "what"_a,
        "The formats of a batch checked (UsageError beginning with ``what``).");
  m.def(
      "_plan_outputs",
      [](const std::vector<std::string> &inputs, const std::string &out_dir, const std::vector<std::string> &formats,
         const std::string &who) {
        std::vector<std::pair<std::string, std::vector<std::string>>> plan;
        for (vasco::pipeline::PlannedInput &p : vasco::pipeline::plan_outputs(inputs, out_dir, formats, who))
          plan.emplace_back(std::move(p.input), std::move(p.outputs));
        return plan;
      },
      "inputs"_a, "out_dir"_a, "formats"_a, "who"_a = "",
      "[(input, [outputs])] of a batch: DIR/STEM.FORMAT; two inputs of one stem refused (UsageError).");
  m.def(
      "_check_outputs",
      [](const std::vector<std::string> &inputs, const std::vector<std::string> &outputs, bool replaceable) {
        nb::gil_scoped_release release;
        vasco::pipeline::check_outputs(inputs, vasco::pipeline::output_files(outputs), replaceable);
      },
      "inputs"_a, "outputs"_a, "replaceable"_a = true,
      "Refuses an output (or a file it writes, a .pgm's .yaml) that is an input or another output\n"
      "(UsageError), or, with ``replaceable``, that a rename could not replace (FileError).");
}

}  // namespace vasco_py
