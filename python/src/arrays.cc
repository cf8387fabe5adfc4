#include "arrays.h"

namespace vasco_py {

using namespace nb::literals;

nb::object contiguous(nb::handle obj, const char *dtype) {
  // Kept for the life of the process: no destructor after the interpreter ends.
  static nb::handle asc = nb::object(nb::module_::import_("numpy").attr("ascontiguousarray")).release();
  return asc(obj, "dtype"_a = dtype);
}

}  // namespace vasco_py
