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

// backends()'s docstring: what it returns in this build, and what each is,
// from the backend registry.
std::string backends_doc() {
  std::string names;
  for (const std::string &n : vasco::compiled_backends()) names += (names.empty() ? "" : ", ") + n;
  std::string doc = "The backends compiled into this build: " + names + ".\n\nEach is a Mapper(backend=...) name:\n";
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

}  // namespace vasco_py

NB_MODULE(_core, m) {
  vasco_py::bind_errors(m);
  vasco_py::bind_module(m);
  vasco_py::bind_params(m);
  vasco_py::bind_frame(m);
  vasco_py::bind_scans(m);
  vasco_py::bind_log(m);
  vasco_py::bind_inputs(m);
  vasco_py::bind_map(m);
  vasco_py::bind_compare(m);
  vasco_py::bind_mapper(m);
}
