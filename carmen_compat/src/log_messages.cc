// The message table: one row per log message type (name, field rule,
// parser), and the line parsing that dispatches on it.
#include "log_messages.h"

#include <cstring>
#include <string>

#include "log_diagnosis.h"
#include "log_number.h"

namespace carmen {

namespace {

bool parse_trailer(FieldParser &f, double &timestamp, std::string &host, double &logger_timestamp,
                   const char **after_host) {
  if (!f.finite(timestamp, "ipc_timestamp")) return false;
  const char *hb, *he;
  if (!f.token(hb, he, "host")) return false;
  host.assign(hb, static_cast<std::size_t>(he - hb));
  if (after_host) *after_host = he;
  if (!f.finite(logger_timestamp, "logger_timestamp")) return false;
  return f.at_end();
}

bool parse_point(FieldParser &f, Point &p, const char *x, const char *y, const char *t) {
  return f.finite(p.x, x) && f.finite(p.y, y) && f.finite(p.theta, t);
}

bool parse_old_laser(FieldParser &f, LaserMessage &m, bool with_poses, Counts &c,
                     const char **after_host) {
  int n;
  if (!f.count(n, "num_readings")) return false;
  c.beams = n;
  m.range.resize(static_cast<std::size_t>(n));
  if (!f.floats(m.range.data(), n, "range")) return false;
  m.remission.clear();
  if (with_poses) {
    if (!parse_point(f, m.laser_pose, "x", "y", "theta")) return false;
    if (!parse_point(f, m.robot_pose, "odom_x", "odom_y", "odom_theta")) return false;
  } else {
    m.laser_pose = Point();
    m.robot_pose = Point();
  }
  if (!parse_trailer(f, m.timestamp, m.host, m.logger_timestamp, after_host)) return false;
  m.id = -1;
  m.config = guess_laser_config(n);
  m.has_pose = with_poses;
  m.tv = m.rv = m.forward_safety_dist = m.side_safety_dist = m.turn_axis = 0;
  return true;
}

bool parse_new_laser(FieldParser &f, LaserMessage &m, bool robot, Counts &c,
                     const char **after_host) {
  LaserConfig &cfg = m.config;
  if (!f.small_int(cfg.laser_type, "laser_type")) return false;
  if (!f.finite(cfg.start_angle, "start_angle")) return false;
  if (!f.finite(cfg.fov, "fov")) return false;
  if (!f.finite(cfg.angular_resolution, "angular_resolution")) return false;
  if (!f.finite(cfg.maximum_range, "maximum_range")) return false;
  if (!f.finite(cfg.accuracy, "accuracy")) return false;
  if (!f.small_int(cfg.remission_mode, "remission_mode")) return false;
  int n;
  if (!f.count(n, "num_readings")) return false;
  c.beams = n;
  m.range.resize(static_cast<std::size_t>(n));
  if (!f.floats(m.range.data(), n, "range")) return false;
  int r;
  if (!f.count(r, "num_remissions")) return false;
  m.remission.resize(static_cast<std::size_t>(r));
  if (!f.floats(m.remission.data(), r, "remission")) return false;
  if (robot) {
    if (!parse_point(f, m.laser_pose, "laser_x", "laser_y", "laser_theta")) return false;
    if (!parse_point(f, m.robot_pose, "robot_x", "robot_y", "robot_theta")) return false;
    if (!f.finite(m.tv, "tv") || !f.finite(m.rv, "rv") ||
        !f.finite(m.forward_safety_dist, "forward_safety_dist") ||
        !f.finite(m.side_safety_dist, "side_safety_dist") || !f.finite(m.turn_axis, "turn_axis"))
      return false;
  } else {
    m.laser_pose = Point();
    m.robot_pose = Point();
    m.tv = m.rv = m.forward_safety_dist = m.side_safety_dist = m.turn_axis = 0;
  }
  m.has_pose = robot;
  return parse_trailer(f, m.timestamp, m.host, m.logger_timestamp, after_host);
}

// Row parsers: each fills the LogMessage member of its type.
bool parse_flaser_row(const MessageRow &, FieldParser &f, LogMessage &msg, Counts &c, const char **after_host) {
  return parse_old_laser(f, msg.laser, true, c, after_host);
}

bool parse_robot_laser_row(const MessageRow &row, FieldParser &f, LogMessage &msg, Counts &c,
                           const char **after_host) {
  const bool ok = parse_new_laser(f, msg.laser, true, c, after_host);
  msg.laser.id = row.laser_id;
  return ok;
}

bool parse_raw_laser_row(const MessageRow &row, FieldParser &f, LogMessage &msg, Counts &c,
                         const char **after_host) {
  const bool ok = parse_new_laser(f, msg.laser, false, c, after_host);
  msg.laser.id = row.laser_id;
  return ok;
}

bool parse_odom_row(const MessageRow &, FieldParser &f, LogMessage &msg, Counts &, const char **after_host) {
  OdometryMessage &o = msg.odom;
  return f.finite(o.x, "x") && f.finite(o.y, "y") && f.finite(o.theta, "theta") && f.finite(o.tv, "tv") &&
         f.finite(o.rv, "rv") && f.finite(o.acceleration, "accel") &&
         parse_trailer(f, o.timestamp, o.host, o.logger_timestamp, after_host);
}

bool parse_truepos_row(const MessageRow &, FieldParser &f, LogMessage &msg, Counts &, const char **after_host) {
  TrueposMessage &t = msg.truepos;
  return parse_point(f, t.truepose, "true_x", "true_y", "true_theta") &&
         parse_point(f, t.odometrypose, "odom_x", "odom_y", "odom_theta") &&
         parse_trailer(f, t.timestamp, t.host, t.logger_timestamp, after_host);
}

bool parse_param_row(const MessageRow &, FieldParser &f, LogMessage &msg, Counts &, const char **) {
  const char *nb, *ne, *vb, *ve;
  if (!f.token(nb, ne, "name") || !f.token(vb, ve, "value")) return false;
  msg.param.name.assign(nb, static_cast<std::size_t>(ne - nb));
  msg.param.value.assign(vb, static_cast<std::size_t>(ve - vb));
  return true;
}

bool parse_sync_row(const MessageRow &, FieldParser &f, LogMessage &msg, Counts &, const char **) {
  const char *tb, *te;
  if (!f.token(tb, te, "tag")) return false;
  msg.sync.tag.assign(tb, static_cast<std::size_t>(te - tb));
  return true;
}

constexpr FieldRule kFlaserRule{FieldRule::BEAMS, 10, nullptr};
constexpr FieldRule kRobotLaserRule{FieldRule::BEAMS_REMISSIONS, 14, nullptr};
constexpr FieldRule kRawLaserRule{FieldRule::BEAMS_REMISSIONS, 3, nullptr};
constexpr FieldRule kPoseTrailerRule{FieldRule::FIXED, 9, nullptr};

// In MessageType order (checked below).
constexpr MessageRow kRows[kNumMessageTypes] = {
    {MessageType::FLASER, "FLASER", -1, kFlaserRule, parse_flaser_row},
    {MessageType::RLASER, "RLASER", -1, kFlaserRule, parse_flaser_row},
    {MessageType::ROBOTLASER1, "ROBOTLASER1", 1, kRobotLaserRule, parse_robot_laser_row},
    {MessageType::ROBOTLASER2, "ROBOTLASER2", 2, kRobotLaserRule, parse_robot_laser_row},
    {MessageType::RAWLASER1, "RAWLASER1", 1, kRawLaserRule, parse_raw_laser_row},
    {MessageType::RAWLASER2, "RAWLASER2", 2, kRawLaserRule, parse_raw_laser_row},
    {MessageType::RAWLASER3, "RAWLASER3", 3, kRawLaserRule, parse_raw_laser_row},
    {MessageType::RAWLASER4, "RAWLASER4", 4, kRawLaserRule, parse_raw_laser_row},
    {MessageType::ODOM, "ODOM", 0, kPoseTrailerRule, parse_odom_row},
    {MessageType::TRUEPOS, "TRUEPOS", 0, kPoseTrailerRule, parse_truepos_row},
    {MessageType::PARAM, "PARAM", 0, {FieldRule::AT_LEAST, 2, "a name and a value"}, parse_param_row},
    {MessageType::SYNC, "SYNC", 0, {FieldRule::AT_LEAST, 1, "a tag"}, parse_sync_row},
};

constexpr bool rows_in_type_order() {
  for (int i = 0; i < kNumMessageTypes; ++i)
    if (static_cast<int>(kRows[i].type) != i) return false;
  return true;
}
static_assert(rows_in_type_order(), "kRows must list the message types in MessageType order");

}  // namespace

const FieldRule kOldLaserRule{FieldRule::BEAMS, 4, nullptr};

const MessageRow &message_row(MessageType type) { return kRows[static_cast<int>(type)]; }

const char *message_type_name(MessageType type) {
  const int i = static_cast<int>(type);
  return i >= 0 && i < kNumMessageTypes ? kRows[i].name.data() : "?";
}

bool message_type_from_name(const char *s, std::size_t n, MessageType *type) {
  for (const MessageRow &row : kRows) {
    if (row.name != std::string_view(s, n)) continue;
    if (type) *type = row.type;
    return true;
  }
  return false;
}

bool is_laser_message(MessageType type) {
  const int i = static_cast<int>(type);
  return i >= 0 && i < kNumMessageTypes && kRows[i].laser_id != 0;
}

bool parse_message_fields(MessageType type, const char *begin, const char *end, LogMessage &msg,
                          LineError *err, const char **after_host) {
  const MessageRow &row = message_row(type);
  FieldParser f(begin, end);
  Counts c;
  msg.type = type;
  if (row.parse(row, f, msg, c, after_host)) return true;
  diagnose(row.name.data(), row.rule, begin, end, f, c, err);
  return false;
}

bool parse_old_laser_fields(const char *begin, const char *end, LaserMessage &laser,
                            LineError *err, const char **after_host) {
  FieldParser f(begin, end);
  Counts c;
  if (parse_old_laser(f, laser, false, c, after_host)) return true;
  diagnose("LASER", kOldLaserRule, begin, end, f, c, err);
  return false;
}

LineKind parse_log_line(const char *begin, const char *end, LogMessage &msg, LineError *err,
                        const char **name_end) {
  using lex::is_sep;
  if (end > begin && end[-1] == '\r') --end;
  const char *p = begin;
  while (p < end && is_sep(*p)) ++p;
  if (p == end) return LineKind::BLANK;
  const char *q = p;
  while (q < end && !is_sep(*q)) ++q;
  if (name_end) *name_end = q;
  if (*p == '#') return LineKind::COMMENT;
  MessageType type;
  if (!message_type_from_name(p, static_cast<std::size_t>(q - p), &type)) return LineKind::UNKNOWN;
  return parse_message_fields(type, q, end, msg, err) ? LineKind::MESSAGE : LineKind::BAD;
}

}  // namespace carmen
