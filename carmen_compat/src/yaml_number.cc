// YAML 1.1 float text of a double or a float (see yaml_number.h).
#include "carmen_compat/yaml_number.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace carmen {

namespace {

// Decimal exponents written in fixed notation: from 1e-4 (as printf's %g)
// up to 16 digits before the point, so that UTM and ECEF coordinates in
// metres read as plain numbers.
constexpr int kFixedMinExponent = -4;
constexpr int kFixedMaxExponent = 15;

bool reads_back(const char *text, double v, bool as_float) {
  const double back = std::strtod(text, nullptr);
  return as_float ? static_cast<float>(back) == static_cast<float>(v) : back == v;
}

// The fewest significant digits that read back as v, with the decimal
// exponent of the text that has them (after rounding: 9.96 at one digit is
// 1e+01).
int shortest_significant_digits(double v, bool as_float, int *exponent) {
  char buf[64];
  int digits = 1;
  for (; digits < 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*e", digits - 1, v);
    if (reads_back(buf, v, as_float)) break;
  }
  std::snprintf(buf, sizeof buf, "%.*e", digits - 1, v);
  const char *e = std::strchr(buf, 'e');
  *exponent = std::atoi(e + 1);
  return digits;
}

std::string with_point(std::string text) {
  const size_t e = text.find('e');
  const std::string mantissa = text.substr(0, e);
  if (mantissa.find('.') != std::string::npos) return text;
  return mantissa + ".0" + (e == std::string::npos ? "" : text.substr(e));
}

std::string float_text(double v, bool as_float) {
  if (std::isnan(v)) return ".nan";
  if (std::isinf(v)) return v < 0 ? "-.inf" : ".inf";
  if (v == 0.0) return std::signbit(v) ? "-0.0" : "0.0";
  int exponent = 0;
  const int digits = shortest_significant_digits(v, as_float, &exponent);
  char buf[64];
  if (exponent >= kFixedMinExponent && exponent <= kFixedMaxExponent) {
    const int decimals = digits - 1 - exponent;
    std::snprintf(buf, sizeof buf, "%.*f", decimals > 0 ? decimals : 0, v);
  } else {
    std::snprintf(buf, sizeof buf, "%.*e", digits - 1, v);  // printf signs the exponent: "1e+20"
  }
  return with_point(buf);
}

}  // namespace

std::string yaml_float_text(double v) { return float_text(v, false); }

std::string yaml_float_text_of_float(double v) {
  if (!std::isfinite(v)) return float_text(v, false);
  return float_text(static_cast<double>(static_cast<float>(v)), true);
}

}  // namespace carmen
