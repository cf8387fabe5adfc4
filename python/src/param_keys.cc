#include "param_keys.h"

#include <cmath>
#include <sstream>

namespace vasco_py {

namespace {

std::string known_keys() {
  std::string s;
  for (const vasco::ParamSpec &k : vasco::param_table()) s += std::string(s.empty() ? "" : ", ") + k.name;
  return s;
}

std::string python_type_name(nb::handle value) {
  return nb::cast<std::string>(nb::str(value.type().attr("__name__")));
}

}  // namespace

void set_param(vasco::MapperParams &p, const std::string &name, nb::handle value) {
  const vasco::ParamSpec *k = vasco::find_param(name);
  if (k == nullptr)
    throw nb::type_error(("Params: unknown parameter '" + name + "' (known: " + known_keys() + ")").c_str());
  if (PyBool_Check(value.ptr()))
    throw nb::type_error(("Params: " + name + " must be a number, not a bool").c_str());
  double v = 0;
  if (!nb::try_cast<double>(value, v))
    throw nb::type_error(("Params: " + name + " must be a number, not " + python_type_name(value)).c_str());
  if (k->integer() && (!(v == std::floor(v)) || std::fabs(v) > 1e15))
    throw nb::type_error(("Params: " + name + " must be a whole number").c_str());
  k->set(p, v);
}

void check_param(const std::string &name, nb::handle value) {
  vasco::MapperParams scratch;
  set_param(scratch, name, value);
}

nb::dict params_dict(const vasco::MapperParams &p) {
  nb::dict d;
  for (const vasco::ParamSpec &k : vasco::param_table()) {
    if (k.integer()) d[k.name] = p.*(k.whole);
    else d[k.name] = p.*(k.real);
  }
  return d;
}

std::string param_keys_doc() {
  std::ostringstream s;
  s << "Keys:\n";
  for (const vasco::ParamSpec &k : vasco::param_table()) {
    s << "\n  " << k.name << ": " << k.meaning << "; default " << k.default_value
      << (k.minus_one_ok ? " (all)" : "") << "; " << k.rule << ".";
  }
  return s.str();
}

}  // namespace vasco_py
