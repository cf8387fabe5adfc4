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

// A 1-D view of `v` kept alive by `owner`; writable.
template <typename T>
Array1<T> view1(std::vector<T> &v, nb::handle owner) {
  return Array1<T>(v.data(), {v.size()}, owner);
}

// A read-only 1-D view (numpy writeable=False, and it cannot be set back):
// for arrays whose values the object's other arrays depend on.
template <typename T>
Array1<const T> view1_ro(const std::vector<T> &v, nb::handle owner) {
  return Array1<const T>(v.data(), {v.size()}, owner);
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

}  // namespace vasco_py

#endif  // VASCO_PY_ARRAYS_H
