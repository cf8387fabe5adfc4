// param_keys.h — the mapper's parameters by ini key, for Python's keywords.
// Library logic carried by the bindings until vasco's parameter table
// (params.h) exists; then these read it and this file goes.
#ifndef VASCO_PY_PARAM_KEYS_H
#define VASCO_PY_PARAM_KEYS_H

#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include <string>

#include "vasco_gpu/params.h"

namespace vasco_py {

namespace nb = nanobind;

struct ParamKey {
  const char *name;  // without vasco_
  double vasco::MapperParams::*d;
  long vasco::MapperParams::*l;
  const char *unit;  // " m" or ""
};

// The key `name` names (with or without "vasco_"), or nullptr.
const ParamKey *find_key(std::string name);
// Sets the key `name` of `p` from a Python number; TypeError for an unknown
// key, a bool, a non-number or a fraction for a whole-number key.
void set_param(vasco::MapperParams &p, const std::string &name, nb::handle value);
// Raises as set_param does when `name` = `value` would be refused.
void check_param(const std::string &name, nb::handle value);
// The parameters as a dict, keys without "vasco_", in the table's order.
nb::dict params_dict(const vasco::MapperParams &p);
// "Keys (default): resolution (0.025 m), ...": the defaults as the table has them.
std::string param_keys_doc();

}  // namespace vasco_py

#endif  // VASCO_PY_PARAM_KEYS_H
