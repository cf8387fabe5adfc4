// CARMEN's readlog converters (carmen_string_to_*_message) on top of the C++
// log parser (log_reader.cc) and its field rules (log_fields.h), so that both
// share one implementation of every message format. A bad line leaves an
// empty, usable message (readlog.h).
#include "carmen/readlog.h"

#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "carmen_compat/log_reader.h"
#include "log_fields.h"
#include "readlog_error.h"

namespace {

std::string &last_error() { return carmen::readlog_error_text(); }
thread_local carmen::LogMessage g_scratch;

void set_error(const std::string &m) { last_error() = m; }

bool is_sep(char c) { return c == ' ' || c == '\t'; }

// The text of one message: from the first non-blank byte to '\n' or NUL,
// without a trailing '\r'.
struct Text {
  const char *begin;
  const char *end;
};

Text message_text(const char *s) {
  while (is_sep(*s)) ++s;
  const char *e = s + std::strcspn(s, "\n");
  if (e > s && e[-1] == '\r') --e;
  return {s, e};
}

// If the text starts with `prefix`, skips the first token and parses what
// follows the prefix in it as an id (when want_id). Returns false for a
// malformed id.
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

bool copy_host(char **host, const std::string &h) {
  void *q = std::realloc(*host, h.size() + 1);
  if (q == nullptr) return false;
  *host = static_cast<char *>(q);
  std::memcpy(*host, h.c_str(), h.size() + 1);
  return true;
}

// The converters return a pointer into the caller's (non-const) string.
char *result(char *string, const char *after_host) { return string + (after_host - string); }

// ---------------------------------------------------------------------------
// A refused line leaves the message empty (readlog.h): arrays freed, numbers
// 0, host a malloc()ed "" (callers free it, and CARMEN's tools strncpy from
// it without looking at the return value).

void empty_host(char **host, const char *fn) {
  std::free(*host);
  *host = static_cast<char *>(std::calloc(1, 1));
  if (*host == nullptr) {  // as CARMEN's converters on a failed allocation
    std::fprintf(stderr, "Out of memory in %s.\n", fn);
    std::exit(-1);
  }
}

// Zeroes every member but host, which becomes "".
template <typename T>
void zero_message(T *m, const char *fn) {
  char *host = m->host;
  std::memset(static_cast<void *>(m), 0, sizeof *m);
  m->host = host;
  empty_host(&m->host, fn);
}

void free_arrays(carmen_laser_laser_message *m) {
  std::free(m->range);
  std::free(m->remission);
}
void free_arrays(carmen_robot_laser_message *m) {
  std::free(m->range);
  std::free(m->tooclose);
  std::free(m->remission);
}
void free_arrays(carmen_arm_state_message *m) {
  std::free(m->joint_angles);
  std::free(m->joint_currents);
  std::free(m->joint_angular_vels);
}
void free_arrays(carmen_base_sonar_message *m) {
  std::free(m->range);
  std::free(m->sonar_offsets);
}
void free_arrays(carmen_base_bumper_message *m) {
  std::free(m->state);
  std::free(m->bumper_offsets);
}
void free_arrays(carmen_robot_follow_trajectory_message *m) { std::free(m->trajectory); }
void free_arrays(void *) {}  // the messages without arrays

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
  if (const char *after = body(string, msg)) return result(string, after);
  std::fprintf(stderr, "%s: %s (the message is left empty)\n", fn, last_error().c_str());
  free_arrays(msg);
  zero_message(msg, fn);
  return string + std::strcspn(string, "\n");
}

template <typename Config>
void copy_config(Config &dst, const carmen::LaserConfig &c) {
  dst.laser_type = static_cast<carmen_laser_laser_type_t>(c.laser_type);
  dst.start_angle = c.start_angle;
  dst.fov = c.fov;
  dst.angular_resolution = c.angular_resolution;
  dst.maximum_range = c.maximum_range;
  dst.accuracy = c.accuracy;
  dst.remission_mode = static_cast<carmen_laser_remission_type_t>(c.remission_mode);
}

bool fill_laser_laser(carmen_laser_laser_message *out, const carmen::LaserMessage &m, int id) {
  const int n = static_cast<int>(m.range.size());
  const int r = static_cast<int>(m.remission.size());
  if (!resize_array(&out->range, out->num_readings, n) ||
      !resize_array(&out->remission, out->num_remissions, r) || !copy_host(&out->host, m.host)) {
    set_error("out of memory");
    return false;
  }
  out->id = id;
  copy_config(out->config, m.config);
  out->num_readings = n;
  if (n) std::memcpy(out->range, m.range.data(), sizeof(float) * n);
  out->num_remissions = r;
  if (r) std::memcpy(out->remission, m.remission.data(), sizeof(float) * r);
  out->timestamp = m.timestamp;
  return true;
}

// `orig`: the old FLASER/RLASER converter, which leaves id, tv, rv, the
// safety distances and turn_axis as they were, as CARMEN's does.
bool fill_robot_laser(carmen_robot_laser_message *out, const carmen::LaserMessage &m, int id, bool orig = false) {
  const int n = static_cast<int>(m.range.size());
  const int r = static_cast<int>(m.remission.size());
  if (!resize_array(&out->range, out->num_readings, n) ||
      !resize_array(&out->tooclose, out->num_readings, n) ||
      !resize_array(&out->remission, out->num_remissions, r) || !copy_host(&out->host, m.host)) {
    set_error("out of memory");
    return false;
  }
  if (!orig) out->id = id;
  copy_config(out->config, m.config);
  out->num_readings = n;
  if (n) {
    std::memcpy(out->range, m.range.data(), sizeof(float) * n);
    std::memset(out->tooclose, 0, static_cast<std::size_t>(n));
  }
  out->num_remissions = r;
  if (r) std::memcpy(out->remission, m.remission.data(), sizeof(float) * r);
  out->laser_pose = {m.laser_pose.x, m.laser_pose.y, m.laser_pose.theta};
  out->robot_pose = {m.robot_pose.x, m.robot_pose.y, m.robot_pose.theta};
  if (!orig) {
    out->tv = m.tv;
    out->rv = m.rv;
    out->forward_safety_dist = m.forward_safety_dist;
    out->side_safety_dist = m.side_safety_dist;
    out->turn_axis = m.turn_axis;
  }
  out->timestamp = m.timestamp;
  return true;
}

// Parses fields of `type` from t; on failure records the error.
bool parse(carmen::MessageType type, const Text &t, const char **after_host) {
  carmen::LineError err;
  if (carmen::parse_message_fields(type, t.begin, t.end, g_scratch, &err, after_host)) return true;
  set_error(err.message);
  return false;
}

// ---------------------------------------------------------------------------
// The other converters' fields, parsed with the log reader's field parser
// (the same bounded, checked number lexing): into temporaries first, so a
// refused line changes nothing before the message is emptied.

const char *out_of_memory() {
  set_error("out of memory");
  return nullptr;
}

// DDMM.MMMM to degrees, as CARMEN's converters do (the sign is the value's;
// the orientation letter is not applied).
double degmin_to_degrees(double dm) {
  const double degrees = std::floor(dm / 100.0);
  return degrees + (dm - degrees * 100.0) / 60.0;
}

// realloc()s *p to v's size (frees it for 0) and copies v in.
template <typename T>
bool store(T **p, int old_n, const std::vector<T> &v) {
  if (!resize_array(p, old_n, static_cast<int>(v.size()))) return false;
  if (!v.empty()) std::memcpy(*p, v.data(), sizeof(T) * v.size());
  return true;
}

std::string printable(std::string_view t) {
  std::string s;
  for (std::size_t i = 0; i < t.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(t[i]);
    s += c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c);
  }
  if (t.size() > 40) s += "...";
  return s;
}

// One line of a message type: skips the name (any of `names`), then parses.
struct Fields {
  Fields(const char *s, const char *type, std::initializer_list<const char *> names)
      : text(message_text(s)), name(type), p(text.begin, text.end) {
    int id = 0;
    bool had = false;
    for (const char *n : names) {
      skip_name(text, n, false, &id, &had);
      if (had) break;
    }
    p = carmen::FieldParser(text.begin, text.end);
  }

  // n doubles; `finite` for offsets and trajectories (poses), else any number.
  bool doubles(std::vector<double> &v, int n, const char *what, bool finite = false) {
    v.resize(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
      if (!(finite ? p.finite(v[i], what, i) : p.number(v[i], what, i))) return false;
    return true;
  }

  // A one-character field (an NMEA orientation letter).
  bool letter(char &c, const char *what) {
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

  bool trailer() {
    const char *hb, *he;
    double logger_timestamp;
    if (!p.finite(timestamp, "ipc_timestamp") || !p.token(hb, he, "host")) return false;
    host.assign(hb, static_cast<std::size_t>(he - hb));
    after_host = he;
    return p.finite(logger_timestamp, "logger_timestamp") && p.at_end();
  }

  bool host_to(char **dst) const { return copy_host(dst, host); }

  // Records why the parse failed; returns nullptr.
  const char *failed() {
    using FP = carmen::FieldParser;
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
        m += " " + what + " " + std::to_string(p.count_value_) + " exceeds the limit of " +
             std::to_string(carmen::kMaxCount);
        break;
      case FP::EXTRA: m += ": extra field " + tok + " after the logger timestamp"; break;
      case FP::NONE: m += ": bad line"; break;
    }
    set_error(m);
    return nullptr;
  }

  Text text;
  const char *name;
  carmen::FieldParser p;
  double timestamp = 0;
  std::string host;
  const char *after_host = nullptr;
  std::string bad_letter;
};

}  // namespace

extern "C" {

double carmen_laser_guess_fov(int num_beams) { return carmen::guess_laser_fov(num_beams); }

double carmen_laser_guess_angle_increment(int num_beams) {
  return carmen::guess_laser_angle_increment(num_beams);
}

char *carmen_string_to_laser_laser_message(char *string, carmen_laser_laser_message *laser) {
  return convert(__func__, string, laser, [](char *str, carmen_laser_laser_message *out) -> const char * {
    Text t = message_text(str);
    int id = -1;
    bool had;
    if (!skip_name(t, "RAWLASER", true, &id, &had)) {
      set_error("bad laser number after RAWLASER");
      return nullptr;
    }
    const char *after = nullptr;
    if (!parse(carmen::MessageType::RAWLASER1, t, &after)) return nullptr;
    if (!fill_laser_laser(out, g_scratch.laser, had ? id : -1)) return nullptr;
    return after;
  });
}

char *carmen_string_to_laser_laser_message_orig(char *string, carmen_laser_laser_message *laser) {
  return convert(__func__, string, laser, [](char *str, carmen_laser_laser_message *out) -> const char * {
    Text t = message_text(str);
    int id = -1;
    bool had = false;
    const char *after = nullptr;
    skip_name(t, "FLASER", false, &id, &had);
    if (!had) skip_name(t, "RLASER", false, &id, &had);
    const bool flaser = had;
    if (flaser) {
      if (!parse(carmen::MessageType::FLASER, t, &after)) return nullptr;
    } else {
      if (!skip_name(t, "LASER", true, &id, &had)) {
        set_error("bad laser number after LASER");
        return nullptr;
      }
      carmen::LineError err;
      if (!carmen::parse_old_laser_fields(t.begin, t.end, g_scratch.laser, &err, &after)) {
        set_error(err.message);
        return nullptr;
      }
    }
    if (!fill_laser_laser(out, g_scratch.laser, had && !flaser ? id : -1)) return nullptr;
    return after;
  });
}

char *carmen_string_to_robot_laser_message(char *string, carmen_robot_laser_message *laser) {
  return convert(__func__, string, laser, [](char *str, carmen_robot_laser_message *out) -> const char * {
    Text t = message_text(str);
    int id = -1;
    bool had;
    if (!skip_name(t, "ROBOTLASER", true, &id, &had)) {
      set_error("bad laser number after ROBOTLASER");
      return nullptr;
    }
    const char *after = nullptr;
    if (!parse(carmen::MessageType::ROBOTLASER1, t, &after)) return nullptr;
    if (!fill_robot_laser(out, g_scratch.laser, had ? id : -1)) return nullptr;
    return after;
  });
}

char *carmen_string_to_robot_laser_message_orig(char *string, carmen_robot_laser_message *laser) {
  return convert(__func__, string, laser, [](char *str, carmen_robot_laser_message *out) -> const char * {
    Text t = message_text(str);
    int id = -1;
    bool had = false;
    skip_name(t, "FLASER", false, &id, &had);
    if (!had) skip_name(t, "RLASER", false, &id, &had);
    const char *after = nullptr;
    if (!parse(carmen::MessageType::FLASER, t, &after)) return nullptr;
    if (!fill_robot_laser(out, g_scratch.laser, -1, true)) return nullptr;
    return after;
  });
}

char *carmen_string_to_base_odometry_message(char *string, carmen_base_odometry_message *odometry) {
  return convert(__func__, string, odometry, [](char *str, carmen_base_odometry_message *out) -> const char * {
    Text t = message_text(str);
    int id = -1;
    bool had;
    skip_name(t, "ODOM", false, &id, &had);
    const char *after = nullptr;
    if (!parse(carmen::MessageType::ODOM, t, &after)) return nullptr;
    const carmen::OdometryMessage &o = g_scratch.odom;
    if (!copy_host(&out->host, o.host)) {
      set_error("out of memory");
      return nullptr;
    }
    out->x = o.x;
    out->y = o.y;
    out->theta = o.theta;
    out->tv = o.tv;
    out->rv = o.rv;
    out->acceleration = o.acceleration;
    out->timestamp = o.timestamp;
    return after;
  });
}

char *carmen_string_to_simulator_truepos_message(char *string,
                                                 carmen_simulator_truepos_message *truepos) {
  return convert(__func__, string, truepos, [](char *str, carmen_simulator_truepos_message *out) -> const char * {
    Text t = message_text(str);
    int id = -1;
    bool had;
    skip_name(t, "TRUEPOS", false, &id, &had);
    const char *after = nullptr;
    if (!parse(carmen::MessageType::TRUEPOS, t, &after)) return nullptr;
    const carmen::TrueposMessage &m = g_scratch.truepos;
    if (!copy_host(&out->host, m.host)) {
      set_error("out of memory");
      return nullptr;
    }
    out->truepose = {m.truepose.x, m.truepose.y, m.truepose.theta};
    out->odometrypose = {m.odometrypose.x, m.odometrypose.y, m.odometrypose.theta};
    out->timestamp = m.timestamp;
    return after;
  });
}

char *carmen_string_to_arm_state_message(char *string, carmen_arm_state_message *arm) {
  return convert(__func__, string, arm, [](char *str, carmen_arm_state_message *out) -> const char * {
    Fields f(str, "ARM", {"ARM"});
    int flags = 0, gripper = 0, nj = 0, nc = 0, nv = 0;
    std::vector<double> joints, currents, vels;
    if (!f.p.small_int(flags, "flags") || !f.p.count(nj, "num_joints") || !f.doubles(joints, nj, "joint_angles") ||
        !f.p.count(nc, "num_currents") || !f.doubles(currents, nc, "joint_currents") ||
        !f.p.count(nv, "num_vels") || !f.doubles(vels, nv, "joint_angular_vels") ||
        !f.p.small_int(gripper, "gripper_closed") || !f.trailer())
      return f.failed();
    if (!store(&out->joint_angles, out->num_joints, joints) ||
        !store(&out->joint_currents, out->num_currents, currents) ||
        !store(&out->joint_angular_vels, out->num_vels, vels) || !f.host_to(&out->host))
      return out_of_memory();
    out->flags = flags;
    out->num_joints = nj;
    out->num_currents = nc;
    out->num_vels = nv;
    out->gripper_closed = gripper;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_base_sonar_message(char *string, carmen_base_sonar_message *sonar) {
  return convert(__func__, string, sonar, [](char *str, carmen_base_sonar_message *out) -> const char * {
    Fields f(str, "SONAR", {"SONAR"});
    double cone = 0;
    int n = 0;
    std::vector<double> ranges, offsets;
    if (!f.p.finite(cone, "cone_angle") || !f.p.count(n, "num_sonars") || !f.doubles(ranges, n, "range") ||
        !f.doubles(offsets, 3 * n, "sonar_offsets", true) || !f.trailer())
      return f.failed();
    std::vector<carmen_point_t> points(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) points[i] = {offsets[3 * i], offsets[3 * i + 1], offsets[3 * i + 2]};
    if (!store(&out->range, out->num_sonars, ranges) || !store(&out->sonar_offsets, out->num_sonars, points) ||
        !f.host_to(&out->host))
      return out_of_memory();
    out->num_sonars = n;
    out->cone_angle = cone;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_base_bumper_message(char *string, carmen_base_bumper_message *bumper) {
  return convert(__func__, string, bumper, [](char *str, carmen_base_bumper_message *out) -> const char * {
    Fields f(str, "BUMPER", {"BUMPER"});
    int n = 0;
    std::vector<unsigned char> states;
    std::vector<double> offsets;
    if (!f.p.count(n, "num_bumpers")) return f.failed();
    for (int i = 0; i < n; ++i) {
      int v = 0;
      if (!f.p.small_int(v, "state")) return f.failed();
      if (v < 0 || v > 255) {
        set_error(std::string("BUMPER state ") + std::to_string(v) + " (field " + std::to_string(f.p.field()) +
                  ") is not 0..255");
        return nullptr;
      }
      states.push_back(static_cast<unsigned char>(v));
    }
    if (!f.doubles(offsets, 2 * n, "bumper_offsets", true) || !f.trailer()) return f.failed();
    std::vector<carmen_position_t> points(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) points[i] = {offsets[2 * i], offsets[2 * i + 1]};
    if (!store(&out->state, out->num_bumpers, states) || !store(&out->bumper_offsets, out->num_bumpers, points) ||
        !f.host_to(&out->host))
      return out_of_memory();
    out->num_bumpers = n;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_base_velocity_message(char *string, carmen_base_velocity_message *msg) {
  return convert(__func__, string, msg, [](char *str, carmen_base_velocity_message *out) -> const char * {
    Fields f(str, "BASEVELOCITY", {"BASEVELOCITY"});
    double tv, rv;
    if (!f.p.finite(tv, "tv") || !f.p.finite(rv, "rv") || !f.trailer()) return f.failed();
    if (!f.host_to(&out->host)) return out_of_memory();
    out->tv = tv;
    out->rv = rv;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_gps_gpgga_message(char *string, carmen_gps_gpgga_message *gps_msg) {
  return convert(__func__, string, gps_msg, [](char *str, carmen_gps_gpgga_message *out) -> const char * {
    Fields f(str, "NMEAGGA", {"NMEAGGA"});
    carmen_gps_gpgga_message m;
    std::memset(static_cast<void *>(&m), 0, sizeof m);
    if (!f.p.small_int(m.nr, "nr") || !f.p.finite(m.utc, "utc") || !f.p.finite(m.latitude_dm, "latitude_dm") ||
        !f.letter(m.lat_orient, "lat_orient") || !f.p.finite(m.longitude_dm, "longitude_dm") ||
        !f.letter(m.long_orient, "long_orient") || !f.p.small_int(m.gps_quality, "gps_quality") ||
        !f.p.small_int(m.num_satellites, "num_satellites") || !f.p.finite(m.hdop, "hdop") ||
        !f.p.finite(m.sea_level, "sea_level") || !f.p.finite(m.altitude, "altitude") ||
        !f.p.finite(m.geo_sea_level, "geo_sea_level") || !f.p.finite(m.geo_sep, "geo_sep") ||
        !f.p.small_int(m.data_age, "data_age") || !f.trailer())
      return f.failed();
    if (!f.host_to(&out->host)) return out_of_memory();
    m.latitude = degmin_to_degrees(m.latitude_dm);
    m.longitude = degmin_to_degrees(m.longitude_dm);
    m.timestamp = f.timestamp;
    m.host = out->host;
    *out = m;
    return f.after_host;
  });
}

char *carmen_string_to_gps_gprmc_message(char *string, carmen_gps_gprmc_message *gps_msg) {
  return convert(__func__, string, gps_msg, [](char *str, carmen_gps_gprmc_message *out) -> const char * {
    Fields f(str, "NMEARMC", {"NMEARMC"});
    carmen_gps_gprmc_message m;
    std::memset(static_cast<void *>(&m), 0, sizeof m);
    if (!f.p.small_int(m.nr, "nr") || !f.p.small_int(m.validity, "validity") || !f.p.finite(m.utc, "utc") ||
        !f.p.finite(m.latitude_dm, "latitude_dm") || !f.letter(m.lat_orient, "lat_orient") ||
        !f.p.finite(m.longitude_dm, "longitude_dm") || !f.letter(m.long_orient, "long_orient") ||
        !f.p.finite(m.speed, "speed") || !f.p.finite(m.true_course, "true_course") ||
        !f.p.finite(m.variation, "variation") || !f.letter(m.var_dir, "var_dir") ||
        !f.p.small_int(m.date, "date") || !f.trailer())
      return f.failed();
    if (!f.host_to(&out->host)) return out_of_memory();
    m.latitude = degmin_to_degrees(m.latitude_dm);
    m.longitude = degmin_to_degrees(m.longitude_dm);
    m.timestamp = f.timestamp;
    m.host = out->host;
    *out = m;
    return f.after_host;
  });
}

char *carmen_string_to_imu_message(char *string, carmen_imu_message *msg) {
  return convert(__func__, string, msg, [](char *str, carmen_imu_message *out) -> const char * {
    Fields f(str, "IMU", {"IMU"});
    double v[13];
    static const char *const kNames[13] = {"accX", "accY", "accZ", "q0",    "q1",    "q2",   "q3",
                                           "magX", "magY", "magZ", "gyroX", "gyroY", "gyroZ"};
    for (int i = 0; i < 13; ++i)
      if (!f.p.finite(v[i], kNames[i])) return f.failed();
    if (!f.trailer()) return f.failed();
    if (!f.host_to(&out->host)) return out_of_memory();
    out->accX = v[0];
    out->accY = v[1];
    out->accZ = v[2];
    out->q0 = v[3];
    out->q1 = v[4];
    out->q2 = v[5];
    out->q3 = v[6];
    out->magX = v[7];
    out->magY = v[8];
    out->magZ = v[9];
    out->gyroX = v[10];
    out->gyroY = v[11];
    out->gyroZ = v[12];
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_pantilt_laserpos_message(char *string, carmen_pantilt_laserpos_message *laserpos) {
  return convert(__func__, string, laserpos, [](char *str, carmen_pantilt_laserpos_message *out) -> const char * {
    Fields f(str, "POSITIONLASER", {"POSITIONLASER"});
    int id;
    double x, y, z, phi, theta, psi;
    if (!f.p.small_int(id, "id") || !f.p.finite(x, "x") || !f.p.finite(y, "y") || !f.p.finite(z, "z") ||
        !f.p.finite(phi, "phi") || !f.p.finite(theta, "theta") || !f.p.finite(psi, "psi") || !f.trailer())
      return f.failed();
    if (!f.host_to(&out->host)) return out_of_memory();
    out->id = id;
    out->x = x;
    out->y = y;
    out->z = z;
    out->phi = phi;
    out->theta = theta;
    out->psi = psi;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_pantilt_scanmark_message(char *string, carmen_pantilt_scanmark_message *scanmark) {
  return convert(__func__, string, scanmark, [](char *str, carmen_pantilt_scanmark_message *out) -> const char * {
    Fields f(str, "SCANMARK", {"SCANMARK"});
    int type, laserid;
    if (!f.p.small_int(type, "type") || !f.p.small_int(laserid, "laserid") || !f.trailer()) return f.failed();
    if (!f.host_to(&out->host)) return out_of_memory();
    out->type = type;
    out->laserid = laserid;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_robot_follow_trajectory_message(char *string,
                                                       carmen_robot_follow_trajectory_message *msg) {
  return convert(__func__, string, msg,
                 [](char *str, carmen_robot_follow_trajectory_message *out) -> const char * {
    Fields f(str, "FOLLOWTRAJECTORY", {"FOLLOWTRAJECTORY", "ROBOTVELOCITY"});
    double r[5];
    static const char *const kNames[5] = {"x", "y", "theta", "t_vel", "r_vel"};
    for (int i = 0; i < 5; ++i)
      if (!f.p.finite(r[i], kNames[i])) return f.failed();
    int n = 0;
    std::vector<double> pts;
    if (!f.p.count(n, "trajectory_length") || !f.doubles(pts, 5 * n, "trajectory", true) || !f.trailer())
      return f.failed();
    std::vector<carmen_traj_point_t> traj(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
      traj[i] = {pts[5 * i], pts[5 * i + 1], pts[5 * i + 2], pts[5 * i + 3], pts[5 * i + 4]};
    if (!store(&out->trajectory, out->trajectory_length, traj) || !f.host_to(&out->host)) return out_of_memory();
    out->trajectory_length = n;
    out->robot_position = {r[0], r[1], r[2], r[3], r[4]};
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_robot_vector_move_message(char *string, carmen_robot_vector_move_message *msg) {
  return convert(__func__, string, msg, [](char *str, carmen_robot_vector_move_message *out) -> const char * {
    Fields f(str, "VECTORMOVE", {"VECTORMOVE"});
    double distance, theta;
    if (!f.p.finite(distance, "distance") || !f.p.finite(theta, "theta") || !f.trailer()) return f.failed();
    if (!f.host_to(&out->host)) return out_of_memory();
    out->distance = distance;
    out->theta = theta;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_robot_velocity_message(char *string, carmen_robot_velocity_message *msg) {
  return convert(__func__, string, msg, [](char *str, carmen_robot_velocity_message *out) -> const char * {
    Fields f(str, "ROBOTVELOCITY", {"ROBOTVELOCITY", "VELOCITY"});
    double tv, rv;
    if (!f.p.finite(tv, "tv") || !f.p.finite(rv, "rv") || !f.trailer()) return f.failed();
    if (!f.host_to(&out->host)) return out_of_memory();
    out->tv = tv;
    out->rv = rv;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

}  // extern "C"
