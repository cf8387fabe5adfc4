// LogStats: the counts a log reader keeps, and their summary for people.
#include "carmen_compat/log_reader.h"

#include <string>

namespace carmen {

namespace {

const char *const kBadLineNames[kNumBadLineClasses] = {
    "truncated", "field count", "not a number", "bad count", "non-finite", "too long"};

}  // namespace

const char *bad_line_name(BadLine kind) {
  const int i = static_cast<int>(kind);
  return i >= 0 && i < kNumBadLineClasses ? kBadLineNames[i] : "?";
}

uint64_t LogStats::laser_messages() const {
  uint64_t s = 0;
  for (int i = 0; i < kNumMessageTypes; ++i)
    if (is_laser_message(static_cast<MessageType>(i))) s += messages[i];
  return s;
}

uint64_t LogStats::total_messages() const {
  uint64_t s = 0;
  for (uint64_t m : messages) s += m;
  return s;
}

uint64_t LogStats::total_bad_lines() const {
  uint64_t s = 0;
  for (uint64_t b : bad_lines) s += b;
  return s;
}

std::string LogStats::summary() const {
  std::string s = std::to_string(lines) + " lines, " + std::to_string(bytes) + " bytes; messages:";
  bool any = false;
  for (int i = 0; i < kNumMessageTypes; ++i) {
    if (messages[i] == 0) continue;
    s += std::string(any ? ", " : " ") + std::to_string(messages[i]) + " " + message_type_name(static_cast<MessageType>(i));
    any = true;
  }
  if (!any) s += " none";
  s += "\nskipped: " + std::to_string(unknown_lines) + " unknown";
  if (!unknown_names.empty()) {
    s += " (";
    for (std::size_t i = 0; i < unknown_names.size(); ++i)
      s += (i ? ", " : "") + unknown_names[i].first + " " + std::to_string(unknown_names[i].second);
    s += ")";
  }
  s += ", " + std::to_string(comment_lines) + " comment, " + std::to_string(blank_lines) + " blank";
  if (nan_ranges || inf_ranges || negative_ranges)
    s += "\nranges: " + std::to_string(nan_ranges) + " NaN, " + std::to_string(inf_ranges) +
         " inf, " + std::to_string(negative_ranges) + " negative";
  if (total_bad_lines()) {
    s += "\nbad lines skipped:";
    bool first = true;
    for (int i = 0; i < kNumBadLineClasses; ++i) {
      if (!bad_lines[i]) continue;
      s += std::string(first ? " " : ", ") + std::to_string(bad_lines[i]) + " " + kBadLineNames[i] +
           " (first at line " + std::to_string(first_bad_line[i]) + ")";
      first = false;
    }
  }
  return s;
}

}  // namespace carmen
