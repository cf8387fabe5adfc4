// arrays.h — how arrays cross the boundary: NumPy views of C++ memory kept
// alive by their owner, vectors moved into arrays that own them, and Python
// objects turned into contiguous arrays of one dtype.
#ifndef VASCO_PY_ARRAYS_H
#define VASCO_PY_ARRAYS_H

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstddef>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "carmen_compat/error.h"

namespace vasco_py {

namespace nb = nanobind;

template <typename T>
using Array1 = nb::ndarray<nb::numpy, T, nb::ndim<1>, nb::c_contig>;
template <typename T>
using Array2 = nb::ndarray<nb::numpy, T, nb::ndim<2>>;

// The NumPy views alive of an object's vectors, counted by the object's
// address: an operation that would move the memory they show (Scans.extend)
// refuses while any is alive, rather than leave them pointing at freed memory.
// counted_owner is the views' owner: it keeps `owner` alive and counts the
// view under `key` until NumPy lets go of it. Both run under the GIL.
nb::capsule counted_owner(const void *key, nb::handle owner);
long live_views(const void *key);

// A 1-D view of n elements at data, kept alive by `owner`, counted under `key`.
template <typename T>
Array1<T> counted_view1(T *data, size_t n, const void *key, nb::handle owner) {
  return Array1<T>(data, {n}, counted_owner(key, owner));
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
nb::object contiguous(nb::handle obj, const char *dtype);

// `obj` as a C-contiguous `ndim`-D array of T (dtype its NumPy name); a
// wrong number of dimensions is bad input naming `what`.
template <typename T>
nb::ndarray<const T, nb::c_contig, nb::device::cpu> as_array(nb::handle obj, const char *dtype, const char *what,
                                                              size_t ndim) {
  nb::object a = contiguous(obj, dtype);
  auto arr = nb::cast<nb::ndarray<const T, nb::c_contig, nb::device::cpu>>(a);
  if (arr.ndim() != ndim)
    throw carmen::Error(carmen::ErrorCode::BadInput, std::string(what) + ": expected a " + std::to_string(ndim) +
                                                         "-D array, got " + std::to_string(arr.ndim()) + "-D");
  return arr;
}

// `obj` as a C-contiguous (n, 3) float64 array of (x, y, theta) rows, one a
// `row` (a scan, a pose); another shape is bad input naming `what`.
inline nb::ndarray<const double, nb::c_contig, nb::device::cpu> xy_theta_rows(nb::handle obj, const char *what,
                                                                             const char *row) {
  auto a = as_array<double>(obj, "float64", what, 2);
  if (a.shape(1) != 3)
    throw carmen::Error(carmen::ErrorCode::BadInput,
                        std::string(what) + ": expected shape (n, 3) (x, y, theta per " + row + ")");
  return a;
}

}  // namespace vasco_py

#endif  // VASCO_PY_ARRAYS_H
