#include "arrays.h"

#include <unordered_map>

namespace vasco_py {

using namespace nb::literals;

nb::object contiguous(nb::handle obj, const char *dtype) {
  // Kept for the life of the process: no destructor after the interpreter ends.
  static nb::handle asc = nb::object(nb::module_::import_("numpy").attr("ascontiguousarray")).release();
  return asc(obj, "dtype"_a = dtype);
}

namespace {

std::unordered_map<const void *, long> &view_counts() {
  static auto *counts = new std::unordered_map<const void *, long>;  // never destroyed: views may outlive statics
  return *counts;
}

struct ViewHold {
  const void *key;
  PyObject *owner;
};

}  // namespace

nb::capsule counted_owner(const void *key, nb::handle owner) {
  auto *hold = new ViewHold{key, owner.ptr()};
  Py_INCREF(hold->owner);
  ++view_counts()[key];
  return nb::capsule(hold, [](void *p) noexcept {
    ViewHold *h = static_cast<ViewHold *>(p);
    auto it = view_counts().find(h->key);
    if (it != view_counts().end() && --it->second == 0) view_counts().erase(it);
    Py_DECREF(h->owner);
    delete h;
  });
}

long live_views(const void *key) {
  const auto it = view_counts().find(key);
  return it == view_counts().end() ? 0 : it->second;
}

}  // namespace vasco_py
