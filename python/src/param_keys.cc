// The parameter table of the bindings (see param_keys.h: it moves to
// params.h's table).
#include "param_keys.h"

#include <cmath>
#include <sstream>

namespace vasco_py {

namespace {

using P = vasco::MapperParams;
const ParamKey kParamKeys[] = {
    {"resolution", &P::resolution, nullptr, " m"},
    {"p_prior", &P::p_prior, nullptr, ""},
    {"p_occ", &P::p_occ, nullptr, ""},
    {"p_emp", &P::p_emp, nullptr, ""},
    {"range_sure", &P::range_sure, nullptr, " m"},
    {"range_max", &P::range_max, nullptr, " m"},
    {"wall_size", &P::wall_size, nullptr, " m"},
    {"downsample", nullptr, &P::downsample, ""},
    {"border", nullptr, &P::border, ""},
    {"first_scan", nullptr, &P::first_scan, ""},
    {"num_scans", nullptr, &P::num_scans, ""},
};

std::string known_keys() {
  std::string s;
  for (const ParamKey &k : kParamKeys) s += std::string(s.empty() ? "" : ", ") + k.name;
  return s;
}

std::string python_type_name(nb::handle value) { return nb::cast<std::string>(nb::str(value.type().attr("__name__"))); }

}  // namespace

const ParamKey *find_key(std::string name) {
  if (name.rfind("vasco_", 0) == 0) name = name.substr(6);
  for (const ParamKey &k : kParamKeys)
    if (name == k.name) return &k;
  return nullptr;
}

void set_param(vasco::MapperParams &p, const std::string &name, nb::handle value) {
  const ParamKey *k = find_key(name);
  if (k == nullptr)
    throw nb::type_error(("Params: unknown parameter '" + name + "' (known: " + known_keys() + ")").c_str());
  if (PyBool_Check(value.ptr()))
    throw nb::type_error(("Params: " + name + " must be a number, not a bool").c_str());
  double v = 0;
  if (!nb::try_cast<double>(value, v))
    throw nb::type_error(("Params: " + name + " must be a number, not " + python_type_name(value)).c_str());
  if (k->d != nullptr) {
    p.*(k->d) = v;
    return;
  }
  if (!(v == std::floor(v)) || std::fabs(v) > 1e15)
    throw nb::type_error(("Params: " + name + " must be a whole number").c_str());
  p.*(k->l) = static_cast<long>(v);
}

void check_param(const std::string &name, nb::handle value) {
  vasco::MapperParams scratch;
  set_param(scratch, name, value);
}

nb::dict params_dict(const vasco::MapperParams &p) {
  nb::dict d;
  for (const ParamKey &k : kParamKeys) {
    if (k.d != nullptr) d[k.name] = p.*(k.d);
    else d[k.name] = p.*(k.l);
  }
  return d;
}

std::string param_keys_doc() {
  const vasco::MapperParams defaults;
  std::ostringstream s;
  s << "Keys (default):";
  bool first = true;
  for (const ParamKey &k : kParamKeys) {
    s << (first ? " " : ", ") << k.name << " (";
    if (k.d != nullptr) s << defaults.*(k.d);
    else s << defaults.*(k.l);
    if (k.l == &P::num_scans) s << ": all";
    s << k.unit << ")";
    first = false;
  }
  s << ".";
  return s.str();
}

}  // namespace vasco_py
