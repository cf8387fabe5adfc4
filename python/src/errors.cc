// The exception translator: carmen::Error (vasco::Error) becomes the class of
// vasco_gpu._errors its code names, carmen::FileError a FileError with the
// file and line. The class is chosen by code(), never by the message.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include "bindings.h"
#include "carmen_compat/error.h"

namespace vasco_py {

namespace {

// Raises `cls(args...)` as the current Python exception.
template <typename... Args>
void raise_as(nb::handle cls, Args &&...args) {
  nb::object exc = cls(std::forward<Args>(args)...);
  PyErr_SetObject(cls.ptr(), exc.ptr());
}

// The translator; `payload` is the module vasco_gpu._errors.
void translate(const std::exception_ptr &p, void *payload) {
  nb::handle errors(static_cast<PyObject *>(payload));
  try {
    std::rethrow_exception(p);
  } catch (const carmen::FileError &e) {
    nb::object line = e.line() > 0 ? nb::object(nb::int_(e.line())) : nb::none();
    raise_as(errors.attr("FileError"), carmen::printable(e.what()), e.file(), line, e.message(),
             carmen::error_code_name(e.code()));
  } catch (const carmen::Error &e) {
    raise_as(errors.attr("BY_CODE")[carmen::error_code_name(e.code())], carmen::printable(e.what()));
  }
  // Anything else leaves as it came, for nanobind's own translator
  // (std::invalid_argument -> ValueError, std::bad_alloc -> MemoryError, ...).
}

}  // namespace

void bind_errors(nb::module_ &) {
  // One translator per initialisation of the module (a re-import gets its
  // own, never a stale one); the module reference is kept for the life of
  // the process (no destructor after the interpreter ends).
  PyObject *errors = nb::module_::import_("vasco_gpu._errors").release().ptr();
  nb::register_exception_translator(&translate, errors);
}

}  // namespace vasco_py
