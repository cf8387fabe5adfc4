// The class Params: the mapper's parameters with carmen.ini's keys as
// keywords and attributes.
#include <nanobind/nanobind.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <deque>
#include <filesystem>
#include <string>

#include "bindings.h"
#include "carmen_compat/ini_file.h"
#include "param_keys.h"
#include "vasco_gpu/params.h"

namespace vasco_py {

using namespace nb::literals;
namespace fs = std::filesystem;
using vasco::MapperParams;

namespace {

std::string params_doc() {
  return "The mapper's parameters: carmen.ini's ``vasco_*`` keys without the prefix.\n\n"
         "``Params(p_occ=0.9, resolution=0.05)`` (the ``vasco_`` prefix is accepted\n"
         "too: ``Params(vasco_p_occ=0.9)``) starts from vasco's defaults and is\n"
         "validated; an unknown keyword is a TypeError, a value out of range a\n"
         "ValueError naming the key. Attributes may be changed afterwards; the Mapper\n"
         "validates them again.\n\n" +
         param_keys_doc();
}

std::string params_repr(const MapperParams &p) {
  std::string s = "Params(";
  bool first = true;
  for (auto [k, v] : params_dict(p)) {
    s += (first ? "" : ", ") + nb::cast<std::string>(nb::str(k)) + "=" + nb::cast<std::string>(nb::repr(v));
    first = false;
  }
  return s + ")";
}

// map_resolution=M over the other keys (MapperParams::set_map_resolution):
// ValueError naming it for a bad value; `downsample_given` keeps the block.
void apply_map_resolution(MapperParams &p, nb::handle v, bool downsample_given) {
  double cell = 0;
  if (PyBool_Check(v.ptr()) || !nb::try_cast(v, cell))
    throw nb::type_error(("map_resolution: expected a number of metres, not " + nb::cast<std::string>(nb::repr(v))).c_str());
  try {
    p.set_map_resolution(cell, downsample_given);
  } catch (const vasco::ParamError &e) {
    throw nb::value_error(e.what());
  }
}

MapperParams params_from_ini(const fs::path &path, const std::string &robot, nb::kwargs overrides) {
  carmen::ParamFile pf = carmen::ParamFile::load(path.string(), robot);
  nb::object cell;
  for (auto [k, v] : overrides) {
    std::string name = nb::cast<std::string>(k);
    if (name == "map_resolution") {
      cell = nb::borrow(v);
      continue;
    }
    check_param(name, v);
    if (name.rfind("vasco_", 0) != 0) name = "vasco_" + name;
    pf.set_override(name, nb::cast<std::string>(nb::str(v)));
  }
  MapperParams p = MapperParams::from_params(pf, nullptr);
  if (cell.is_valid()) apply_map_resolution(p, cell, pf.has("vasco_downsample"));
  return p;
}

// Params' constructors (keywords, from_ini) and keys().
void bind_params_constructors(nb::class_<MapperParams> &cls) {
  cls.def(
         "__init__",
         [](MapperParams *self, nb::kwargs kwargs) {
           MapperParams p;
           nb::object cell;
           bool downsample_given = false;
           for (auto [k, v] : kwargs) {
             const std::string name = nb::cast<std::string>(k);
             if (name == "map_resolution") {
               cell = nb::borrow(v);
               continue;
             }
             set_param(p, name, v);
             downsample_given |= name == "downsample" || name == "vasco_downsample";
           }
           p.validate();
           if (cell.is_valid()) apply_map_resolution(p, cell, downsample_given);
           new (self) MapperParams(p);
         },
         nb::sig("def __init__(self, **params: float | int) -> None"),
         "Parameters from keywords (ini key names, with or without ``vasco_``); the rest keep vasco's\n"
         "defaults. Validated. ``map_resolution=M`` sets the written map's cell (see the property).")
      .def_static("from_ini", &params_from_ini, "path"_a, "robot"_a = "", "overrides"_a,
                  nb::sig("def from_ini(path: str | os.PathLike, robot: str = '', **overrides: float | int) -> Params"),
                  "Parameters from a carmen.ini (sections [*], [expert] and the robot's, as CARMEN's param_daemon\n"
                  "reads them), keywords overriding the file (``map_resolution=M`` too). Errors raise FileError\n"
                  "naming FILE:LINE.")
      .def_static(
          "keys", []() { return vasco::mapper_param_keys(); },
          "The ini keys the mapper understands (vasco_resolution, ...).");
}

// Params' methods: validate, to_dict, repr, equality and copies.
void bind_params_methods(nb::class_<MapperParams> &cls) {
  cls.def_prop_ro("map_resolution", &MapperParams::map_resolution,
                  "The written map's cell size in metres, resolution x downsample: ROS's resolution. Given as\n"
                  "``Params(map_resolution=M)`` (log2map --resolution), it sets resolution = M / downsample, with\n"
                  "the downsample given, else the one nearest resolution: max(1, round(M / resolution)).");
  cls.def("validate", &MapperParams::validate, "Raises ValueError naming the key when a value is out of range.")
      .def("to_dict", &params_dict, "The parameters as a dict (keys without ``vasco_``).")
      .def("__repr__", &params_repr)
      .def(
          "__eq__",
          [](const MapperParams &a, nb::handle b) -> nb::object {
            if (!nb::isinstance<MapperParams>(b)) return nb::borrow(Py_NotImplemented);
            return nb::bool_(params_dict(a).equal(params_dict(nb::cast<const MapperParams &>(b))));
          },
          nb::sig("def __eq__(self, other: object) -> bool"))
      .def("__copy__", [](const MapperParams &p) { return p; })
      .def("__deepcopy__", [](const MapperParams &p, nb::handle) { return p; }, "memo"_a);
}

// Params' attributes, one per row of the parameter table.
void bind_params_attributes(nb::class_<MapperParams> &cls) {
  static std::deque<std::string> docs;  // nanobind keeps the pointers it is given
  for (const vasco::ParamSpec &k : vasco::param_table()) {
    docs.push_back(std::string(k.key) + ": " + k.meaning + ".");
    if (k.integer()) cls.def_rw(k.name, k.whole, docs.back().c_str());
    else cls.def_rw(k.name, k.real, docs.back().c_str());
  }
}

}  // namespace

void bind_params(nb::module_ &m) {
  // The docstring outlives the class: nanobind keeps the pointer it is given.
  static const std::string doc = params_doc();
  nb::class_<MapperParams> cls(m, "Params", doc.c_str());
  bind_params_constructors(cls);
  bind_params_methods(cls);
  bind_params_attributes(cls);
  cls.attr("__hash__") = nb::none();  // mutable, compared by value
}

}  // namespace vasco_py
