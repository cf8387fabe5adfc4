// CARMEN's readlog C API on top of the C++ log parser (log_reader.cc), so the
// two share one implementation of every message format.
#include "carmen/readlog.h"

#include <atomic>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "carmen_compat/log_reader.h"

namespace {

thread_local std::string g_last_error;
thread_local carmen::LogMessage g_scratch;

void set_error(const std::string &m) { g_last_error = m; }

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

bool check_args(const void *string, const void *msg) {
  g_last_error.clear();
  if (string == nullptr || msg == nullptr) {
    set_error("NULL argument");
    return false;
  }
  return true;
}

// The largest index carmen_logfile_index_messages builds (readlog.h).
std::atomic<int> g_max_messages{CARMEN_LOGFILE_MAX_MESSAGES};

// Message offsets, kept in a malloc()ed array that grows by half again (it
// becomes the index's array: no copy at the end). One slot more than the
// count, for the length.
struct Offsets {
  off_t *at = nullptr;
  std::size_t count = 0, capacity = 0;
  ~Offsets() { std::free(at); }
  // Room for one more offset after the last.
  bool room() {
    if (count < capacity) return true;
    const std::size_t grown = capacity < 1024 ? 1024 : capacity + capacity / 2;
    void *p = std::realloc(at, sizeof(off_t) * grown);
    if (p == nullptr) return false;
    at = static_cast<off_t *>(p);
    capacity = grown;
    return true;
  }
  bool push(off_t offset) {
    if (!room()) return false;
    at[count++] = offset;
    return true;
  }
};

// As CARMEN: index what could be read, and say what is wrong. A last
// message cut by the damage is dropped (it would be half a line).
void note_damage(carmen_FILE *infile, Offsets &offsets, bool after_newline, off_t &total) {
  const std::string what = infile->compressed ? "corrupt or truncated gzip stream" : "read error";
  if (!after_newline && offsets.count > 0) total = offsets.at[--offsets.count];
  set_error(what + " after " + std::to_string(offsets.count) + " messages: the rest of the log is lost");
  std::fprintf(stderr, "carmen_logfile_index_messages: %s\n", g_last_error.c_str());
  if (infile->compressed) gzclearerr(infile->comp_fp);
  else std::clearerr(infile->fp);
}

// Finds where every message starts (every byte after a '\n' but '\r', as
// CARMEN), stopping with an error at more than g_max_messages; the length of
// the stream goes in the slot after the last.
bool find_messages(carmen_FILE *infile, Offsets &offsets) {
  const std::size_t limit = static_cast<std::size_t>(g_max_messages.load());
  std::vector<char> chunk(std::size_t(1) << 20);
  off_t total = 0;
  bool after_newline = true;  // the first byte starts a message
  for (;;) {
    const std::size_t n = carmen_fread(chunk.data(), 1, chunk.size(), infile);
    for (std::size_t i = 0; i < n; ++i) {
      const char c = chunk[i];
      if (after_newline && c != '\r') {
        if (offsets.count == limit) {
          set_error("more than " + std::to_string(limit) +
                    " messages: over the index's limit (carmen_logfile_set_max_messages raises it)");
          return false;
        }
        if (!offsets.push(total + static_cast<off_t>(i))) {
          set_error("out of memory");
          return false;
        }
      }
      after_newline = c == '\n';
    }
    total += static_cast<off_t>(n);
    if (n < chunk.size()) break;
  }
  if (carmen_ferror(infile)) note_damage(infile, offsets, after_newline, total);
  if (!offsets.room()) {  // for the length
    set_error("out of memory");
    return false;
  }
  offsets.at[offsets.count] = total;
  return true;
}

// The index over `offsets`, which hands over its array; NULL when out of memory.
carmen_logfile_index_t *make_index(Offsets &offsets) {
  auto *index = static_cast<carmen_logfile_index_t *>(std::calloc(1, sizeof(carmen_logfile_index_t)));
  if (index == nullptr) {
    set_error("out of memory");
    return nullptr;
  }
  index->num_messages = static_cast<int>(offsets.count);
  index->current_position = 0;
  index->offset = offsets.at;
  offsets.at = nullptr;
  return index;
}

}  // namespace

extern "C" {

const char *carmen_readlog_last_error(void) { return g_last_error.c_str(); }

double carmen_laser_guess_fov(int num_beams) { return carmen::guess_laser_fov(num_beams); }

double carmen_laser_guess_angle_increment(int num_beams) {
  return carmen::guess_laser_angle_increment(num_beams);
}

char *carmen_string_to_laser_laser_message(char *string, carmen_laser_laser_message *laser) {
  if (!check_args(string, laser)) return nullptr;
  Text t = message_text(string);
  int id = -1;
  bool had;
  if (!skip_name(t, "RAWLASER", true, &id, &had)) {
    set_error("bad laser number after RAWLASER");
    return nullptr;
  }
  const char *after = nullptr;
  if (!parse(carmen::MessageType::RAWLASER1, t, &after)) return nullptr;
  if (!fill_laser_laser(laser, g_scratch.laser, had ? id : -1)) return nullptr;
  return result(string, after);
}

char *carmen_string_to_laser_laser_message_orig(char *string, carmen_laser_laser_message *laser) {
  if (!check_args(string, laser)) return nullptr;
  Text t = message_text(string);
  int id = -1;
  bool had = false;
  const char *after = nullptr;
  bool flaser = false;
  if (!skip_name(t, "FLASER", false, &id, &had)) return nullptr;
  if (!had && !skip_name(t, "RLASER", false, &id, &had)) return nullptr;
  flaser = had;
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
  if (!fill_laser_laser(laser, g_scratch.laser, had && !flaser ? id : -1)) return nullptr;
  return result(string, after);
}

char *carmen_string_to_robot_laser_message(char *string, carmen_robot_laser_message *laser) {
  if (!check_args(string, laser)) return nullptr;
  Text t = message_text(string);
  int id = -1;
  bool had;
  if (!skip_name(t, "ROBOTLASER", true, &id, &had)) {
    set_error("bad laser number after ROBOTLASER");
    return nullptr;
  }
  const char *after = nullptr;
  if (!parse(carmen::MessageType::ROBOTLASER1, t, &after)) return nullptr;
  if (!fill_robot_laser(laser, g_scratch.laser, had ? id : -1)) return nullptr;
  return result(string, after);
}

char *carmen_string_to_robot_laser_message_orig(char *string, carmen_robot_laser_message *laser) {
  if (!check_args(string, laser)) return nullptr;
  Text t = message_text(string);
  int id = -1;
  bool had = false;
  if (!skip_name(t, "FLASER", false, &id, &had)) return nullptr;
  if (!had && !skip_name(t, "RLASER", false, &id, &had)) return nullptr;
  const char *after = nullptr;
  if (!parse(carmen::MessageType::FLASER, t, &after)) return nullptr;
  if (!fill_robot_laser(laser, g_scratch.laser, -1, true)) return nullptr;
  return result(string, after);
}

char *carmen_string_to_base_odometry_message(char *string, carmen_base_odometry_message *odometry) {
  if (!check_args(string, odometry)) return nullptr;
  Text t = message_text(string);
  int id = -1;
  bool had;
  skip_name(t, "ODOM", false, &id, &had);
  const char *after = nullptr;
  if (!parse(carmen::MessageType::ODOM, t, &after)) return nullptr;
  const carmen::OdometryMessage &o = g_scratch.odom;
  if (!copy_host(&odometry->host, o.host)) {
    set_error("out of memory");
    return nullptr;
  }
  odometry->x = o.x;
  odometry->y = o.y;
  odometry->theta = o.theta;
  odometry->tv = o.tv;
  odometry->rv = o.rv;
  odometry->acceleration = o.acceleration;
  odometry->timestamp = o.timestamp;
  return result(string, after);
}

char *carmen_string_to_simulator_truepos_message(char *string,
                                                 carmen_simulator_truepos_message *truepos) {
  if (!check_args(string, truepos)) return nullptr;
  Text t = message_text(string);
  int id = -1;
  bool had;
  skip_name(t, "TRUEPOS", false, &id, &had);
  const char *after = nullptr;
  if (!parse(carmen::MessageType::TRUEPOS, t, &after)) return nullptr;
  const carmen::TrueposMessage &m = g_scratch.truepos;
  if (!copy_host(&truepos->host, m.host)) {
    set_error("out of memory");
    return nullptr;
  }
  truepos->truepose = {m.truepose.x, m.truepose.y, m.truepose.theta};
  truepos->odometrypose = {m.odometrypose.x, m.odometrypose.y, m.odometrypose.theta};
  truepos->timestamp = m.timestamp;
  return result(string, after);
}

// ---------------------------------------------------------------------------
// Index.

carmen_logfile_index_p carmen_logfile_index_messages(carmen_FILE *infile) {
  g_last_error.clear();
  if (infile == nullptr) {
    set_error("NULL file");
    return nullptr;
  }
  if (carmen_fseek(infile, 0, SEEK_SET) != 0) {
    set_error("cannot rewind the log");
    return nullptr;
  }
  Offsets offsets;
  if (!find_messages(infile, offsets)) return nullptr;
  carmen_logfile_index_t *index = make_index(offsets);
  if (index && carmen_fseek(infile, 0, SEEK_SET) != 0) {
    carmen_logfile_free_index(&index);
    set_error("cannot rewind the log");
  }
  return index;
}

int carmen_logfile_set_max_messages(int max_messages) {
  const int before = g_max_messages;
  if (max_messages > 0) g_max_messages = max_messages;
  return before;
}

void carmen_logfile_free_index(carmen_logfile_index_p *pindex) {
  if (pindex == nullptr || *pindex == nullptr) return;
  std::free((*pindex)->offset);
  std::free(*pindex);
  *pindex = nullptr;
}

int carmen_logfile_eof(carmen_logfile_index_p index) {
  if (index == nullptr) return 1;
  return index->current_position >= index->num_messages ? 1 : 0;
}

float carmen_logfile_percent_read(carmen_logfile_index_p index) {
  if (index == nullptr || index->num_messages <= 0) return 1.0f;
  return static_cast<float>(index->current_position) / static_cast<float>(index->num_messages);
}

// Positions the index (and the file) at message `next`; when the file cannot
// get there, at the end, so that carmen_logfile_eof() ends a reading loop.
static void skip_to(carmen_logfile_index_p index, carmen_FILE *infile, int next) {
  if (next < index->num_messages &&
      carmen_fseek(infile, static_cast<long>(index->offset[next]), SEEK_SET) == 0) {
    index->current_position = next;
  } else {
    index->current_position = index->num_messages;
  }
}

int carmen_logfile_read_line(carmen_logfile_index_p index, carmen_FILE *infile, int message_num,
                             int max_line_length, char *line) {
  g_last_error.clear();
  if (index == nullptr || infile == nullptr || line == nullptr || max_line_length <= 0) {
    set_error("NULL or invalid argument");
    return -1;
  }
  if (message_num < 0 || message_num >= index->num_messages) {
    set_error("message number " + std::to_string(message_num) + " out of range (0.." +
              std::to_string(index->num_messages - 1) + ")");
    return -1;
  }
  const off_t start = index->offset[message_num];
  const off_t length = index->offset[message_num + 1] - start;
  if (length >= static_cast<off_t>(max_line_length)) {
    // CARMEN exits here; we skip the message, so that a loop of
    // carmen_logfile_read_next_line until carmen_logfile_eof goes on.
    set_error("message " + std::to_string(message_num) + " has " + std::to_string(length) +
              " bytes, more than the buffer of " + std::to_string(max_line_length) + " allows: skipped");
    std::fprintf(stderr, "carmen_logfile_read_line: %s\n", g_last_error.c_str());
    skip_to(index, infile, message_num + 1);
    return -1;
  }
  if (message_num != index->current_position) {
    if (carmen_fseek(infile, static_cast<long>(start), SEEK_SET) != 0) {
      set_error("seek failed");
      return -1;
    }
    index->current_position = message_num;
  }
  const std::size_t n = carmen_fread(line, 1, static_cast<std::size_t>(length), infile);
  line[n] = '\0';
  if (n != static_cast<std::size_t>(length)) {
    set_error("short read: the log changed or is damaged");
    skip_to(index, infile, message_num + 1);  // the next call goes on, never spins
    return -1;
  }
  index->current_position = message_num + 1;
  return static_cast<int>(n);
}

int carmen_logfile_read_next_line(carmen_logfile_index_p index, carmen_FILE *infile,
                                  int max_line_length, char *line) {
  if (index == nullptr) {
    set_error("NULL index");
    return -1;
  }
  return carmen_logfile_read_line(index, infile, index->current_position, max_line_length, line);
}

}  // extern "C"
