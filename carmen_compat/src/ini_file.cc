// carmen.ini reader: syntax, sections and robot selection as CARMEN 0.7.4's
// param_daemon has them, typed values as its clients read them (C locale).
#include "carmen_compat/ini_file.h"
#include "carmen_compat/input_file.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <clocale>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <locale.h>
#include <optional>
#include <stdlib.h>
#include <unordered_set>
#include <utility>

namespace carmen {

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t'; }

char ascii_lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

std::string lower(const std::string &s) {
  std::string out(s);
  for (char &c : out) c = ascii_lower(c);
  return out;
}

bool iequals(const std::string &a, const std::string &b) { return lower(a) == lower(b); }

bool istarts_with(const std::string &s, const std::string &prefix) {
  return s.size() >= prefix.size() && lower(s.substr(0, prefix.size())) == lower(prefix);
}

// Trailing, then leading, spaces and tabs.
std::string trim(const std::string &s) {
  std::size_t end = s.size();
  while (end > 0 && is_blank(s[end - 1])) --end;
  std::size_t begin = 0;
  while (begin < end && is_blank(s[begin])) ++begin;
  return s.substr(begin, end - begin);
}

// Position of the '_' that splits module from variable, or npos when the
// name has no non-empty module and variable (CARMEN's "%[^_]_%s").
std::size_t module_split(const std::string &name) {
  const std::size_t us = name.find('_');
  if (us == std::string::npos || us == 0 || us + 1 >= name.size()) return std::string::npos;
  return us;
}

// The first few items, for messages ("a, b, c and 99997 more").
std::string join(const std::vector<std::string> &items) {
  constexpr std::size_t kShown = 10;
  std::string out;
  for (std::size_t i = 0; i < items.size() && i < kShown; ++i) {
    if (!out.empty()) out += ", ";
    out += items[i];
  }
  if (items.size() > kShown) out += " and " + std::to_string(items.size() - kShown) + " more";
  return out;
}

// strtod/strtol in the C locale, whatever the process locale is.
#if defined(__GLIBC__)
locale_t c_locale() {
  static const locale_t loc = newlocale(LC_ALL_MASK, "C", static_cast<locale_t>(0));
  return loc;
}
double c_strtod(const char *s, char **end) {
  const locale_t loc = c_locale();
  return loc != static_cast<locale_t>(0) ? strtod_l(s, end, loc) : std::strtod(s, end);
}
long c_strtol(const char *s, char **end) {
  const locale_t loc = c_locale();
  return loc != static_cast<locale_t>(0) ? strtol_l(s, end, 0, loc) : std::strtol(s, end, 0);
}
#else
// Without strtod_l: spell the decimal point the way the current locale wants
// it. (strtol does not depend on the locale for the strings accepted here.)
double c_strtod(const char *s, char **end) {
  const char *point = std::localeconv()->decimal_point;
  if (point == nullptr || *point == '\0' || std::strcmp(point, ".") == 0)
    return std::strtod(s, end);
  std::string local;
  std::vector<std::size_t> offsets;  // offset in s of each char of local
  const std::size_t point_len = std::strlen(point);
  for (std::size_t i = 0; s[i] != '\0'; ++i) {
    // The locale's own decimal point is not one in the C locale: stop there.
    if (std::strncmp(s + i, point, point_len) == 0) break;
    if (s[i] == '.') {
      for (const char *p = point; *p != '\0'; ++p) {
        local += *p;
        offsets.push_back(i);
      }
    } else {
      local += s[i];
      offsets.push_back(i);
    }
  }
  offsets.push_back(offsets.empty() ? 0 : offsets.back() + 1);
  char *local_end = nullptr;
  const double v = std::strtod(local.c_str(), &local_end);
  const std::size_t used = static_cast<std::size_t>(local_end - local.c_str());
  *end = const_cast<char *>(s) + offsets[used];
  return v;
}
long c_strtol(const char *s, char **end) { return std::strtol(s, end, 0); }
#endif

// "KEY: 'VALUE' ..." at the definition's FILE:LINE.
[[noreturn]] void bad_value(const ParamValue &pv, const std::string &what) {
  throw FileError(pv.file, pv.line, pv.name + ": '" + pv.value + "' " + what);
}

void require_value(const ParamValue &pv) {
  if (pv.value.empty()) throw FileError(pv.file, pv.line, pv.name + " has no value");
}

double to_double(const ParamValue &pv) {
  require_value(pv);
  const char *s = pv.value.c_str();
  char *end = nullptr;
  errno = 0;
  const double v = c_strtod(s, &end);
  if (end == s || *end != '\0') bad_value(pv, "is not a number");
  if (!std::isfinite(v)) bad_value(pv, "is not a finite number");
  return v;
}

long to_int(const ParamValue &pv) {
  require_value(pv);
  const char *s = pv.value.c_str();
  char *end = nullptr;
  errno = 0;
  const long v = c_strtol(s, &end);
  if (end == s || *end != '\0') {
    // "08", "-019": all digits, but strtol stops at the 8 or 9 because a
    // leading 0 means octal.
    const std::size_t i = (s[0] == '+' || s[0] == '-') ? 1 : 0;
    const bool digits_only = s[i] != '\0' && std::strspn(s + i, "0123456789") == std::strlen(s + i);
    bad_value(pv, digits_only && s[i] == '0' ? "is not an integer (a leading 0 means octal)"
                                             : "is not an integer");
  }
  if (errno == ERANGE) bad_value(pv, "is out of range");
  return v;
}

bool to_onoff(const ParamValue &pv) {
  require_value(pv);
  if (istarts_with(pv.value, "on")) return true;
  if (istarts_with(pv.value, "off")) return false;
  bad_value(pv, "is not on or off");
}

enum class SectionKind { kNone, kAll, kExpert, kOtherExpert, kRobot };

SectionKind classify(const std::string &section) {
  if (section == "*") return SectionKind::kAll;
  if (iequals(section, "expert")) return SectionKind::kExpert;
  if (istarts_with(section, "expert")) return SectionKind::kOtherExpert;
  return SectionKind::kRobot;
}

// A line that survived comment stripping and trimming.
struct Line {
  long number;
  bool is_section;
  std::string text;  // the section name (trimmed, without brackets), or the whole line
};

// One raw line made ready for parsing: '\r' and comment removed, trimmed; NUL bytes and
// over-long lines are errors at FILE:NUMBER.
std::string clean_line(std::string raw, const std::string &file, long number) {
  if (!raw.empty() && raw.back() == '\r') raw.pop_back();
  if (raw.find('\0') != std::string::npos)
    throw FileError(file, number, "NUL byte: not a text parameter file");
  if (raw.size() > ParamFile::kMaxLineLength)
    throw FileError(file, number,
                    "line longer than " + std::to_string(ParamFile::kMaxLineLength) +
                        " characters (" + std::to_string(raw.size()) + ")");
  const std::size_t hash = raw.find('#');
  if (hash != std::string::npos) raw.erase(hash);
  return trim(raw);
}

// A "[name]" header (`line` starts with '['): the name, checked; text after the ']' is a warning.
Line section_header(const std::string &line, const std::string &file, long number,
                    std::vector<ParamWarning> &warnings) {
  const std::size_t close = line.find(']');
  if (close == std::string::npos)
    throw FileError(file, number, "section header without ']': " + line);
  std::string section = trim(line.substr(1, close - 1));
  if (section.empty()) throw FileError(file, number, "empty section name");
  if (close + 1 < line.size())
    warnings.push_back({file, number,
                        "text after section header [" + section + "] ignored: " +
                            trim(line.substr(close + 1))});
  return {number, true, section};
}

// Pass 1: split into lines (the last one kept even without a newline, unlike CARMEN 0.7.4, which
// loses it), check lengths, strip comments, trim, and find the section headers.
std::vector<Line> split_lines(const std::string &text, const std::string &file,
                              std::vector<ParamWarning> &warnings) {
  std::vector<Line> lines;
  long number = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    ++number;
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    std::string line = clean_line(text.substr(pos, nl - pos), file, number);
    pos = nl + 1;
    if (line.empty()) continue;
    if (line[0] == '[')
      lines.push_back(section_header(line, file, number, warnings));
    else
      lines.push_back({number, false, line});
  }
  return lines;
}

// Robots: every section other than [*] and [expert...], each once, first spelling (a set of
// lower-cased names: linear in the number of sections).
std::vector<std::string> robot_sections(const std::vector<Line> &lines) {
  std::vector<std::string> robots;
  std::unordered_set<std::string> seen;
  for (const Line &l : lines) {
    if (!l.is_section || classify(l.text) != SectionKind::kRobot) continue;
    if (seen.insert(lower(l.text)).second) robots.push_back(l.text);
  }
  return robots;
}

// The robot section to use as spelled in the file: the named one, else the only one, else ""
// when there are none; a missing or ambiguous robot is an error.
std::string select_robot(const std::vector<std::string> &robots, const std::string &robot,
                         const std::string &file) {
  if (!robot.empty()) {
    const auto it = std::find_if(robots.begin(), robots.end(),
                                 [&](const std::string &r) { return iequals(r, robot); });
    if (it == robots.end())
      throw FileError(file, "no section [" + robot + "] for robot '" + robot + "' (" +
                                (robots.empty() ? std::string("the file has no robot sections")
                                                : "robots: " + join(robots)) +
                                ")");
    return *it;
  }
  if (robots.size() > 1)
    throw FileError(file, "several robots (" + join(robots) + "): the robot to use must be named");
  return robots.empty() ? std::string() : robots.front();
}

// Enters section `l` (pass 2): its kind, and in `applies` whether its definitions are used.
SectionKind enter_section(const Line &l, const std::string &file, const std::string &selected_robot,
                          bool &applies, std::vector<ParamWarning> &warnings) {
  const SectionKind kind = classify(l.text);
  applies = kind == SectionKind::kAll || kind == SectionKind::kExpert ||
            (kind == SectionKind::kRobot && iequals(l.text, selected_robot));
  if (kind == SectionKind::kOtherExpert)
    warnings.push_back({file, l.number,
                        "section [" + l.text +
                            "] is neither [expert] nor a robot; its lines are ignored"});
  return kind;
}

// A "module_variable value" line of an applying section; nullopt (with a warning) when the name
// is not module_variable, an error when it is too long.
std::optional<ParamValue> definition(const Line &l, const std::string &file,
                                     std::vector<ParamWarning> &warnings) {
  std::size_t name_end = 0;
  while (name_end < l.text.size() && !is_blank(l.text[name_end])) ++name_end;
  const std::string name = l.text.substr(0, name_end);
  if (name.size() > ParamFile::kMaxNameLength)
    throw FileError(file, l.number,
                    "parameter name longer than " + std::to_string(ParamFile::kMaxNameLength) +
                        " characters");
  std::size_t value_begin = name_end;
  while (value_begin < l.text.size() && is_blank(l.text[value_begin])) ++value_begin;
  if (module_split(name) == std::string::npos) {
    warnings.push_back({file, l.number, "'" + name + "' is not module_variable; ignored"});
    return std::nullopt;
  }
  ParamValue pv;
  pv.name = name;
  pv.value = l.text.substr(value_begin);
  pv.file = file;
  pv.line = l.number;
  return pv;
}

}  // namespace

// ---------------------------------------------------------------------------
// ParamValue, ParamWarning

std::string ParamValue::where() const {
  return line > 0 ? file + ":" + std::to_string(line) : file;
}

std::string ParamValue::module() const {
  const std::size_t us = name.find('_');
  return us == std::string::npos ? name : name.substr(0, us);
}

std::string ParamValue::variable() const {
  const std::size_t us = name.find('_');
  return us == std::string::npos ? std::string() : name.substr(us + 1);
}

std::string ParamWarning::str() const { return FileError::format(file, line, message); }

// ---------------------------------------------------------------------------
// Reading

ParamFile ParamFile::load(const std::string &path, const std::string &robot) {
  require_regular_file(path, "a carmen.ini");  // a FIFO would block fopen for ever
  std::FILE *fp = std::fopen(path.c_str(), "rb");
  if (fp == nullptr) throw FileError(path, std::string("cannot open: ") + std::strerror(errno));
  std::string text;
  char buffer[1 << 16];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, fp)) > 0) {
    text.append(buffer, n);
    if (text.size() > kMaxFileBytes) {
      std::fclose(fp);
      throw FileError(path, "larger than " + std::to_string(kMaxFileBytes >> 20) +
                                " MiB: not a carmen.ini (a parameter file is a few hundred KiB)");
    }
  }
  const bool failed = std::ferror(fp) != 0;
  const int err = errno;
  std::fclose(fp);
  if (failed) throw FileError(path, std::string("cannot read: ") + std::strerror(err));
  return parse(text, path, robot);
}

ParamFile ParamFile::parse(const std::string &text, const std::string &name_for_errors,
                           const std::string &robot) {
  ParamFile pf;
  pf.source_ = name_for_errors;
  const std::string &file = name_for_errors;
  const std::vector<Line> lines = split_lines(text, file, pf.warnings_);
  pf.robots_ = robot_sections(lines);
  pf.selected_robot_ = select_robot(pf.robots_, robot, file);

  // Pass 2: the definitions of the sections that apply.
  SectionKind kind = SectionKind::kNone;
  bool applies = false;
  for (const Line &l : lines) {
    if (l.is_section) {
      kind = enter_section(l, file, pf.selected_robot_, applies, pf.warnings_);
      continue;
    }
    if (kind == SectionKind::kNone) {
      pf.warnings_.push_back({file, l.number, "definition before the first section ignored"});
      continue;
    }
    if (!applies) continue;
    std::optional<ParamValue> pv = definition(l, file, pf.warnings_);
    if (!pv) continue;
    pv->expert = kind == SectionKind::kExpert;
    pf.put(pf.ini_, std::move(*pv));
  }
  return pf;
}

void ParamFile::put(Table &table, ParamValue value) {
  const std::string key = lower(value.name);
  table[key] = Entry{std::move(value), next_order_++};
}

// ---------------------------------------------------------------------------
// Other sources

void ParamFile::add_fallback(const std::string &name, const std::string &value,
                             const std::string &file, long line) {
  if (module_split(name) == std::string::npos) {
    warnings_.push_back({file, line, "'" + name + "' is not module_variable; ignored"});
    return;
  }
  ParamValue pv;
  pv.name = name;
  pv.value = trim(value);
  pv.file = file;
  pv.line = line;
  put(fallback_, std::move(pv));
}

void ParamFile::set_override(const std::string &name, const std::string &value) {
  if (module_split(name) == std::string::npos)
    throw FileError(kCommandLine, "'" + name + "' is not a module_variable parameter name");
  ParamValue pv;
  pv.name = name;
  pv.value = trim(value);
  pv.file = kCommandLine;
  pv.line = 0;
  put(override_, std::move(pv));
}

// ---------------------------------------------------------------------------
// Lookup

std::optional<ParamValue> ParamFile::find(const std::string &name) const {
  const std::string key = lower(name);
  for (const Table *table : {&override_, &ini_, &fallback_}) {
    const auto it = table->find(key);
    if (it != table->end()) return it->second.value;
  }
  return std::nullopt;
}

bool ParamFile::has(const std::string &name) const { return find(name).has_value(); }

const ParamValue &ParamFile::require(const std::string &name) const {
  const std::string key = lower(name);
  for (const Table *table : {&override_, &ini_, &fallback_}) {
    const auto it = table->find(key);
    if (it != table->end()) return it->second.value;
  }
  throw FileError(source_.empty() ? std::string("parameters") : source_,
                  name + " is not defined" +
                      (selected_robot_.empty() ? std::string()
                                               : " (robot " + selected_robot_ + ")"));
}

double ParamFile::get_double(const std::string &name) const { return to_double(require(name)); }

double ParamFile::get_double(const std::string &name, double fallback) const {
  const auto pv = find(name);
  return pv ? to_double(*pv) : fallback;
}

long ParamFile::get_int(const std::string &name) const { return to_int(require(name)); }

long ParamFile::get_int(const std::string &name, long fallback) const {
  const auto pv = find(name);
  return pv ? to_int(*pv) : fallback;
}

bool ParamFile::get_onoff(const std::string &name) const { return to_onoff(require(name)); }

bool ParamFile::get_onoff(const std::string &name, bool fallback) const {
  const auto pv = find(name);
  return pv ? to_onoff(*pv) : fallback;
}

std::string ParamFile::get_string(const std::string &name) const { return require(name).value; }

std::string ParamFile::get_string(const std::string &name, const std::string &fallback) const {
  const auto pv = find(name);
  return pv ? pv->value : fallback;
}

std::vector<ParamValue> ParamFile::unknown_in_module(const std::string &module,
                                                     const std::vector<std::string> &known) const {
  std::vector<std::string> known_lower;
  for (const std::string &k : known) known_lower.push_back(lower(k));
  const std::string mod = lower(module);

  auto is_unknown = [&](const std::string &key) {
    const std::size_t us = module_split(key);
    if (us == std::string::npos || key.substr(0, us) != mod) return false;
    const std::string variable = key.substr(us + 1);
    return std::none_of(known_lower.begin(), known_lower.end(), [&](const std::string &k) {
      return k == key || k == variable;
    });
  };

  // ini names in line order, then names only the command line defines.
  std::vector<std::pair<std::size_t, std::string>> keys;
  for (const auto &[key, entry] : ini_) keys.emplace_back(entry.order, key);
  std::vector<std::pair<std::size_t, std::string>> override_only;
  for (const auto &[key, entry] : override_)
    if (ini_.count(key) == 0) override_only.emplace_back(entry.order, key);
  std::sort(keys.begin(), keys.end());
  std::sort(override_only.begin(), override_only.end());
  keys.insert(keys.end(), override_only.begin(), override_only.end());

  std::vector<ParamValue> out;
  for (const auto &item : keys)
    if (is_unknown(item.second)) out.push_back(*find(item.second));
  return out;
}

std::vector<ParamValue> ParamFile::all() const {
  std::map<std::string, const ParamValue *> merged;
  for (const Table *table : {&fallback_, &ini_, &override_})
    for (const auto &[key, entry] : *table) merged[key] = &entry.value;
  std::vector<ParamValue> out;
  out.reserve(merged.size());
  for (const auto &item : merged) out.push_back(*item.second);
  return out;
}

}  // namespace carmen
