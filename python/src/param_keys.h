// param_keys.h — Python keywords and attributes of the mapper's parameters,
// read from vasco's parameter table (params.h: param_table()).
#ifndef VASCO_PY_PARAM_KEYS_H
#define VASCO_PY_PARAM_KEYS_H

#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include <string>

#include "vasco_gpu/params.h"

namespace vasco_py {

namespace nb = nanobind;

// Sets the parameter `name` (with or without "vasco_") of `p` from a Python
// number; TypeError for an unknown key, a bool, a non-number or a fraction
// for a whole-number key. Bounds are validate()'s.
void set_param(vasco::MapperParams &p, const std::string &name, nb::handle value);
// Raises as set_param does when `name` = `value` would be refused.
void check_param(const std::string &name, nb::handle value);
// The parameters as a dict, keys without "vasco_", in the table's order.
nb::dict params_dict(const vasco::MapperParams &p);
// One line per key: "name: meaning; default D; RULE".
std::string param_keys_doc();

}  // namespace vasco_py

#endif  // VASCO_PY_PARAM_KEYS_H
