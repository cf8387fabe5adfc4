// The readlog converters' shared pieces (readlog_convert.h).
#include "readlog_convert.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

namespace carmen::readlog {
namespace {

bool is_sep(char c) { return c == ' ' || c == '\t'; }

// A token as a message quotes it: control bytes as '?', at most 40 bytes.
std::string printable(std::string_view t) {
  std::string s;
  for (std::size_t i = 0; i < t.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(t[i]);
    s += c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c);
  }
  if (t.size() > 40) s += "...";
  return s;
}

}  // namespace

const char *out_of_memory() {
  set_error("out of memory");
  return nullptr;
}

Text message_text(const char *s) {
  while (is_sep(*s)) ++s;
  const char *e = s + std::strcspn(s, "\n");
  if (e > s && e[-1] == '\r') --e;
  return {s, e};
}

bool skip_name(Text &t, const char *prefix, bool want_id, int *id, bool *had_name) {
  const std::size_t n = std::strlen(prefix);
  *had_name = false;
  if (static_cast<std::size_t>(t.end - t.begin) < n || std::strncmp(t.begin, prefix, n) != 0)
    return true;
  const char *q = t.begin + n;
  const char *e = q;
  while (e < t.end && !is_sep(*e)) ++e;
  if (want_id) {
    int v = 0;
    if (e == q) return false;
    for (const char *p = q; p < e; ++p) {
      if (*p < '0' || *p > '9' || v > 100000) return false;
      v = v * 10 + (*p - '0');
    }
    *id = v;
  } else if (e != q) {
    return true;  // a longer word that merely starts with the prefix: not the name
  }
  t.begin = e;
  *had_name = true;
  return true;
}

bool copy_host(char **host, const std::string &h) {
  void *q = std::realloc(*host, h.size() + 1);
  if (q == nullptr) return false;
  *host = static_cast<char *>(q);
  std::memcpy(*host, h.c_str(), h.size() + 1);
  return true;
}

void empty_host(char **host, const char *fn) {
  std::free(*host);
  *host = static_cast<char *>(std::calloc(1, 1));
  if (*host == nullptr) {  // as CARMEN's converters on a failed allocation
    std::fprintf(stderr, "Out of memory in %s.\n", fn);
    std::exit(-1);
  }
}

Fields::Fields(const char *s, const char *type, std::initializer_list<const char *> names)
    : text(message_text(s)), name(type), p(text.begin, text.end) {
  int id = 0;
  bool had = false;
  for (const char *n : names) {
    skip_name(text, n, false, &id, &had);
    if (had) break;
  }
  p = FieldParser(text.begin, text.end);
}

bool Fields::doubles(std::vector<double> &v, int n, const char *what, bool finite) {
  v.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    if (!(finite ? p.finite(v[i], what, i) : p.number(v[i], what, i))) return false;
  return true;
}

bool Fields::letter(char &c, const char *what) {
  const char *b, *e;
  if (!p.token(b, e, what)) return false;
  if (e - b != 1) {
    bad_letter = std::string(name) + " " + what + " (field " + std::to_string(p.field()) + "): '" +
                 printable(std::string_view(b, static_cast<std::size_t>(e - b))) + "' is not one character";
    return false;
  }
  c = *b;
  return true;
}

bool Fields::trailer() {
  const char *hb, *he;
  double logger_timestamp;
  if (!p.finite(timestamp, "ipc_timestamp") || !p.token(hb, he, "host")) return false;
  host.assign(hb, static_cast<std::size_t>(he - hb));
  after_host = he;
  return p.finite(logger_timestamp, "logger_timestamp") && p.at_end();
}

const char *Fields::failed() {
  using FP = FieldParser;
  if (!bad_letter.empty()) {
    set_error(bad_letter);
    return nullptr;
  }
  std::string what = p.what ? p.what : "?";
  if (p.index >= 0) what += "[" + std::to_string(p.index) + "]";
  const std::string where = what + " (field " + std::to_string(p.failed_field) + ")";
  const std::string tok = "'" + printable(p.failed_token) + "'";
  std::string m = name;
  switch (p.failure) {
    case FP::MISSING: m += " truncated: the line ends before " + where; break;
    case FP::NOT_NUMBER: m += " " + where + ": " + tok + " is not a number"; break;
    case FP::NOT_FINITE: m += " " + where + ": " + tok + " is not finite"; break;
    case FP::NEGATIVE_COUNT: m += " " + what + " " + std::to_string(p.count_value_) + " is negative"; break;
    case FP::HUGE_COUNT:
      m += " " + what + " " + std::to_string(p.count_value_) + " exceeds the limit of " + std::to_string(kMaxCount);
      break;
    case FP::EXTRA: m += ": extra field " + tok + " after the logger timestamp"; break;
    case FP::NONE: m += ": bad line"; break;
  }
  set_error(m);
  return nullptr;
}

}  // namespace carmen::readlog
