// vasco_gpu._core — the Python bindings of the C++ API (nanobind).
//
// What crosses the boundary and how:
//   - arrays owned by a C++ object (a Scans' ranges and per-scan columns, a
//     Map's cells) are NumPy views of its memory, keeping the object alive;
//   - arrays C++ returns by value (Mapper.read, a finished map) are moved into
//     an owner, never copied;
//   - poses travel as an (n, 3) float64 array, copied once into the session's
//     own vector (24 bytes a scan);
//   - every call that maps, reads a log or writes a file releases the GIL.
// carmen::FileError becomes vasco_gpu.FileError (with .file and .line),
// std::invalid_argument ValueError, other errors RuntimeError.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/map.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/image_io.h"
#include "carmen_compat/ini_file.h"
#include "carmen_compat/log_reader.h"
#include "carmen_compat/map_file.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/compare.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/log_input.h"
#include "vasco_gpu/map_digest.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"
#include "vasco_gpu/version.h"
#if defined(VASCO_HAVE_CUDA)
#include "vasco_gpu/cuda_backend.h"
#endif

namespace nb = nanobind;
using namespace nb::literals;
namespace fs = std::filesystem;

namespace {

static_assert(sizeof(vasco::Pose) == 3 * sizeof(double), "Pose must be three packed doubles");

template <typename T>
using Array1 = nb::ndarray<nb::numpy, T, nb::ndim<1>, nb::c_contig>;
template <typename T>
using Array2 = nb::ndarray<nb::numpy, T, nb::ndim<2>>;

// A 1-D view of `v` kept alive by `owner`.
template <typename T>
Array1<T> view1(std::vector<T> &v, nb::handle owner) {
  return Array1<T>(v.data(), {v.size()}, owner);
}

// A vector moved into a capsule: an array that owns it, no copy.
template <typename T>
nb::ndarray<nb::numpy, T> owned(std::vector<T> &&v, std::initializer_list<size_t> shape) {
  auto *heap = new std::vector<T>(std::move(v));
  nb::capsule owner(heap, [](void *p) noexcept { delete static_cast<std::vector<T> *>(p); });
  return nb::ndarray<nb::numpy, T>(heap->data(), shape, owner);
}

// np.ascontiguousarray(obj, dtype): zero-copy for an array that already
// fits, one conversion otherwise (lists and tuples included).
nb::object contiguous(nb::handle obj, const char *dtype) {
  // Kept for the life of the process: no destructor after the interpreter ends.
  static nb::handle asc = nb::object(nb::module_::import_("numpy").attr("ascontiguousarray")).release();
  return asc(obj, "dtype"_a = dtype);
}

template <typename T>
nb::ndarray<const T, nb::c_contig, nb::device::cpu> as_array(nb::handle obj, const char *dtype, const char *what,
                                                              size_t ndim) {
  nb::object a = contiguous(obj, dtype);
  auto arr = nb::cast<nb::ndarray<const T, nb::c_contig, nb::device::cpu>>(a);
  if (arr.ndim() != ndim)
    throw std::invalid_argument(std::string(what) + ": expected a " + std::to_string(ndim) + "-D array, got " +
                                std::to_string(arr.ndim()) + "-D");
  return arr;
}

std::string ext_of(const std::string &path) {
  auto ends = [&](const char *e) {
    const size_t n = std::strlen(e);
    if (path.size() < n) return false;
    for (size_t i = 0; i < n; ++i)
      if (std::tolower(static_cast<unsigned char>(path[path.size() - n + i])) != e[i]) return false;
    return true;
  };
  for (const char *e : {".map.gz", ".map", ".pgm", ".png"})
    if (ends(e)) return e;
  return "";
}

// ---------------------------------------------------------------------------
// Params: keyword names are the ini keys, with or without "vasco_".
// ---------------------------------------------------------------------------
struct ParamKey {
  const char *name;  // without vasco_
  double vasco::MapperParams::*d;
  long vasco::MapperParams::*l;
};
const ParamKey kParamKeys[] = {
    {"resolution", &vasco::MapperParams::resolution, nullptr},
    {"p_prior", &vasco::MapperParams::p_prior, nullptr},
    {"p_occ", &vasco::MapperParams::p_occ, nullptr},
    {"p_emp", &vasco::MapperParams::p_emp, nullptr},
    {"range_sure", &vasco::MapperParams::range_sure, nullptr},
    {"range_max", &vasco::MapperParams::range_max, nullptr},
    {"wall_size", &vasco::MapperParams::wall_size, nullptr},
    {"downsample", nullptr, &vasco::MapperParams::downsample},
    {"border", nullptr, &vasco::MapperParams::border},
    {"first_scan", nullptr, &vasco::MapperParams::first_scan},
    {"num_scans", nullptr, &vasco::MapperParams::num_scans},
};

const ParamKey *find_key(std::string name) {
  if (name.rfind("vasco_", 0) == 0) name = name.substr(6);
  for (const ParamKey &k : kParamKeys)
    if (name == k.name) return &k;
  return nullptr;
}

void set_param(vasco::MapperParams &p, const std::string &name, nb::handle value) {
  const ParamKey *k = find_key(name);
  if (k == nullptr)
    throw nb::type_error(("Params: unknown parameter '" + name + "' (known: " + [] {
                            std::string s;
                            for (const ParamKey &k : kParamKeys) s += std::string(s.empty() ? "" : ", ") + k.name;
                            return s;
                          }() + ")")
                             .c_str());
  if (PyBool_Check(value.ptr()))
    throw nb::type_error(("Params: " + name + " must be a number, not a bool").c_str());
  double v = 0;
  if (!nb::try_cast<double>(value, v))
    throw nb::type_error(("Params: " + name + " must be a number, not " +
                          nb::cast<std::string>(nb::str(value.type().attr("__name__")))).c_str());
  if (k->d != nullptr) {
    p.*(k->d) = v;
  } else {
    if (!(v == std::floor(v)) || std::fabs(v) > 1e15)
      throw nb::type_error(("Params: " + name + " must be a whole number").c_str());
    p.*(k->l) = static_cast<long>(v);
  }
}

nb::dict params_dict(const vasco::MapperParams &p) {
  nb::dict d;
  for (const ParamKey &k : kParamKeys) {
    if (k.d != nullptr) d[k.name] = p.*(k.d);
    else d[k.name] = p.*(k.l);
  }
  return d;
}

std::string params_repr(const vasco::MapperParams &p) {
  std::string s = "Params(";
  bool first = true;
  nb::dict d = params_dict(p);
  for (auto [k, v] : d) {
    s += (first ? "" : ", ") + nb::cast<std::string>(nb::str(k)) + "=" + nb::cast<std::string>(nb::repr(v));
    first = false;
  }
  return s + ")";
}

// ---------------------------------------------------------------------------
// Maps
// ---------------------------------------------------------------------------
struct Map {
  carmen::GridMap grid;
  carmen::GlobalOffset origin;  // world pose of the lower-left corner of cell (0, 0)
  bool has_origin = false;
  int downsample = 1;
  int min_x = 0, min_y = 0;
};

Map map_from_finished(vasco::FinishedMap &&f, const vasco::GridGeometry &geo) {
  Map m;
  m.grid.size_x = f.size_x;
  m.grid.size_y = f.size_y;
  m.grid.resolution = f.resolution;
  m.grid.cells = std::move(f.cells);
  m.downsample = f.downsample;
  m.min_x = f.min_x;
  m.min_y = f.min_y;
  // As log2map writes it: theta_offset is the first scan's heading, so the
  // grid axes are the world axes.
  m.origin.x = geo.world_x(static_cast<double>(f.min_x) * f.downsample);
  m.origin.y = geo.world_y(static_cast<double>(f.min_y) * f.downsample);
  m.origin.theta = 0;
  m.has_origin = true;
  return m;
}

Map read_png_map(const std::string &path) {
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path.c_str()))
    throw carmen::FileError(path, std::string("cannot read PNG: ") + img.message);
  img.format = PNG_FORMAT_GRAY;
  std::vector<uint8_t> px(PNG_IMAGE_SIZE(img));
  if (!png_image_finish_read(&img, nullptr, px.data(), 0, nullptr)) {
    const std::string msg = img.message;
    png_image_free(&img);
    throw carmen::FileError(path, "cannot read PNG: " + msg);
  }
  Map m;
  m.grid.size_x = static_cast<int>(img.width);
  m.grid.size_y = static_cast<int>(img.height);
  m.grid.resolution = 0;
  m.grid.cells.resize(static_cast<size_t>(img.width) * img.height);
  for (size_t x = 0; x < img.width; ++x)
    for (size_t y = 0; y < img.height; ++y) {
      const uint8_t v = px[(img.height - 1 - y) * img.width + x];
      m.grid.cells[x * img.height + y] = v == carmen::kPngUnknown ? -1.0f : 1.0f - static_cast<float>(v) / 255.0f;
    }
  return m;
}

void write_map(const std::string &path, const Map &m, const std::string &mode, const std::string &description) {
  if (m.grid.cells.size() != static_cast<size_t>(m.grid.size_x) * static_cast<size_t>(m.grid.size_y) ||
      m.grid.size_x <= 0 || m.grid.size_y <= 0)
    throw std::invalid_argument("write_map: the map is empty or inconsistent");
  const std::string ext = ext_of(path);
  if (ext == ".map" || ext == ".map.gz") {
    carmen::MapFile mf;
    const auto now = static_cast<int64_t>(std::time(nullptr));
    const std::string desc = description.empty() ? "vasco_gpu " + std::string(vasco::version()) : description;
    mf.comments = carmen::standard_map_comments(m.grid.size_x, m.grid.size_y, m.grid.resolution, "vasco_gpu",
                                                desc, "vasco_gpu", now);
    carmen::CreatorInfo creator;
    creator.user = "vasco_gpu";
    creator.origin = "python";
    creator.description = desc;
    creator.time = now;
    mf.creator = creator;
    mf.gridmap = m.grid;
    if (m.has_origin) mf.offset = m.origin;
    carmen::write_map_file(path, mf);
  } else if (ext == ".pgm") {
    carmen::PgmMode pm;
    if (!carmen::parse_pgm_mode(mode, &pm))
      throw std::invalid_argument("write_map: mode '" + mode + "': expected trinary, scale or raw");
    carmen::write_pgm_with_yaml(path, m.grid, m.origin, pm);
  } else if (ext == ".png") {
    carmen::write_png(path, m.grid);
  } else {
    throw std::invalid_argument("write_map: '" + path + "': the name must end in .map, .map.gz, .pgm or .png");
  }
}

// ---------------------------------------------------------------------------
// Scans
// ---------------------------------------------------------------------------
vasco::ScanBatch make_scans(nb::handle poses_obj, nb::handle ranges_obj, nb::handle counts_obj,
                            nb::handle first_obj, nb::handle step_obj) {
  auto poses = as_array<double>(poses_obj, "float64", "poses", 2);
  if (poses.shape(1) != 3) throw std::invalid_argument("poses: expected shape (n, 3) (x, y, theta per scan)");
  const size_t n = poses.shape(0);
  auto ranges = as_array<float>(ranges_obj, "float32", "ranges", 1);
  auto counts = as_array<int64_t>(counts_obj, "int64", "beam_counts", 1);
  if (counts.shape(0) != n)
    throw std::invalid_argument("beam_counts: " + std::to_string(counts.shape(0)) + " counts for " +
                                std::to_string(n) + " poses");
  auto per_scan = [&](nb::handle obj, const char *what) {
    static nb::handle ndim = nb::object(nb::module_::import_("numpy").attr("ndim")).release();
    std::vector<double> v;
    if (nb::cast<int>(ndim(obj)) == 0) {
      v.assign(n, nb::cast<double>(nb::module_::import_("builtins").attr("float")(obj)));
      return v;
    }
    nb::object a = contiguous(obj, "float64");
    auto arr = nb::cast<nb::ndarray<const double, nb::c_contig, nb::device::cpu>>(a);
    if (arr.ndim() == 1 && arr.shape(0) == n) {
      v.assign(arr.data(), arr.data() + n);
    } else {
      throw std::invalid_argument(std::string(what) + ": expected a number or one value per scan (" +
                                  std::to_string(n) + ")");
    }
    return v;
  };
  const std::vector<double> first = per_scan(first_obj, "first_angle");
  const std::vector<double> step = per_scan(step_obj, "angle_step");
  uint64_t total = 0;
  for (size_t s = 0; s < n; ++s) {
    const int64_t c = counts.data()[s];
    if (c < 0 || c > carmen::kMaxCount)
      throw std::invalid_argument("beam_counts[" + std::to_string(s) + "] = " + std::to_string(c) +
                                  ": must be between 0 and " + std::to_string(carmen::kMaxCount));
    total += static_cast<uint64_t>(c);
  }
  if (total != ranges.shape(0))
    throw std::invalid_argument("ranges: " + std::to_string(ranges.shape(0)) + " ranges, but the beam counts add up to " +
                                std::to_string(total));
  vasco::ScanBatch b;
  const float *r = ranges.data();
  const double *p = poses.data();
  for (size_t s = 0; s < n; ++s) {
    const int c = static_cast<int>(counts.data()[s]);
    b.add_scan(p[3 * s], p[3 * s + 1], p[3 * s + 2], first[s], step[s], r, c, static_cast<long>(s + 1));
    r += c;
  }
  return b;
}

nb::ndarray<nb::numpy, double> poses_of(const std::vector<double> &x, const std::vector<double> &y,
                                        const std::vector<double> &t) {
  std::vector<double> p(3 * x.size());
  for (size_t s = 0; s < x.size(); ++s) {
    p[3 * s] = x[s];
    p[3 * s + 1] = y[s];
    p[3 * s + 2] = t[s];
  }
  return owned(std::move(p), {x.size(), 3});
}

std::vector<vasco::Pose> poses_from(nb::handle obj) {
  auto a = as_array<double>(obj, "float64", "poses", 2);
  if (a.shape(1) != 3) throw std::invalid_argument("poses: expected shape (n, 3) (x, y, theta per scan)");
  std::vector<vasco::Pose> p(a.shape(0));
  const double *d = a.data();
  for (size_t s = 0; s < p.size(); ++s) p[s] = {d[3 * s], d[3 * s + 1], d[3 * s + 2]};
  return p;
}

// ---------------------------------------------------------------------------
// Mapper: one session, calls serialised (the GIL is released while it maps).
// ---------------------------------------------------------------------------
struct PyMapper {
  std::unique_ptr<vasco::Mapper> mapper;
  mutable std::mutex mutex;
};

vasco::BackendOptions backend_options(const std::string &backend, const std::optional<std::string> &cuda_mode,
                                      int threads, int cuda_device, uint64_t max_memory_bytes, std::string *name) {
  vasco::BackendOptions o;
  if (cuda_mode) {
    if (*cuda_mode == "float") o.cuda_mode = vasco::CudaMode::Float;
    else if (*cuda_mode == "exact") o.cuda_mode = vasco::CudaMode::Exact;
    else throw std::invalid_argument("cuda_mode '" + *cuda_mode + "': expected 'float' or 'exact'");
  }
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: all cores)");
  o.threads = threads;
  o.cuda_device = cuda_device;
  o.max_memory_bytes = max_memory_bytes;
  const vasco::CudaMode asked = o.cuda_mode;
  *name = vasco::resolve_backend_name(backend, &o);
  if (cuda_mode && o.cuda_mode != asked)
    throw std::invalid_argument("backend '" + backend + "' contradicts cuda_mode='" + *cuda_mode + "'");
  return o;
}

nb::dict stats_dict(const vasco::MapStats &s) {
  nb::dict d;
  d["scans"] = s.scans;
  d["beams_used"] = s.beams_used;
  d["beams_skipped"] = s.beams_skipped;
  d["cell_updates"] = s.cell_updates;
  d["prep_s"] = s.prep_s;
  d["upload_s"] = s.upload_s;
  d["map_s"] = s.map_s;
  d["download_s"] = s.download_s;
  return d;
}

nb::dict load_stats_dict(const vasco::LogLoadStats &l) {
  nb::dict d;
  const carmen::LogStats &s = l.log;
  d["lines"] = s.lines;
  d["laser_messages"] = l.laser_messages;
  d["scans_used"] = l.scans_used;
  nb::dict messages;
  for (int t = 0; t < carmen::kNumMessageTypes; ++t)
    if (s.messages[t] > 0) messages[carmen::message_type_name(static_cast<carmen::MessageType>(t))] = s.messages[t];
  d["messages"] = messages;
  d["blank_lines"] = s.blank_lines;
  d["comment_lines"] = s.comment_lines;
  d["unknown_lines"] = s.unknown_lines;
  nb::dict bad;
  for (int b = 0; b < carmen::kNumBadLineClasses; ++b)
    if (s.bad_lines[b] > 0) bad[carmen::bad_line_name(static_cast<carmen::BadLine>(b))] = s.bad_lines[b];
  d["bad_lines"] = bad;
  d["nan_ranges"] = s.nan_ranges;
  d["inf_ranges"] = s.inf_ranges;
  d["negative_ranges"] = s.negative_ranges;
  return d;
}

bool cuda_available(std::string *why) {
#if defined(VASCO_HAVE_CUDA)
  return vasco::cuda_usable(0, why);
#else
  *why = "this build has no CUDA backend (no CUDA toolkit when it was built)";
  return false;
#endif
}

}  // namespace

namespace {

// The error translator, the version and the module-level functions.
void bind_module(nb::module_ &m) {
  m.doc() = "vasco_gpu's C++ engine (see the package vasco_gpu for the documentation).";

  // carmen::FileError -> vasco_gpu.FileError(text, file, line, message).
  // The class travels as the translator's payload, one per initialisation of
  // the module (a re-import gets its own translator and class, never a stale
  // one); the reference is kept for the life of the process (no destructor at
  // exit). Other exceptions leave the translator as they came, for nanobind's
  // own translator (std::invalid_argument -> ValueError, ...).
  PyObject *file_error = nb::object(nb::module_::import_("vasco_gpu._errors").attr("FileError")).release().ptr();
  nb::register_exception_translator(
      [](const std::exception_ptr &p, void *payload) {
        try {
          std::rethrow_exception(p);
        } catch (const carmen::FileError &e) {
          nb::handle cls(static_cast<PyObject *>(payload));
          nb::object line = e.line() > 0 ? nb::object(nb::int_(e.line())) : nb::none();
          nb::object exc = cls(carmen::printable(e.what()), e.file(), line, e.message());
          PyErr_SetObject(cls.ptr(), exc.ptr());
        }
      },
      file_error);

  m.attr("__version__") = vasco::version();
#if defined(VASCO_HAVE_CUDA)
  m.attr("has_cuda") = true;
#else
  m.attr("has_cuda") = false;
#endif
  m.def("backends", &vasco::compiled_backends,
        "The backend names this build knows: cpu_double, cpu_threads, cpu_float, cuda (when built with\n"
        "CUDA) and auto.");
  m.def(
      "cuda_available",
      []() {
        std::string why;
        nb::gil_scoped_release r;
        const bool ok = cuda_available(&why);
        return std::make_pair(ok, why);
      },
      "Whether the CUDA backend can run here (built with CUDA and a usable GPU), and why not.\n\n"
      "Returns ``(True, '')`` or ``(False, reason)``. The first call starts the CUDA context (a few\n"
      "tenths of a second).");
}

// The docstring of the class Params.
constexpr const char *kParamsDoc =
    "The mapper's parameters: carmen.ini's ``vasco_*`` keys without the prefix.\n\n"
    "``Params(p_occ=0.9, resolution=0.05)`` (the ``vasco_`` prefix is accepted\n"
    "too: ``Params(vasco_p_occ=0.9)``) starts from vasco's defaults and is\n"
    "validated; an unknown keyword is a TypeError, a value out of range a\n"
    "ValueError naming the key. Attributes may be changed afterwards; the Mapper\n"
    "validates them again.\n\n"
    "Keys (default): resolution (0.025 m), p_prior (0.5), p_occ (0.55), p_emp\n"
    "(0.45), range_sure (5.0 m), range_max (10.0 m), wall_size (0.2 m), downsample\n"
    "(4), border (20), first_scan (0), num_scans (-1: all).";

// Params' constructors (keywords, from_ini) and keys().
void bind_params_constructors(nb::class_<vasco::MapperParams> &cls) {
  cls.def(
         "__init__",
         [](vasco::MapperParams *self, nb::kwargs kwargs) {
           vasco::MapperParams p;
           for (auto [k, v] : kwargs) set_param(p, nb::cast<std::string>(k), v);
           p.validate();
           new (self) vasco::MapperParams(p);
         },
         nb::sig("def __init__(self, **params: float | int) -> None"),
         "Parameters from keywords (ini key names, with or without ``vasco_``); the rest keep vasco's\n"
         "defaults. Validated.")
      .def_static(
          "from_ini",
          [](const fs::path &path, const std::string &robot, nb::kwargs overrides) {
            carmen::ParamFile pf = carmen::ParamFile::load(path.string(), robot);
            for (auto [k, v] : overrides) {
              std::string name = nb::cast<std::string>(k);
              if (find_key(name) == nullptr) set_param(*std::make_unique<vasco::MapperParams>(), name, v);  // raises
              if (name.rfind("vasco_", 0) != 0) name = "vasco_" + name;
              pf.set_override(name, nb::cast<std::string>(nb::str(v)));
            }
            return vasco::MapperParams::from_params(pf, nullptr);
          },
          "path"_a, "robot"_a = "", "overrides"_a,
          nb::sig("def from_ini(path: str | os.PathLike, robot: str = '', **overrides: float | int) -> Params"),
          "Parameters from a carmen.ini (sections [*], [expert] and the robot's, as CARMEN's param_daemon\n"
          "reads them), keywords overriding the file. Errors raise FileError naming FILE:LINE.")
      .def_static(
          "keys", []() { return vasco::mapper_param_keys(); },
          "The ini keys the mapper understands (vasco_resolution, ...).");
}

// Params' methods: validate, to_dict, repr, equality and copies.
void bind_params_methods(nb::class_<vasco::MapperParams> &cls) {
  cls.def("validate", &vasco::MapperParams::validate,
          "Raises ValueError naming the key when a value is out of range.")
      .def("to_dict", &params_dict, "The parameters as a dict (keys without ``vasco_``).")
      .def("__repr__", &params_repr)
      .def("__eq__",
           [](const vasco::MapperParams &a, nb::handle b) -> nb::object {
             if (!nb::isinstance<vasco::MapperParams>(b)) return nb::borrow(Py_NotImplemented);
             return nb::bool_(params_dict(a).equal(params_dict(nb::cast<const vasco::MapperParams &>(b))));
           }, nb::sig("def __eq__(self, other: object) -> bool"))
      .def("__copy__", [](const vasco::MapperParams &p) { return p; })
      .def("__deepcopy__", [](const vasco::MapperParams &p, nb::handle) { return p; }, "memo"_a);
}

// Params' attributes, one per ini key.
void bind_params_attributes(nb::class_<vasco::MapperParams> &cls) {
  cls.def_rw("resolution", &vasco::MapperParams::resolution, "vasco_resolution: cell size in metres.")
      .def_rw("p_prior", &vasco::MapperParams::p_prior, "vasco_p_prior: prior occupancy.")
      .def_rw("p_occ", &vasco::MapperParams::p_occ, "vasco_p_occ: evidence of a hit.")
      .def_rw("p_emp", &vasco::MapperParams::p_emp, "vasco_p_emp: evidence of a free cell.")
      .def_rw("range_sure", &vasco::MapperParams::range_sure, "vasco_range_sure: full-confidence range (m).")
      .def_rw("range_max", &vasco::MapperParams::range_max, "vasco_range_max: evidence ends here (m).")
      .def_rw("wall_size", &vasco::MapperParams::wall_size,
              "vasco_wall_size: thickness marked occupied behind a hit (m).")
      .def_rw("downsample", &vasco::MapperParams::downsample, "vasco_downsample: finish's block size.")
      .def_rw("border", &vasco::MapperParams::border, "vasco_border: cells kept around the known area.")
      .def_rw("first_scan", &vasco::MapperParams::first_scan,
              "vasco_first_scan: first laser message used by load_log.")
      .def_rw("num_scans", &vasco::MapperParams::num_scans,
              "vasco_num_scans: laser messages used by load_log (-1: all).");
}

// The class Params.
void bind_params(nb::module_ &m) {
  auto params_class = nb::class_<vasco::MapperParams>(m, "Params", kParamsDoc);
  bind_params_constructors(params_class);
  bind_params_methods(params_class);
  bind_params_attributes(params_class);
  params_class.attr("__hash__") = nb::none();  // mutable, compared by value
}

void bind_frame(nb::module_ &m) {
  nb::class_<vasco::GridGeometry>(m, "Frame",
                                  "Where a full-resolution evidence grid lies: size in cells, resolution,\n"
                                  "the first scan's heading (theta_offset) and laser position (x0, y0); the\n"
                                  "grid is centred on (x0, y0). Pass one to Mapper(frame=...) for a fixed frame\n"
                                  "(size, resolution and theta_offset are used; x0 and y0 come from the first\n"
                                  "scan).")
      .def(
          "__init__",
          [](vasco::GridGeometry *self, int size_x, int size_y, double resolution, double theta_offset) {
            auto *g = new (self) vasco::GridGeometry();
            g->size_x = size_x;
            g->size_y = size_y;
            g->resolution = resolution;
            g->theta_offset = theta_offset;
          },
          "size_x"_a, "size_y"_a, "resolution"_a, "theta_offset"_a = 0.0)
      .def_rw("size_x", &vasco::GridGeometry::size_x)
      .def_rw("size_y", &vasco::GridGeometry::size_y)
      .def_rw("resolution", &vasco::GridGeometry::resolution)
      .def_rw("theta_offset", &vasco::GridGeometry::theta_offset)
      .def_rw("x0", &vasco::GridGeometry::x0)
      .def_rw("y0", &vasco::GridGeometry::y0)
      .def("world_x", &vasco::GridGeometry::world_x, "gx"_a,
           "World x of the lower-left corner of cell column gx.")
      .def("world_y", &vasco::GridGeometry::world_y, "gy"_a, "World y of the lower-left corner of cell row gy.")
      .def("__repr__", [](const vasco::GridGeometry &g) {
        return nb::str("Frame(size_x={}, size_y={}, resolution={}, theta_offset={}, x0={}, y0={})")
            .format(g.size_x, g.size_y, g.resolution, g.theta_offset, g.x0, g.y0);
      });
}

// The docstring of the class Scans.
constexpr const char *kScansDoc =
    "Laser scans, stored as CARMEN reads them: a pose (x, y, theta of the laser, float64) and beam\n"
    "geometry (first_angle relative to theta, angle_step) per scan, ranges as float32, all scans'\n"
    "beams concatenated.\n\n"
    "``ranges``, ``x``, ``y``, ``theta``, ``first_angle``, ``angle_step``, ``beam_offsets`` and\n"
    "``lines`` are writable NumPy views of the object's memory (they keep it alive); ``poses``\n"
    "and ``beam_counts`` are new arrays.";

// Scans' constructor from arrays, its length and beam count.
void bind_scans_constructor(nb::class_<vasco::ScanBatch> &cls) {
  cls.def(
         "__init__",
         [](vasco::ScanBatch *self, nb::handle poses, nb::handle ranges, nb::handle beam_counts,
            nb::handle first_angle, nb::handle angle_step) {
           new (self) vasco::ScanBatch(make_scans(poses, ranges, beam_counts, first_angle, angle_step));
         },
         "poses"_a, "ranges"_a, "beam_counts"_a, "first_angle"_a, "angle_step"_a,
         nb::sig("def __init__(self, poses: numpy.typing.ArrayLike, ranges: numpy.typing.ArrayLike, "
                 "beam_counts: numpy.typing.ArrayLike, first_angle: float | numpy.typing.ArrayLike, "
                 "angle_step: float | numpy.typing.ArrayLike) -> None"),
         "Scans from arrays (copied): poses (n, 3), ranges (sum of beam_counts,), beam_counts (n,),\n"
         "first_angle and angle_step a number or one value per scan (radians; CARMEN's 181-beam SICK:\n"
         "first_angle=-pi/2, angle_step=pi/180).")
      .def("__len__", &vasco::ScanBatch::num_scans)
      .def_prop_ro("num_beams", &vasco::ScanBatch::num_beams);
}

// Scans' arrays that are views of its memory.
void bind_scans_views(nb::class_<vasco::ScanBatch> &cls) {
  cls.def_prop_ro(
         "ranges", [](nb::handle_t<vasco::ScanBatch> self) { return view1(nb::cast<vasco::ScanBatch &>(self).range, self); }, nb::rv_policy::reference,
         "All beams' ranges, float32, scan after scan (a view).")
      .def_prop_ro(
          "x", [](nb::handle_t<vasco::ScanBatch> self) { return view1(nb::cast<vasco::ScanBatch &>(self).x, self); }, nb::rv_policy::reference,
          "Laser x per scan (a view).")
      .def_prop_ro(
          "y", [](nb::handle_t<vasco::ScanBatch> self) { return view1(nb::cast<vasco::ScanBatch &>(self).y, self); }, nb::rv_policy::reference,
          "Laser y per scan (a view).")
      .def_prop_ro(
          "theta",
          [](nb::handle_t<vasco::ScanBatch> self) { return view1(nb::cast<vasco::ScanBatch &>(self).theta, self); }, nb::rv_policy::reference,
          "Laser heading per scan (a view).")
      .def_prop_ro(
          "first_angle",
          [](nb::handle_t<vasco::ScanBatch> self) {
            return view1(nb::cast<vasco::ScanBatch &>(self).first_angle, self);
          }, nb::rv_policy::reference,
          "Angle of beam 0 relative to theta, per scan (a view).")
      .def_prop_ro(
          "angle_step",
          [](nb::handle_t<vasco::ScanBatch> self) { return view1(nb::cast<vasco::ScanBatch &>(self).angle_step, self); }, nb::rv_policy::reference,
          "Angle added after every beam, per scan (a view).")
      .def_prop_ro(
          "beam_offsets",
          [](nb::handle_t<vasco::ScanBatch> self) {
            return view1(nb::cast<vasco::ScanBatch &>(self).beam_offset, self);
          }, nb::rv_policy::reference,
          "Scan s owns ranges[beam_offsets[s]:beam_offsets[s + 1]] (uint64, n + 1 entries, a view).")
      .def_prop_ro(
          "lines", [](nb::handle_t<vasco::ScanBatch> self) { return view1(nb::cast<vasco::ScanBatch &>(self).line, self); }, nb::rv_policy::reference,
          "Line of each scan in its log (a view).");
}

// Scans' new arrays, one scan's ranges, select and repr.
void bind_scans_methods(nb::class_<vasco::ScanBatch> &cls) {
  cls.def_prop_ro(
         "poses", [](const vasco::ScanBatch &b) { return poses_of(b.x, b.y, b.theta); }, nb::rv_policy::reference,
         "(n, 3) float64 array of (x, y, theta): a new array.")
      .def_prop_ro(
          "beam_counts",
          [](const vasco::ScanBatch &b) {
            std::vector<int64_t> c(b.num_scans());
            for (size_t s = 0; s < c.size(); ++s) c[s] = b.beams_in(s);
            return owned(std::move(c), {c.size()});
          }, nb::rv_policy::reference,
          "Beams per scan (int64): a new array.")
      .def(
          "ranges_of",
          [](nb::handle_t<vasco::ScanBatch> self, long s) {
            vasco::ScanBatch &b = nb::cast<vasco::ScanBatch &>(self);
            if (s < 0) s += static_cast<long>(b.num_scans());
            if (s < 0 || static_cast<size_t>(s) >= b.num_scans()) throw nb::index_error("scan index out of range");
            return Array1<float>(b.range.data() + b.beam_offset[s], {static_cast<size_t>(b.beams_in(s))}, self);
          },
          "s"_a, nb::rv_policy::reference, "The ranges of scan s (a view).")
      .def("select", &vasco::ScanBatch::select, "first"_a, "count"_a = -1,
           "Scans [first, first + count) as new Scans (count -1: to the end), clipped to the batch.")
      .def("__repr__", [](const vasco::ScanBatch &b) {
        return nb::str("Scans({} scans, {} beams)").format(b.num_scans(), b.num_beams());
      });
}

// The class Scans.
void bind_scans(nb::module_ &m) {
  nb::class_<vasco::ScanBatch> cls(m, "Scans", kScansDoc);
  bind_scans_constructor(cls);
  bind_scans_views(cls);
  bind_scans_methods(cls);
}

void bind_log(nb::module_ &m) {
  nb::class_<vasco::LogInput>(m, "Log",
                              "A CARMEN log read by load_log: the selected scans, the effective parameters\n"
                              "(keywords > ini > the log's PARAM lines > defaults), the PROTOCOL frame and\n"
                              "what the reader counted.")
      .def_prop_ro(
          "scans", [](vasco::LogInput &in) -> vasco::ScanBatch & { return in.batch; }, nb::rv_policy::reference_internal,
          "The selected scans (FLASER and ROBOTLASER1 lines, in log order); its arrays are views.")
      .def_prop_ro(
          "params", [](const vasco::LogInput &in) { return in.params; }, "The effective parameters (a copy).")
      .def_prop_ro(
          "frame", [](const vasco::LogInput &in) { return in.geo; },
          "The PROTOCOL frame of the selected scans (a copy): what Mapper uses by default.")
      .def_prop_ro(
          "poses", [](const vasco::LogInput &in) { return poses_of(in.batch.x, in.batch.y, in.batch.theta); }, nb::rv_policy::reference,
          "(n, 3) float64 laser poses (x, y, theta): a new array.")
      .def_prop_ro(
          "ranges", [](nb::handle_t<vasco::LogInput> self) { return view1(nb::cast<vasco::LogInput &>(self).batch.range, self); }, nb::rv_policy::reference,
          "All ranges, float32 (a view; see Scans).")
      .def_ro("warnings", &vasco::LogInput::warnings, "Unknown vasco_* keys and the like.")
      .def_prop_ro(
          "stats", [](const vasco::LogInput &in) { return load_stats_dict(in.load); },
          "What the reader counted: lines, messages by type, bad lines by class (lenient mode), odd\n"
          "ranges, scans used.")
      .def("__len__", [](const vasco::LogInput &in) { return in.batch.num_scans(); })
      .def("__repr__", [](const vasco::LogInput &in) {
        return nb::str("Log({} scans, {} beams)").format(in.batch.num_scans(), in.batch.num_beams());
      });

  m.def(
      "load_log",
      [](const fs::path &path, std::optional<fs::path> param_file, const std::string &robot,
         std::optional<nb::dict> overrides, bool lenient) {
        vasco::LogInputOptions o;
        o.log = path.string();
        if (param_file) o.param_file = param_file->string();
        o.robot = robot;
        o.lenient = lenient;
        if (overrides) {
          for (auto [k, v] : *overrides) {
            std::string name = nb::cast<std::string>(k);
            if (find_key(name) == nullptr) set_param(*std::make_unique<vasco::MapperParams>(), name, v);  // raises
            if (name.rfind("vasco_", 0) != 0) name = "vasco_" + name;
            o.overrides[name] = nb::cast<std::string>(nb::str(v));
          }
        }
        nb::gil_scoped_release release;
        return vasco::load_log_input(o);
      },
      "path"_a, "param_file"_a = nb::none(), "robot"_a = "", "overrides"_a = nb::none(), "lenient"_a = false,
      nb::sig("def load_log(path: str | os.PathLike, param_file: str | os.PathLike | None = None, "
              "robot: str = '', overrides: dict[str, float | int] | None = None, lenient: bool = False) -> Log"),
      "Reads a CARMEN log (.log, .clf, gzipped if the name ends in .gz) as log2map does.\n\n"
      "Every FLASER and ROBOTLASER1 line is a scan; ``param_file`` is a carmen.ini (``robot`` its\n"
      "section), ``overrides`` keys as in Params (they win over the ini, which wins over the log's\n"
      "PARAM lines). Strict by default: a bad line raises FileError with ``.file`` and ``.line``;\n"
      "``lenient=True`` skips bad lines and counts them in ``Log.stats['bad_lines']``. The GIL is\n"
      "released while the log is read.");
}

// The docstring of the class Map.
constexpr const char *kMapDoc =
    "A finished occupancy map (or one read from a file).\n\n"
    "``cells`` is a writable 2-D float32 NumPy view of the map's memory, shape (size_x,\n"
    "size_y), x-major as CARMEN stores it: ``cells[x, y]`` is the cell x columns right of and y\n"
    "rows above the lower-left corner; -1 is unknown, else the occupancy probability.\n"
    "``image`` is the same memory seen as a picture (``cells.T[::-1]``: row 0 at the top, +y up),\n"
    "also a view. ``origin`` is the world pose (x, y, theta) of the lower-left corner of cell\n"
    "(0, 0), as CARMEN's OFFSET chunk and map_server's YAML give it.";

// The docstring of write_map.
constexpr const char *kWriteMapDoc =
    "Writes a map, the format chosen by the name: ``.map`` / ``.map.gz`` (CARMEN, with an OFFSET\n"
    "chunk when the map has an origin), ``.pgm`` (ROS map_server image plus a ``.yaml`` beside it;\n"
    "``mode`` trinary, scale or raw) or ``.png`` (grey: white free, black occupied, mid grey\n"
    "unknown). Atomic: a failure leaves no file behind. Raises FileError naming the file.";

// Map's constructor from cells and its two views of them (cells, image).
void bind_map_cells(nb::class_<Map> &cls) {
  cls.def(
         "__init__",
         [](Map *self, nb::handle cells, double resolution, std::tuple<double, double, double> origin) {
           auto a = as_array<float>(cells, "float32", "cells", 2);
           Map mp;
           mp.grid.size_x = static_cast<int>(a.shape(0));
           mp.grid.size_y = static_cast<int>(a.shape(1));
           mp.grid.resolution = resolution;
           mp.grid.cells.assign(a.data(), a.data() + a.size());
           mp.origin = {std::get<0>(origin), std::get<1>(origin), std::get<2>(origin)};
           mp.has_origin = true;
           new (self) Map(std::move(mp));
         },
         "cells"_a, "resolution"_a, "origin"_a = std::make_tuple(0.0, 0.0, 0.0),
         nb::sig("def __init__(self, cells: numpy.typing.ArrayLike, resolution: float, "
                 "origin: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None"),
         "A map from x-major cells (size_x, size_y), copied into the map.")
      .def_prop_ro(
          "cells",
          [](nb::handle_t<Map> self) {
            Map &mp = nb::cast<Map &>(self);
            return Array2<float>(mp.grid.cells.data(),
                                 {static_cast<size_t>(mp.grid.size_x), static_cast<size_t>(mp.grid.size_y)}, self);
          }, nb::rv_policy::reference,
          nb::sig("def cells(self) -> numpy.typing.NDArray[numpy.float32]"),
          "(size_x, size_y) float32, x-major (cells[x, y]); a view of the map's memory.")
      .def_prop_ro(
          "image",
          [](nb::handle_t<Map> self) {
            Map &mp = nb::cast<Map &>(self);
            const int64_t sy = mp.grid.size_y;
            float *last_row = mp.grid.cells.empty() ? nullptr : mp.grid.cells.data() + (sy - 1);
            return Array2<float>(last_row, {static_cast<size_t>(mp.grid.size_y), static_cast<size_t>(mp.grid.size_x)},
                                 self, {-1, sy});
          }, nb::rv_policy::reference,
          nb::sig("def image(self) -> numpy.typing.NDArray[numpy.float32]"),
          "(size_y, size_x) float32 view with row 0 at the top (``cells.T[::-1]``), for plotting.");
}

// Map's size, resolution, origin and finish's crop, its digest and repr.
void bind_map_properties(nb::class_<Map> &cls) {
  cls.def_prop_ro("size_x", [](const Map &mp) { return mp.grid.size_x; })
      .def_prop_ro("size_y", [](const Map &mp) { return mp.grid.size_y; })
      .def_prop_ro("shape", [](const Map &mp) { return std::make_tuple(mp.grid.size_x, mp.grid.size_y); })
      .def_prop_rw(
          "resolution", [](const Map &mp) { return mp.grid.resolution; },
          [](Map &mp, double r) { mp.grid.resolution = r; }, "Metres per cell.")
      .def_prop_rw(
          "origin", [](const Map &mp) { return std::make_tuple(mp.origin.x, mp.origin.y, mp.origin.theta); },
          [](Map &mp, std::tuple<double, double, double> o) {
            mp.origin = {std::get<0>(o), std::get<1>(o), std::get<2>(o)};
            mp.has_origin = true;
          },
          "World pose (x, y, theta) of the lower-left corner of cell (0, 0); (0, 0, 0) when unknown.")
      .def_prop_ro("has_origin", [](const Map &mp) { return mp.has_origin; },
                   "False for a CARMEN map without an OFFSET chunk and for PNG images.")
      .def_prop_ro("downsample", [](const Map &mp) { return mp.downsample; },
                   "The block size finish used (1 for maps read from files).")
      .def_prop_ro("offset_cells", [](const Map &mp) { return std::make_pair(mp.min_x, mp.min_y); },
                   "finish's crop offset (min_x, min_y), in downsampled cells.")
      .def(
          "sha256", [](const Map &mp) {
            return vasco::gridmap_payload_sha256(mp.grid.size_x, mp.grid.size_y, mp.grid.resolution, mp.grid.cells);
          },
          "SHA-256 of the map's CARMEN GRIDMAP payload (what the golden SHA256SUMS hold).")
      .def("__repr__", [](const Map &mp) {
        return nb::str("Map(size_x={}, size_y={}, resolution={}, origin=({}, {}, {}))")
            .format(mp.grid.size_x, mp.grid.size_y, mp.grid.resolution, mp.origin.x, mp.origin.y, mp.origin.theta);
      });
}

// The module functions that read and write maps: _read_map, write_map.
void bind_map_files(nb::module_ &m) {
  m.def(
      "_read_map",
      [](const fs::path &path) {
        const std::string p = path.string();
        const std::string ext = ext_of(p);
        nb::gil_scoped_release release;
        if (ext == ".png") return read_png_map(p);
        carmen::MapFile mf = carmen::read_map_file(p);
        if (!mf.gridmap) throw carmen::FileError(p, "no GRIDMAP chunk");
        Map mp;
        mp.grid = std::move(*mf.gridmap);
        if (mf.offset) {
          mp.origin = *mf.offset;
          mp.has_origin = true;
        }
        return mp;
      },
      "path"_a, nb::sig("def _read_map(path: str | os.PathLike) -> Map"),
      "Reads a CARMEN map (.map, .map.gz) or a PNG (lossy).");
  m.def(
      "write_map",
      [](const fs::path &path, const Map &mp, const std::string &mode, const std::string &description) {
        nb::gil_scoped_release release;
        write_map(path.string(), mp, mode, description);
      },
      "path"_a, "map"_a, "mode"_a = "trinary", "description"_a = "",
      nb::sig("def write_map(path: str | os.PathLike, map: Map, mode: str = 'trinary', description: str = '') -> None"),
      kWriteMapDoc);
}

// The class Map and the functions that read and write maps.
void bind_map(nb::module_ &m) {
  nb::class_<Map> cls(m, "Map", kMapDoc);
  bind_map_cells(cls);
  bind_map_properties(cls);
  bind_map_files(m);
}

// The docstring of compare.
constexpr const char *kCompareDoc =
    "Compares map B with map A (the reference): DESIGN section 4's table (class agreement,\n"
    "known/unknown differences, |dp| > 0.1, max |dp|, bit-identical cells). Maps whose origins\n"
    "are a whole number of cells apart are aligned by them (``align=False``: cell (0, 0) on cell\n"
    "(0, 0)). ``top``: how many of the largest differences to keep in ``.largest``.";

// Every count of a comparison as a dict (Comparison.to_dict).
nb::dict comparison_dict(const vasco::GridComparison &c) {
  const vasco::Agreement &a = c.agreement;
  nb::dict d;
  d["cells"] = a.cells;
  d["both_known"] = a.both_known;
  d["status_differs"] = a.status_differs;
  d["identical"] = a.identical;
  d["max_abs_diff"] = a.max_abs_diff;
  d["large_diffs"] = a.large_diffs;
  d["class_agree"] = a.class_agree;
  d["class_agreement"] = a.class_agreement();
  d["occupied_ref"] = a.occupied_ref;
  d["occupied_agree"] = a.occupied_agree;
  d["free_ref"] = a.free_ref;
  d["free_agree"] = a.free_agree;
  d["unknown_ref"] = a.unknown_ref;
  d["unknown_agree"] = a.unknown_agree;
  d["shift_x"] = c.shift_x;
  d["shift_y"] = c.shift_y;
  d["outside"] = c.outside;
  d["outside_known"] = c.outside_known;
  d["same_cells"] = c.same_cells();
  return d;
}

// Comparison's agreement counts over the overlap.
void bind_comparison_counts(nb::class_<vasco::GridComparison> &cls) {
  cls.def_prop_ro("cells", [](const vasco::GridComparison &c) { return c.agreement.cells; }, "Cells compared (the overlap).")
      .def_prop_ro("both_known", [](const vasco::GridComparison &c) { return c.agreement.both_known; })
      .def_prop_ro("status_differs", [](const vasco::GridComparison &c) { return c.agreement.status_differs; },
                   "Known in one map, unknown in the other.")
      .def_prop_ro("identical", [](const vasco::GridComparison &c) { return c.agreement.identical; },
                   "Bit-identical cells.")
      .def_prop_ro("max_abs_diff", [](const vasco::GridComparison &c) { return c.agreement.max_abs_diff; },
                   "max |a - b| over cells known in both.")
      .def_prop_ro("large_diffs", [](const vasco::GridComparison &c) { return c.agreement.large_diffs; },
                   "Cells known in both with |a - b| > 0.1.")
      .def_prop_ro("class_agree", [](const vasco::GridComparison &c) { return c.agreement.class_agree; })
      .def_prop_ro("class_agreement", [](const vasco::GridComparison &c) { return c.agreement.class_agreement(); },
                   "Share of cells in the same class (occupied p > 0.5, free p < 0.5, unknown).")
      .def_prop_ro("occupied_ref", [](const vasco::GridComparison &c) { return c.agreement.occupied_ref; })
      .def_prop_ro("occupied_agree", [](const vasco::GridComparison &c) { return c.agreement.occupied_agree; })
      .def_prop_ro("free_ref", [](const vasco::GridComparison &c) { return c.agreement.free_ref; })
      .def_prop_ro("free_agree", [](const vasco::GridComparison &c) { return c.agreement.free_agree; })
      .def_prop_ro("unknown_ref", [](const vasco::GridComparison &c) { return c.agreement.unknown_ref; })
      .def_prop_ro("unknown_agree", [](const vasco::GridComparison &c) { return c.agreement.unknown_agree; });
}

// Comparison's alignment, the cells outside the overlap and the largest differences.
void bind_comparison_extent(nb::class_<vasco::GridComparison> &cls) {
  cls.def_ro("shift_x", &vasco::GridComparison::shift_x, "B's cell (bx, by) lies on A's (bx + shift_x, by + shift_y).")
      .def_ro("shift_y", &vasco::GridComparison::shift_y)
      .def_ro("outside", &vasco::GridComparison::outside, "Cells of A or B outside the overlap (they differ).")
      .def_ro("outside_known", &vasco::GridComparison::outside_known)
      .def_prop_ro("differing_cells", &vasco::GridComparison::differing_cells)
      .def_prop_ro("same_cells", &vasco::GridComparison::same_cells,
                   "Bit-identical over the overlap and nothing outside it.")
      .def_prop_ro(
          "largest",
          [](const vasco::GridComparison &c) {
            std::vector<std::tuple<int, int, float, float>> v;
            for (const auto &d : c.largest) v.emplace_back(d.x, d.y, d.a, d.b);
            return v;
          },
          "Up to `top` cells known in both whose bits differ, largest |a - b| first: (x, y, a, b).");
}

// Comparison's table, dict, str and repr.
void bind_comparison_methods(nb::class_<vasco::GridComparison> &cls) {
  cls.def("table", [](const vasco::GridComparison &c, const std::string &title) { return c.agreement.table(title); },
          "title"_a = "B against A", "The table as text.")
      .def(
          "to_dict", [](const vasco::GridComparison &c) { return comparison_dict(c); }, "Every count as a dict.")
      .def("__str__", [](const vasco::GridComparison &c) { return c.agreement.table("B against A"); })
      .def("__repr__", [](const vasco::GridComparison &c) {
        const vasco::Agreement &a = c.agreement;
        return nb::str("Comparison(cells={}, class_agreement={:.6f}, status_differs={}, large_diffs={}, "
                       "max_abs_diff={}, identical={}, outside={})")
            .format(a.cells, a.class_agreement(), a.status_differs, a.large_diffs, a.max_abs_diff, a.identical,
                    c.outside);
      });
}

// The class Comparison and the function compare.
void bind_compare(nb::module_ &m) {
  nb::class_<vasco::GridComparison> cls(
      m, "Comparison",
      "DESIGN section 4's agreement table of map B against map A (the reference), over their overlap.");
  bind_comparison_counts(cls);
  bind_comparison_extent(cls);
  bind_comparison_methods(cls);

  m.def(
      "compare",
      [](const Map &a, const Map &b, bool align, size_t top) {
        nb::gil_scoped_release release;
        int64_t sx = 0, sy = 0;
        if (align && a.has_origin && b.has_origin) {
          std::string why;
          if (!vasco::offset_shift(a.origin, b.origin, a.grid.resolution, &sx, &sy, &why)) sx = sy = 0;
        }
        return vasco::compare_grids(a.grid, b.grid, sx, sy, top);
      },
      "a"_a, "b"_a, "align"_a = true, "top"_a = 0, kCompareDoc);
}

// The docstring of the class Mapper.
constexpr const char *kMapperDoc =
    "A mapping session (DESIGN section 7): scans stored once (on the GPU for ``cuda``), poses\n"
    "replaceable as a whole, the evidence grid kept between calls.\n\n"
    "    mapper = vasco_gpu.Mapper(params, backend='cuda', cuda_mode='exact')\n"
    "    mapper.insert(log.scans)          # new scans continue the grid\n"
    "    mapper.render(new_poses)          # a loop closure: every pose moved, recomputed\n"
    "    m = mapper.finish()               # CARMEN's finish -> Map\n\n"
    "Backends: cpu_double (CARMEN's routine, bit-identical), cpu_threads (the same bytes on every\n"
    "core), cpu_float (single precision), cuda (cuda_mode 'float', the default, or 'exact':\n"
    "CARMEN's bytes), auto (cuda when a GPU is usable, else cpu_threads); 'cuda_exact' and\n"
    "'cuda_float' name the CUDA modes too. The GIL is released while the session maps; calls on\n"
    "one Mapper from several threads are serialised.";

// The docstring of Mapper.__init__.
constexpr const char *kMapperInitDoc =
    "A session with ``params`` (vasco's defaults when None) on ``backend``.\n\n"
    "cuda_mode: 'float' (default) or 'exact'. threads: cpu_threads' threads (0: all cores).\n"
    "frame: a fixed Frame (cells outside it are skipped, as CARMEN does) instead of the PROTOCOL\n"
    "frame, which grows as scans arrive. max_memory_bytes: host memory the session may use (0: no\n"
    "limit). Raises ValueError for bad parameters or an unknown backend, RuntimeError when the\n"
    "backend cannot run here (e.g. cuda without a GPU).";

// Mapper's constructor: a session with the given parameters on the given backend.
void bind_mapper_constructor(nb::class_<PyMapper> &cls) {
  cls.def(
      "__init__",
      [](PyMapper *self, std::optional<vasco::MapperParams> params, const std::string &backend,
         std::optional<std::string> cuda_mode, int threads, std::optional<vasco::GridGeometry> frame,
         int cuda_device, uint64_t max_memory_bytes) {
        std::string name;
        const vasco::BackendOptions o =
            backend_options(backend, cuda_mode, threads, cuda_device, max_memory_bytes, &name);
        const vasco::MapperParams p = params ? *params : vasco::MapperParams();
        std::unique_ptr<vasco::Mapper> mp;
        {
          nb::gil_scoped_release release;
          p.validate();
          mp = frame ? std::make_unique<vasco::Mapper>(p, *frame, name, o) : std::make_unique<vasco::Mapper>(p, name, o);
        }
        auto *pm = new (self) PyMapper();
        pm->mapper = std::move(mp);
      },
      "params"_a = nb::none(), "backend"_a = "cpu_double", "cuda_mode"_a = nb::none(), "threads"_a = 0,
      "frame"_a = nb::none(), "cuda_device"_a = 0, "max_memory_bytes"_a = vasco::kDefaultMaxMemoryBytes,
      kMapperInitDoc);
}

// Mapper's calls that change the grid or finish it: insert, render, finish.
void bind_mapper_mapping(nb::class_<PyMapper> &cls) {
  cls.def(
         "insert",
         [](PyMapper &pm, const vasco::ScanBatch &scans) {
           nb::gil_scoped_release release;
           std::lock_guard<std::mutex> lock(pm.mutex);
           pm.mapper->insert(scans);
         },
         "scans"_a,
         "Stores ``scans`` after those stored and applies them to the grid (exact backends: the bytes\n"
         "of mapping everything at once). Raises RuntimeError when the frame would be too large or the\n"
         "session would exceed max_memory_bytes (nothing is stored then).")
      .def(
          "render",
          [](PyMapper &pm, nb::handle poses) {
            std::vector<vasco::Pose> p = poses_from(poses);
            nb::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(pm.mutex);
            pm.mapper->render(p);
          },
          "poses"_a, nb::sig("def render(self, poses: numpy.typing.ArrayLike) -> None"),
          "New poses for every stored scan, an (n, 3) float64 array of (x, y, theta), and the grid\n"
          "recomputed from scratch with them (only the poses travel to the GPU).")
      .def(
          "finish",
          [](PyMapper &pm, std::optional<int> downsample, std::optional<int> border) {
            nb::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(pm.mutex);
            const vasco::MapperParams &p = pm.mapper->params();
            vasco::FinishedMap f = pm.mapper->finish(downsample ? *downsample : static_cast<int>(p.downsample),
                                                     border ? *border : static_cast<int>(p.border));
            return map_from_finished(std::move(f), pm.mapper->frame());
          },
          "downsample"_a = nb::none(), "border"_a = nb::none(),
          "CARMEN's finish of the current grid (block means, crop to the known area plus ``border``),\n"
          "on the GPU for cuda; ``downsample``/``border`` default to the params'. Returns a Map whose\n"
          "cells are moved, not copied, out of the session.");
}

// Mapper's arrays out of the session: read (the grid) and poses.
void bind_mapper_arrays(nb::class_<PyMapper> &cls) {
  cls.def(
         "read",
         [](PyMapper &pm, std::optional<std::tuple<int, int, int, int>> window) {
           std::vector<float> v;
           size_t w = 0, h = 0;
           {
             nb::gil_scoped_release release;
             std::lock_guard<std::mutex> lock(pm.mutex);
             vasco::GridWindow gw;
             if (window) {
               gw = {std::get<0>(*window), std::get<1>(*window), std::get<2>(*window), std::get<3>(*window)};
             } else {
               gw = {0, 0, pm.mapper->frame().size_x, pm.mapper->frame().size_y};
             }
             v = pm.mapper->read(gw);
             w = static_cast<size_t>(gw.width);
             h = static_cast<size_t>(gw.height);
           }
           return owned(std::move(v), {w, h});
         },
         "window"_a = nb::none(),
         nb::sig("def read(self, window: tuple[int, int, int, int] | None = None) -> numpy.typing.NDArray[numpy.float32]"),
         "The full-resolution grid, or the window (x0, y0, width, height) of it, as a (width, height)\n"
         "float32 array, x-major (a new array that owns the cells C++ returned; no further copy).")
      .def_prop_ro(
          "poses",
          [](PyMapper &pm) {
            std::lock_guard<std::mutex> lock(pm.mutex);
            std::vector<vasco::Pose> p = pm.mapper->poses();
            std::vector<double> flat(3 * p.size());
            for (size_t s = 0; s < p.size(); ++s) {
              flat[3 * s] = p[s].x;
              flat[3 * s + 1] = p[s].y;
              flat[3 * s + 2] = p[s].theta;
            }
            return owned(std::move(flat), {p.size(), 3});
          }, nb::rv_policy::reference,
          "The stored scans' poses, (n, 3) float64 (a new array).");
}

// Mapper's state: size, frame, parameters, backend, statistics, renders and repr.
void bind_mapper_state(nb::class_<PyMapper> &cls) {
  cls.def("__len__", [](PyMapper &pm) {
       std::lock_guard<std::mutex> lock(pm.mutex);
       return pm.mapper->num_scans();
     })
      .def_prop_ro("num_scans", [](PyMapper &pm) {
        std::lock_guard<std::mutex> lock(pm.mutex);
        return pm.mapper->num_scans();
      }, "Scans stored.")
      .def_prop_ro("frame", [](PyMapper &pm) {
        std::lock_guard<std::mutex> lock(pm.mutex);
        return pm.mapper->frame();
      }, "The current frame (a copy).")
      .def_prop_ro("params", [](PyMapper &pm) { return pm.mapper->params(); }, "The session's parameters (a copy).")
      .def_prop_ro("backend", [](PyMapper &pm) { return pm.mapper->backend_name(); },
                   "The backend's name (cpu_double, cpu_threads, cpu_float, cuda_float, cuda_exact).")
      .def_prop_ro("last_stats", [](PyMapper &pm) {
        std::lock_guard<std::mutex> lock(pm.mutex);
        return stats_dict(pm.mapper->last_stats());
      }, "Counts and phase times of the last insert or render.")
      .def_prop_ro("renders", [](PyMapper &pm) {
        std::lock_guard<std::mutex> lock(pm.mutex);
        return pm.mapper->renders();
      },
                   "Full renders since construction (each render(), each growth, the first insert).")
      .def("__repr__", [](PyMapper &pm) {
        std::lock_guard<std::mutex> lock(pm.mutex);
        return nb::str("Mapper(backend='{}', {} scans)").format(pm.mapper->backend_name(), pm.mapper->num_scans());
      });
}

// The class Mapper.
void bind_mapper(nb::module_ &m) {
  nb::class_<PyMapper> cls(m, "Mapper", kMapperDoc);
  bind_mapper_constructor(cls);
  bind_mapper_mapping(cls);
  bind_mapper_arrays(cls);
  bind_mapper_state(cls);
}

}  // namespace

NB_MODULE(_core, m) {
  bind_module(m);
  bind_params(m);
  bind_frame(m);
  bind_scans(m);
  bind_log(m);
  bind_map(m);
  bind_compare(m);
  bind_mapper(m);
}
