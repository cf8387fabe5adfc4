// CARMEN's readlog converters of the messages the C++ log reader knows
// (RAWLASER, the old LASER/FLASER/RLASER forms, ROBOTLASER, ODOM, TRUEPOS),
// on its parser (log_reader.cc) and field rules (log_fields.h), so that both
// share one implementation of every message format; the other converters
// are in readlog_field_messages.cc. A bad line leaves an empty, usable
// message (readlog.h, readlog_convert.h).
#include "carmen/readlog.h"

#include <cstring>
#include <string>

#include "carmen_compat/log_reader.h"
#include "log_fields.h"
#include "readlog_convert.h"

namespace {

using namespace carmen::readlog;

thread_local carmen::LogMessage g_scratch;

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

// Skips "PREFIX<id>" (the laser's number); false, with the error set, for a
// malformed number.
bool skip_laser_name(Text &t, const char *prefix, int *id, bool *had) {
  if (skip_name(t, prefix, true, id, had)) return true;
  set_error(std::string("bad laser number after ") + prefix);
  return false;
}

// The line of a message without a number: its name skipped when it is
// there, its fields parsed into g_scratch.
bool parse_named(char *str, const char *prefix, carmen::MessageType type, const char **after_host) {
  Text t = message_text(str);
  int id = -1;
  bool had;
  skip_name(t, prefix, false, &id, &had);
  return parse(type, t, after_host);
}

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
    if (!skip_laser_name(t, "RAWLASER", &id, &had)) return nullptr;
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
      if (!skip_laser_name(t, "LASER", &id, &had)) return nullptr;
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
    if (!skip_laser_name(t, "ROBOTLASER", &id, &had)) return nullptr;
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
    const char *after = nullptr;
    if (!parse_named(str, "ODOM", carmen::MessageType::ODOM, &after)) return nullptr;
    const carmen::OdometryMessage &o = g_scratch.odom;
    if (!copy_host(&out->host, o.host)) return out_of_memory();
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
    const char *after = nullptr;
    if (!parse_named(str, "TRUEPOS", carmen::MessageType::TRUEPOS, &after)) return nullptr;
    const carmen::TrueposMessage &m = g_scratch.truepos;
    if (!copy_host(&out->host, m.host)) return out_of_memory();
    out->truepose = {m.truepose.x, m.truepose.y, m.truepose.theta};
    out->odometrypose = {m.odometrypose.x, m.odometrypose.y, m.odometrypose.theta};
    out->timestamp = m.timestamp;
    return after;
  });
}

}  // extern "C"
