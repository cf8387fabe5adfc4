// carmen.ini parameter files, read the way CARMEN 0.7.4's param_daemon reads
// them, plus the two other sources a mapping run has: PARAM lines of a log
// (lowest priority) and command-line overrides (highest priority).
//
// Syntax (one definition per line):
//   - '#' anywhere starts a comment, so a value cannot contain '#'.
//   - Trailing, then leading, spaces and tabs are trimmed; blank lines are
//     skipped. A "\r\n" line end counts as "\n".
//   - The first token (split on space or tab, at most 254 characters) is the
//     name; the rest of the line, with its leading blanks skipped, is the
//     value and may contain spaces. A name with nothing after it is kept with
//     an empty value.
//   - The name splits at its first '_' into module and variable
//     ("vasco_p_occ" is module "vasco", variable "p_occ"). A name without a
//     module or a variable is dropped with a warning (see warnings()).
//   - Lookup is case-insensitive (ASCII); a later definition replaces an
//     earlier one, whatever sections they are in.
//   - Sections: [*] applies to all robots; [expert] (any case) applies to all
//     robots and marks its parameters as expert; [name] applies only when
//     `name` is the selected robot (compared case-insensitively). Other
//     sections whose name starts with "expert" are not robots; their lines
//     are ignored with a warning. Lines before the first section are ignored
//     (with a warning when they hold a definition).
//   - A line over 2047 characters (not counting its line end), a section
//     header without ']' or with an empty name, and a NUL byte are errors.
//   - CARMEN 0.7.4 silently drops a last line that has no trailing newline
//     (an end-of-file bug fixed in 0.8); this reader keeps it.
//
// Robot selection, as param_daemon does it: the robots are the [x] sections
// other than [*] and [expert...]. With none, only [*] and [expert] apply and
// a requested robot is an error. With exactly one, it is selected when none
// is requested. With several, a robot must be requested. A requested robot
// without a section is an error.
//
// Typed values are read in the C locale whatever setlocale() says:
//   - double: what strtod accepts (decimal, exponent, hex floats), the whole
//     value; non-finite results ("inf", "nan", overflow such as "1e999") are
//     errors, since no mapping parameter is ever infinite.
//   - int: strtol with base 0 (a "0x" prefix is hex, a leading 0 octal), the
//     whole value; out-of-range values are errors.
//   - onoff: a value starting with "on" is true, one starting with "off"
//     false, case-insensitively (CARMEN's prefix rule, so "ON" and "onward"
//     are true); anything else is an error.
// Every error is a carmen::FileError naming FILE:LINE of the definition (the
// file is "command line" for overrides) and the parameter's name.
#ifndef CARMEN_COMPAT_INI_FILE_H
#define CARMEN_COMPAT_INI_FILE_H

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "carmen_compat/error.h"

namespace carmen {

// One definition: where it came from and what it says.
struct ParamValue {
  std::string name;    // as written where it was defined (module_variable)
  std::string value;   // the rest of the line, trimmed; may be empty
  std::string file;    // the ini or log file, or "command line"
  long line = 0;       // 1-based; 0 when no line applies (command line)
  bool expert = false; // defined in an [expert] section

  // "FILE:LINE", or just "FILE" when line is 0.
  std::string where() const;
  // The part before the first '_' and the part after it.
  std::string module() const;
  std::string variable() const;
};

// Something suspicious that was skipped rather than rejected.
struct ParamWarning {
  std::string file;
  long line = 0;
  std::string message;
  // "FILE:LINE: message" (like FileError::what()).
  std::string str() const;
};

class ParamFile {
 public:
  static constexpr std::size_t kMaxLineLength = 2047;  // longer lines are errors
  // load() refuses a larger file before reading on (a carmen.ini is a few
  // hundred KiB; a device such as /dev/urandom would otherwise never end).
  static constexpr std::size_t kMaxFileBytes = std::size_t(16) << 20;
  static constexpr std::size_t kMaxNameLength = 254;   // longer names are errors
  static constexpr const char *kCommandLine = "command line";

  // No ini: only fallbacks and overrides will be known.
  ParamFile() = default;

  // Reads and parses `path` (see the syntax above). Throws FileError naming
  // the file when it cannot be read, and naming FILE:LINE for syntax errors.
  static ParamFile load(const std::string &path, const std::string &robot = "");
  // The same from text in memory; `name_for_errors` stands in for the path.
  static ParamFile parse(const std::string &text, const std::string &name_for_errors,
                         const std::string &robot = "");

  // A lower-priority source, such as the PARAM lines of a log (name is
  // module_variable): it only provides names that neither the ini nor an
  // override defines. A later fallback for the same name replaces an earlier
  // one. A name that is not module_variable is dropped with a warning.
  void add_fallback(const std::string &name, const std::string &value, const std::string &file,
                    long line);
  // The highest priority, e.g. "--vasco_p_occ 0.9": file "command line",
  // line 0. Throws FileError("command line", ...) when `name` is not
  // module_variable. The value is trimmed of spaces and tabs.
  void set_override(const std::string &name, const std::string &value);

  // The effective definition of `name` (case-insensitive): the override,
  // else the ini, else the fallback.
  std::optional<ParamValue> find(const std::string &name) const;
  bool has(const std::string &name) const;

  // Typed getters. Without a fallback argument a missing name is a FileError
  // naming the ini file. With one, a missing name gives the fallback, but a
  // name that is defined and bad (no value, not a number, ...) is still an
  // error: a value the user wrote is never silently replaced.
  double get_double(const std::string &name) const;
  double get_double(const std::string &name, double fallback) const;
  long get_int(const std::string &name) const;
  long get_int(const std::string &name, long fallback) const;
  bool get_onoff(const std::string &name) const;
  bool get_onoff(const std::string &name, bool fallback) const;
  // The value as written (may be empty).
  std::string get_string(const std::string &name) const;
  std::string get_string(const std::string &name, const std::string &fallback) const;

  // Robot sections of the ini in file order (each once, first spelling), and
  // the selected one as spelled in the file ("" when none is selected).
  std::vector<std::string> robots() const { return robots_; }
  const std::string &selected_robot() const { return selected_robot_; }
  // The path (or name_for_errors) of the ini; "" for a default-constructed one.
  const std::string &source() const { return source_; }

  // Names of module `module` (case-insensitive) defined by the ini or by an
  // override that match no entry of `known`, each with where its effective
  // definition is — for the caller to warn about typos such as
  // vasco_p_ocupied. An entry of `known` may be the full name ("vasco_p_occ")
  // or the variable alone ("p_occ"), in any case. Fallbacks (log PARAM lines)
  // are not reported: logs carry parameters of other programs. Ordered by
  // source (ini in line order, then overrides in the order they were set).
  std::vector<ParamValue> unknown_in_module(const std::string &module,
                                            const std::vector<std::string> &known) const;

  // Every effective definition (one per name), ordered by lower-cased name.
  std::vector<ParamValue> all() const;

  // What was skipped while parsing and adding fallbacks, in order.
  const std::vector<ParamWarning> &warnings() const { return warnings_; }

 private:
  struct Entry {
    ParamValue value;
    std::size_t order = 0;  // insertion order of the name in its source
  };
  using Table = std::map<std::string, Entry>;  // key: lower-cased name

  void put(Table &table, ParamValue value);
  const ParamValue &require(const std::string &name) const;

  std::string source_;
  std::vector<std::string> robots_;
  std::string selected_robot_;
  Table ini_;
  Table fallback_;
  Table override_;
  std::size_t next_order_ = 0;
  std::vector<ParamWarning> warnings_;
};

}  // namespace carmen

#endif  // CARMEN_COMPAT_INI_FILE_H
