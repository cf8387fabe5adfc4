// The shape every readlog converter (carmen_string_to_*_message) shares: a
// NULL argument or a refused line is reported on stderr and in
// carmen_readlog_last_error(), and leaves a valid empty message (arrays
// freed, numbers 0, host a malloc()ed ""), as readlog.h promises; a line
// taken fills the message and returns the end of its host field. The
// converters of the log reader's messages (readlog_messages.cc) parse with
// its field rules (log_fields.h); the others (readlog_field_messages.cc) read
// their fields with the same parser through `Fields`, scalar messages from a
// table of their fields (`ScalarField`).
#ifndef CARMEN_COMPAT_READLOG_CONVERT_H
#define CARMEN_COMPAT_READLOG_CONVERT_H

#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <string>
#include <variant>
#include <vector>

#include "carmen/readlog.h"
#include "log_fields.h"
#include "readlog_error.h"

namespace carmen::readlog {

inline std::string &last_error() { return readlog_error_text(); }
inline void set_error(const std::string &m) { last_error() = m; }
// Records "out of memory"; returns nullptr, a converter body's failure.
const char *out_of_memory();

// The text of one message: from the first non-blank byte to '\n' or NUL,
// without a trailing '\r'.
struct Text {
  const char *begin;
  const char *end;
};
Text message_text(const char *s);

// If the text starts with `prefix`, skips the first token and parses what
// follows the prefix in it as an id (when want_id). Returns false for a
// malformed id.
bool skip_name(Text &t, const char *prefix, bool want_id, int *id, bool *had_name);

// realloc()s *p to n elements when n changed; frees it for n == 0.
template <typename T>
bool resize_array(T **p, int old_n, int n) {
  if (n == old_n && (n == 0 || *p != nullptr)) return true;
  if (n == 0) {
    std::free(*p);
    *p = nullptr;
    return true;
  }
  void *q = std::realloc(*p, sizeof(T) * static_cast<std::size_t>(n));
  if (q == nullptr) return false;
  *p = static_cast<T *>(q);
  return true;
}

// realloc()s *p to v's size (frees it for 0) and copies v in.
template <typename T>
bool store(T **p, int old_n, const std::vector<T> &v) {
  if (!resize_array(p, old_n, static_cast<int>(v.size()))) return false;
  if (!v.empty()) std::memcpy(*p, v.data(), sizeof(T) * v.size());
  return true;
}

bool copy_host(char **host, const std::string &h);

// ---------------------------------------------------------------------------
// A refused line leaves the message empty (readlog.h): arrays freed, numbers
// 0, host a malloc()ed "" (callers free it, and CARMEN's tools strncpy from
// it without looking at the return value).

void empty_host(char **host, const char *fn);

// Zeroes every member but host, which becomes "".
template <typename T>
void zero_message(T *m, const char *fn) {
  char *host = m->host;
  std::memset(static_cast<void *>(m), 0, sizeof *m);
  m->host = host;
  empty_host(&m->host, fn);
}

// The arrays a message owns, freed before it is emptied.
inline void free_arrays(carmen_laser_laser_message *m) {
  std::free(m->range);
  std::free(m->remission);
}
inline void free_arrays(carmen_robot_laser_message *m) {
  std::free(m->range);
  std::free(m->tooclose);
  std::free(m->remission);
}
inline void free_arrays(carmen_arm_state_message *m) {
  std::free(m->joint_angles);
  std::free(m->joint_currents);
  std::free(m->joint_angular_vels);
}
inline void free_arrays(carmen_base_sonar_message *m) {
  std::free(m->range);
  std::free(m->sonar_offsets);
}
inline void free_arrays(carmen_base_bumper_message *m) {
  std::free(m->state);
  std::free(m->bumper_offsets);
}
inline void free_arrays(carmen_robot_follow_trajectory_message *m) { std::free(m->trajectory); }
inline void free_arrays(void *) {}  // the messages without arrays

// Runs `body` (which returns the end of the host, or nullptr with
// last_error() set); on failure reports it, empties the message and returns
// the end of the line. NULL only for a NULL argument.
template <typename T, typename Body>
char *convert(const char *fn, char *string, T *msg, Body body) {
  last_error().clear();
  if (string == nullptr || msg == nullptr) {
    last_error() = "NULL argument";
    std::fprintf(stderr, "%s: NULL argument\n", fn);
    if (msg != nullptr) {
      free_arrays(msg);
      zero_message(msg, fn);
    }
    return nullptr;
  }
  // The converters return a pointer into the caller's (non-const) string.
  if (const char *after = body(string, msg)) return string + (after - string);
  std::fprintf(stderr, "%s: %s (the message is left empty)\n", fn, last_error().c_str());
  free_arrays(msg);
  zero_message(msg, fn);
  return string + std::strcspn(string, "\n");
}

// ---------------------------------------------------------------------------
// The converters whose messages the log reader does not parse read their
// fields with its field parser (the same bounded, checked number lexing):
// into temporaries first, so a refused line changes nothing before the
// message is emptied.

// One line of a message type: skips the name (any of `names`), then parses.
struct Fields {
  Fields(const char *s, const char *type, std::initializer_list<const char *> names);

  // n doubles; `finite` for offsets and trajectories (poses), else any number.
  bool doubles(std::vector<double> &v, int n, const char *what, bool finite = false);
  // A one-character field (an NMEA orientation letter).
  bool letter(char &c, const char *what);
  // One field by its member's type: a finite double, a small int, a letter.
  bool read(double &v, const char *what) { return p.finite(v, what); }
  bool read(int &v, const char *what) { return p.small_int(v, what); }
  bool read(char &c, const char *what) { return letter(c, what); }
  // The timestamp, host and logger timestamp every message ends with.
  bool trailer();
  bool host_to(char **dst) const { return copy_host(dst, host); }
  // Records why the parse failed; returns nullptr.
  const char *failed();

  Text text;
  const char *name;
  FieldParser p;
  double timestamp = 0;
  std::string host;
  const char *after_host = nullptr;
  std::string bad_letter;
};

// One field of a message without arrays: its name (in messages) and its
// member, whose type says how it is read (Fields::read).
template <typename Msg>
struct ScalarField {
  const char *name;
  std::variant<double Msg::*, int Msg::*, char Msg::*> member;
};

// The converter of a message whose fields are all scalars: `names` (the
// first is the type's, used in messages) then `fields` in order, then the
// trailer. Only the table's members, the timestamp and the host are set,
// and `derive` (when given) fills the members computed from them.
template <typename Msg, std::size_t N>
char *convert_scalars(const char *fn, char *string, Msg *msg, std::initializer_list<const char *> names,
                      const ScalarField<Msg> (&fields)[N], void (*derive)(Msg *) = nullptr) {
  return convert(fn, string, msg, [&](char *str, Msg *out) -> const char * {
    Fields f(str, *names.begin(), names);
    Msg m;
    std::memset(static_cast<void *>(&m), 0, sizeof m);
    for (const ScalarField<Msg> &field : fields)
      if (!std::visit([&](auto member) { return f.read(m.*member, field.name); }, field.member)) return f.failed();
    if (!f.trailer()) return f.failed();
    if (!f.host_to(&out->host)) return out_of_memory();
    for (const ScalarField<Msg> &field : fields)
      std::visit([&](auto member) { out->*member = m.*member; }, field.member);
    if (derive != nullptr) derive(out);
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

}  // namespace carmen::readlog

#endif  // CARMEN_COMPAT_READLOG_CONVERT_H
