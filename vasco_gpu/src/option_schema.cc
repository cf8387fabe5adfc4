#include "vasco_gpu/option_schema.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "vasco_gpu/error.h"

namespace vasco {

const char *option_type_name(OptionType type) {
  switch (type) {
    case OptionType::Flag: return "flag";
    case OptionType::Whole: return "whole";
    case OptionType::Real: return "real";
    case OptionType::Bytes: return "bytes";
    case OptionType::Choice: return "choice";
    case OptionType::Text: return "text";
    case OptionType::WholeList: return "whole_list";
  }
  return "text";
}

std::string OptionSpec::help_with_default() const {
  return default_text.empty() ? help : help + " (default: " + default_text + ")";
}

std::string OptionSpec::flag() const {
  std::string f = "--" + name;
  std::replace(f.begin() + 2, f.end(), '_', '-');
  return f;
}

bool OptionSpec::in_bounds(double v) const {
  if (!(v == v)) return false;  // NaN is never within bounds
  if (lo == 0 && hi == 0) return true;
  const bool above_lo = lo_open ? v > lo : v >= lo;
  const bool below_hi = hi_open ? v < hi : v <= hi;
  return above_lo && below_hi;
}

std::string OptionSpec::rule() const {
  if (type == OptionType::Choice) {
    std::string s = "one of: ";
    for (size_t i = 0; i < choices.size(); ++i) s += (i ? ", " : "") + choices[i];
    return s;
  }
  const bool whole = type == OptionType::Whole || type == OptionType::WholeList;
  if ((whole || type == OptionType::Real) && !(lo == 0 && hi == 0)) {
    char text[160];
    std::snprintf(text, sizeof text, "%s in %c%.15g, %.15g%c",
                  type == OptionType::WholeList ? "whole numbers, each" : whole ? "a whole number" : "a number",
                  lo_open ? '(' : '[', lo, hi, hi_open ? ')' : ']');
    return text;
  }
  switch (type) {
    case OptionType::Flag: return "true or false";
    case OptionType::Whole: return "a whole number";
    case OptionType::Real: return "a finite number";
    case OptionType::Bytes: return "a whole number of MiB (0: no limit)";
    case OptionType::WholeList: return "whole numbers";
    default: return "any text";
  }
}

const OptionSpec *find_option(const OptionTable &table, std::string_view name) {
  for (const OptionSpec &o : table)
    if (o.name == name || o.flag() == name) return &o;
  return nullptr;
}

const OptionSpec &option_row(const OptionTable &table, std::string_view name) {
  const OptionSpec *o = find_option(table, name);
  if (o == nullptr) throw Error(ErrorCode::Internal, "no option '" + std::string(name) + "' in its table");
  return *o;
}

void check_option_choice(const OptionSpec &spec, const std::string &value, const std::string &who) {
  if (std::find(spec.choices.begin(), spec.choices.end(), value) != spec.choices.end()) return;
  throw Error(ErrorCode::Usage, who + " '" + carmen::printable(value) + "': expected " + spec.rule());
}

void check_option_number(const OptionSpec &spec, double value, const std::string &who) {
  const bool whole = spec.type == OptionType::Whole || spec.type == OptionType::WholeList;
  if (spec.in_bounds(value) && (!whole || std::floor(value) == value)) return;
  std::ostringstream v;
  v.precision(17);
  v << value;
  throw Error(ErrorCode::Usage, who + " " + v.str() + ": expected " + spec.rule());
}

}  // namespace vasco
