// number_text.h — a double as the pose files' messages write it.
#ifndef VASCO_GPU_PIPELINE_SRC_NUMBER_TEXT_H
#define VASCO_GPU_PIPELINE_SRC_NUMBER_TEXT_H

#include <charconv>
#include <string>

namespace vasco {

// The shortest text that reads back as the same double (std::to_chars does
// not look at the locale, unlike printf, which writes "1083,25" in de_DE).
inline std::string number_text(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace vasco

#endif  // VASCO_GPU_PIPELINE_SRC_NUMBER_TEXT_H
