// file_names.h — the one rule for telling a file's kind by its name.
//
// Extensions are compared without regard to ASCII case: "x.PNG", "x.Map.Gz"
// and "x.png" name the same kind of file (cameras, Windows tools and some
// ROS exports write upper case; refusing them helps nobody). Only the name
// is looked at, never the contents: a gzip file must be named ".gz" to be
// inflated, as CARMEN's carmen_fopen does (its C API keeps its own,
// case-sensitive ".gz" test, so CARMEN programs see CARMEN's behaviour).
#ifndef CARMEN_COMPAT_FILE_NAMES_H
#define CARMEN_COMPAT_FILE_NAMES_H

#include <string>
#include <string_view>

namespace carmen {

// True when `text` ends with `suffix`, byte for byte.
inline bool ends_with(std::string_view text, std::string_view suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

inline char ascii_lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

// True when `path` ends with `extension` (".map.gz"), ignoring ASCII case.
inline bool has_extension(std::string_view path, std::string_view extension) {
  if (path.size() < extension.size()) return false;
  const std::string_view tail = path.substr(path.size() - extension.size());
  for (size_t i = 0; i < tail.size(); ++i)
    if (ascii_lower(tail[i]) != ascii_lower(extension[i])) return false;
  return true;
}

// Whether the C++ map reader and writer treat `path` as gzip data.
inline bool is_gzip_name(std::string_view path) { return has_extension(path, ".gz"); }

}  // namespace carmen

#endif  // CARMEN_COMPAT_FILE_NAMES_H
