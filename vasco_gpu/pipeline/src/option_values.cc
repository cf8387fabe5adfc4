#include "vasco_gpu/pipeline/option_values.h"

namespace vasco::pipeline {

std::string option_name(const OptionSpec &row, OptionNaming naming) {
  return naming == OptionNaming::Flag ? row.flag() : row.name;
}

std::string option_names_text(const std::vector<const OptionSpec *> &rows, OptionNaming naming) {
  std::string text;
  for (size_t i = 0; i < rows.size(); ++i) {
    if (i > 0) text += i + 1 == rows.size() ? " and " : ", ";
    text += option_name(*rows[i], naming);
  }
  return text;
}

}  // namespace vasco::pipeline
