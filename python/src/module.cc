// vasco_gpu._core — the Python bindings of the C++ API (nanobind), one file
// per class (bindings.h lists them); this one holds the module and its
// module-level functions.
//
// What crosses the boundary and how:
//   - arrays owned by a C++ object (a Scans' ranges and per-scan columns, a
//     Map's cells) are NumPy views of its memory, keeping the object alive;
//     those other arrays depend on (a Scans' beam_offsets) are read-only;
//   - arrays C++ returns by value (Mapper.read, a finished map) are moved into
//     an owner, never copied;
//   - poses travel as an (n, 3) float64 array, copied once into the session's
//     own vector (24 bytes a scan);
//   - every call that maps, reads a log or writes a file releases the GIL.
// Errors: carmen::Error becomes the class of vasco_gpu._errors its code
// names (errors.cc); std::invalid_argument ValueError, other errors
// RuntimeError.
#include <nanobind/nanobind.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/version.h"
#if defined(VASCO_HAVE_CUDA)
#include "vasco_gpu/cuda_backend.h"
#endif

namespace vasco_py {

namespace {

bool cuda_available(std::string *why) {
#if defined(VASCO_HAVE_CUDA)
  return vasco::cuda_usable(0, why);
#else
  *why = "this build has no CUDA backend (no CUDA toolkit when it was built)";
  return false;
#endif
}

// backends()'s docstring: exactly what it returns in this build, and what
// each name is, from the backend registry.
std::string backends_doc() {
  const std::vector<std::string> compiled = vasco::compiled_backends();
  std::string names;
  bool has_auto = false;
  for (const std::string &n : compiled) {
    names += (names.empty() ? "'" : ", '") + n + "'";
    has_auto = has_auto || n == "auto";
  }
  std::string doc = "Returns the names Mapper(backend=...) takes in this build:\n\n  [" + names + "]\n\n";
  doc += has_auto ? "That is every backend compiled into this build, then 'auto', which is no backend of its own\n"
                    "but picks cuda or cpu_threads by the cost model log2map --backend auto uses (at the\n"
                    "Mapper's first insert, or when it is made with expected_renders=0). "
                  : "That is every backend compiled into this build. ";
  doc += "Aliases are not listed; each follows its\nbackend's line:\n";
  for (const vasco::BackendInfo &b : vasco::backend_registry()) {
    if (!b.compiled) continue;
    doc += std::string("\n  ") + b.name + ": " + b.summary;
    for (const vasco::BackendAlias &a : b.aliases) doc += std::string(" (also '") + a.name + "')";
  }
  return doc;
}

}  // namespace

void bind_module(nb::module_ &m) {
  m.doc() = "vasco_gpu's C++ engine (see the package vasco_gpu for the documentation).";
  m.attr("__version__") = vasco::version();
#if defined(VASCO_HAVE_CUDA)
  m.attr("has_cuda") = true;
#else
  m.attr("has_cuda") = false;
#endif
  static const std::string doc = backends_doc();
  m.def("backends", &vasco::compiled_backends, doc.c_str());
  // vasco_gpu.cuda_available() (_cuda.py) wraps this one: its CudaStatus is
  // true or false, where a pair would always be true.
  m.def(
      "_cuda_available",
      []() {
        std::string why;
        nb::gil_scoped_release r;
        const bool ok = cuda_available(&why);
        return std::make_pair(ok, why);
      },
      nb::sig("def _cuda_available() -> tuple[bool, str]"),
      "``(True, '')`` when the CUDA backend can run here, else ``(False, reason)``, the reason as\n"
      "the engine gives it (vasco_gpu.cuda_available() says it in the user's words).");
}

}  // namespace vasco_py

NB_MODULE(_core, m) {
  vasco_py::bind_errors(m);
  vasco_py::bind_module(m);
  vasco_py::bind_registries(m);
  vasco_py::bind_output_file(m);
  vasco_py::bind_params(m);
  vasco_py::bind_frame(m);
  vasco_py::bind_scans(m);
  vasco_py::bind_log(m);
  vasco_py::bind_inputs(m);
  vasco_py::bind_map(m);
  vasco_py::bind_compare(m);
  vasco_py::bind_mapper(m);
  vasco_py::bind_pose_series(m);
  vasco_py::bind_path_cdr(m);
  vasco_py::bind_align(m);
}
