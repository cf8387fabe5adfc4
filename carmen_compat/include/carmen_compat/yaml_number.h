// Numbers in the YAML files the tools write (map_server's .yaml), in a form
// every YAML reader takes as a float: PyYAML follows YAML 1.1, whose float
// needs a "." (and a signed exponent), so "1e+02" or "10" would come back as
// a string or an int there, while yaml-cpp reads any of them as a double.
#pragma once

#include <string>

namespace carmen {

// The shortest decimal text that reads back as exactly v, always with a
// decimal point: -100 -> "-100.0", 0.05 -> "0.05", 1e-5 -> "1.0e-05",
// 1e20 -> "1.0e+20", -0.0 -> "-0.0"; infinities and NaN as YAML spells them
// (".inf", "-.inf", ".nan").
std::string yaml_float_text(double v);

// The same for the float nearest v: the shortest text that reads back as
// that float (a resolution of 0.05f as "0.05", not 0.05000000074505806).
std::string yaml_float_text_of_float(double v);

}  // namespace carmen
