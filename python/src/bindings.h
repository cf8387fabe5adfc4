// bindings.h — the parts of the module vasco_gpu._core, one per class or
// group of functions (each in its own file), and what they share.
#ifndef VASCO_PY_BINDINGS_H
#define VASCO_PY_BINDINGS_H

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <string>

#include "vasco_gpu/align.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco_py {

namespace nb = nanobind;

void bind_errors(nb::module_ &m);   // C++ error codes -> vasco_gpu._errors classes
void bind_module(nb::module_ &m);   // version, backends, _cuda_available
void bind_registries(nb::module_ &m);  // backend_registry, map_formats, output rules
void bind_output_file(nb::module_ &m);  // _OutputFile (atomic_file.h)
void bind_params(nb::module_ &m);   // Params
void bind_frame(nb::module_ &m);    // Frame
void bind_scans(nb::module_ &m);    // Scans
void bind_log(nb::module_ &m);      // Log, load_log
void bind_inputs(nb::module_ &m);   // _log_from_scans, _run_tool (bag2map)
void bind_map(nb::module_ &m);      // Map, _read_map, write_map
void bind_compare(nb::module_ &m);  // Comparison, compare
void bind_mapper(nb::module_ &m);   // Mapper
void bind_pose_series(nb::module_ &m);  // _repose (pose_series.h)
void bind_path_cdr(nb::module_ &m);     // _path_from_cdr (the node's Path bytes)
void bind_align(nb::module_ &m);       // _align_maps (align.h)

// A caller's writable buffer of bytes (array('b'), bytearray), exported while it lives, so
// that C++ may write into it without the GIL and it cannot be resized meanwhile. TypeError
// naming `what` for anything else (read-only, or of wider items). Made with the GIL held.
class WritableBytes {
 public:
  WritableBytes(nb::handle obj, const char *what) {
    if (PyObject_GetBuffer(obj.ptr(), &view_, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) != 0) {
      PyErr_Clear();
      throw nb::type_error(message(what).c_str());
    }
    if (view_.itemsize != 1) {
      PyBuffer_Release(&view_);
      throw nb::type_error(message(what).c_str());
    }
  }
  ~WritableBytes() { PyBuffer_Release(&view_); }
  WritableBytes(const WritableBytes &) = delete;
  WritableBytes &operator=(const WritableBytes &) = delete;
  int8_t *data() const { return static_cast<int8_t *>(view_.buf); }
  size_t size() const { return static_cast<size_t>(view_.len); }

 private:
  static std::string message(const char *what) {
    return std::string(what) + ": expected a writable buffer of bytes (array('b'), bytearray)";
  }
  Py_buffer view_{};
};

// The batch's poses as a new (n, 3) float64 array of (x, y, theta).
nb::ndarray<nb::numpy, double> poses_of(const vasco::ScanBatch &b);

// What the alignment's callers share (align.cc): _align_maps, load_log's and
// load_bag's ("auto", hint) sessions, Mapper.insert(transform=...).
// A hint (x, y, theta) or (x, y, theta, radius_m, radius_rad), its radii
// AlignHint's where not given; UsageError naming `what` for anything else.
vasco::AlignHint align_hint_of(nb::handle h, const std::string &what);
// The result as a dict: verdict, reason, transform, score, second_*, overlap, counts.
nb::dict align_result_dict(const vasco::AlignResult &r);

}  // namespace vasco_py

#endif  // VASCO_PY_BINDINGS_H
