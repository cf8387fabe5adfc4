// Pose files of SLAM back ends (TUM, g2o, CARMEN logs) and their matching
// to a log's scans; see pose_file.h.
#include "vasco_gpu/pose_file.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <string_view>
#include <system_error>
#include <unordered_map>

#include <sys/stat.h>

#include "carmen_compat/error.h"
#include "carmen_compat/file_names.h"
#include "carmen_compat/input_file.h"
#include "carmen_compat/log_reader.h"
#include "vasco_gpu/pose_series.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

namespace {

using carmen::ErrorCode;
using carmen::FileError;

// Longer lines are refused before they are stored: a pose line is well under
// 1 KiB, so a longer one is a binary or foreign file, not a reason to
// allocate without bound.
constexpr size_t kMaxLineLength = size_t(64) << 10;

// The shortest text that reads back as the same double (std::to_chars does
// not look at the locale, unlike printf, which writes "1083,25" in de_DE).
std::string number_text(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// A field as messages quote it: control characters escaped, long ones cut.
std::string quoted(std::string_view field) {
  constexpr size_t kShown = 40;
  std::string text(field.substr(0, kShown));
  if (field.size() > kShown) text += "...";
  return "'" + carmen::printable(text) + "'";
}

// ---------------------------------------------------------------------------
// Reading text files line by line.

// The lines of a plain text file, numbered from 1, each without its '\n'
// (and '\r'); refuses NUL bytes, gzip data and over-long lines.
class TextLines {
 public:
  explicit TextLines(const std::string &path) : path_(path) {
    // A directory opens, then reads as empty; a FIFO blocks the open: say what it is instead.
    carmen::require_regular_file(path, "a pose file");
    in_.open(path, std::ios::binary);
    if (!in_) throw FileError(path, std::string("cannot open: ") + std::strerror(errno), ErrorCode::Io);
  }

  bool next(std::string &line) {
    std::streambuf *buf = in_.rdbuf();
    line.clear();
    int c = buf->sbumpc();
    if (c == std::char_traits<char>::eof()) return false;
    ++number_;
    for (; c != std::char_traits<char>::eof() && c != '\n'; c = buf->sbumpc()) {
      if (line.size() >= kMaxLineLength)
        throw FileError(path_, number_,
                        "line longer than " + std::to_string(kMaxLineLength) + " bytes: not a pose file");
      line.push_back(static_cast<char>(c));
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    check(line);
    return true;
  }

  long number() const { return number_; }

 private:
  void check(std::string &line) const {
    if (number_ == 1 && line.compare(0, 2, "\x1f\x8b") == 0)
      throw FileError(path_, 1, "gzip data: only CARMEN logs are read compressed; gunzip it first");
    if (number_ == 1 && line.compare(0, 3, "\xef\xbb\xbf") == 0) line.erase(0, 3);  // UTF-8 byte order mark
    if (line.find('\0') != std::string::npos) throw FileError(path_, number_, "NUL byte: not a text file");
  }

  std::string path_;
  std::ifstream in_;
  long number_ = 0;
};

// Counts the poses read against PoseReadLimits. A pose is charged twice its
// size (the vector's growth, and the sorted copy time matching makes), plus
// what an index of it takes (g2o's ids).
class PoseBudget {
 public:
  PoseBudget(const std::string &path, const PoseReadLimits &limits, uint64_t index_bytes = 0)
      : path_(path), limits_(limits), per_pose_(2 * sizeof(StampedPose) + index_bytes) {}

  void charge(long line) {
    used_ += per_pose_;
    if (limits_.memory_budget == 0 || used_ <= limits_.memory_budget) return;
    throw FileError(path_, line,
                    "the poses up to here take more than the " + mebibytes(limits_.memory_budget) +
                        " MiB the run may use (" + limits_.budget_option + "): refused before the rest is read",
                    ErrorCode::OutOfMemory);
  }

 private:
  static std::string mebibytes(uint64_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", static_cast<double>(bytes) / (1 << 20));
    return text;
  }
  const std::string &path_;
  const PoseReadLimits &limits_;
  uint64_t per_pose_;
  uint64_t used_ = 0;
};

// The fields of a line, split at spaces and tabs.
std::vector<std::string_view> split_fields(const std::string &line) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (true) {
    i = line.find_first_not_of(" \t", i);
    if (i == std::string::npos) break;
    const size_t end = std::min(line.find_first_of(" \t", i), line.size());
    fields.emplace_back(line.data() + i, end - i);
    i = end;
  }
  return fields;
}

// Blank lines and lines whose first field starts with '#' carry nothing.
bool is_comment_or_blank(const std::vector<std::string_view> &fields) {
  return fields.empty() || fields[0][0] == '#';
}

// Where a field is, for messages: the file, the line, the field's number
// (from 1, as people count).
struct FieldAt {
  const std::string &path;
  long line;
  size_t number;
};

[[noreturn]] void bad_field(const FieldAt &at, std::string_view field, const std::string &what) {
  throw FileError(at.path, at.line, "field " + std::to_string(at.number) + " (" + quoted(field) + ") " + what);
}

// from_chars takes no '+' sign; strtod (and so every CARMEN tool) does.
std::string_view without_plus(std::string_view f) {
  if (f.size() > 1 && f[0] == '+' && f[1] != '+' && f[1] != '-') f.remove_prefix(1);
  return f;
}

// A finite double in the C locale whatever the process locale (from_chars
// never looks at it), correctly rounded: "%.17g" text reads back bit for bit.
double parse_double(const FieldAt &at, std::string_view field) {
  const std::string_view f = without_plus(field);
  double v = 0;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), v);
  if (r.ec == std::errc::invalid_argument || r.ptr != f.data() + f.size()) bad_field(at, field, "is not a number");
  if (r.ec == std::errc::result_out_of_range) bad_field(at, field, "is out of range");
  if (!std::isfinite(v)) bad_field(at, field, "is not finite");
  return v;
}

// A decimal integer >= 0 (vertex ids, scan indices).
long parse_index(const FieldAt &at, std::string_view field) {
  const std::string_view f = without_plus(field);
  long v = 0;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), v);
  if (r.ec == std::errc::invalid_argument || r.ptr != f.data() + f.size()) bad_field(at, field, "is not an integer");
  if (r.ec == std::errc::result_out_of_range) bad_field(at, field, "is out of range");
  if (v < 0) bad_field(at, field, "is negative");
  return v;
}

// The poses in stamp order, for the search by time. Real logs have stamps
// that go back now and then (intel's has four), so the file's order is
// not required; a stamp given twice must mean one pose.
std::vector<StampedPose> by_stamp(const std::string &path, std::vector<StampedPose> poses) {
  std::stable_sort(poses.begin(), poses.end(),
                   [](const StampedPose &a, const StampedPose &b) { return a.stamp < b.stamp; });
  std::vector<StampedPose> out;
  out.reserve(poses.size());
  for (const StampedPose &p : poses) {
    if (!out.empty() && out.back().stamp == p.stamp) {
      const Pose2 &a = out.back().pose, &b = p.pose;
      if (a.x == b.x && a.y == b.y && a.theta == b.theta) continue;
      const StampedPose &first = out.back().line < p.line ? out.back() : p;
      const StampedPose &second = out.back().line < p.line ? p : out.back();
      throw FileError(path, second.line,
                      "stamp " + number_text(p.stamp) + " is that of line " + std::to_string(first.line) +
                          " with another pose: which one a scan of that stamp takes is unclear");
    }
    out.push_back(p);
  }
  return out;
}

// ---------------------------------------------------------------------------
// The formats.

double quaternion_norm(double qx, double qy, double qz, double qw) {
  return std::hypot(std::hypot(qx, qy), std::hypot(qz, qw));  // no overflow for large components
}

// "t x y z qx qy qz qw".
StampedPose tum_pose(const std::string &path, long line, const std::vector<std::string_view> &fields) {
  if (fields.size() != 8)
    throw FileError(path, line,
                    std::to_string(fields.size()) + " fields, expected 8: 't x y z qx qy qz qw' (TUM)");
  double v[8];
  for (size_t i = 0; i < 8; ++i) v[i] = parse_double(FieldAt{path, line, i + 1}, fields[i]);
  const double norm = quaternion_norm(v[4], v[5], v[6], v[7]);
  if (norm == 0 || !std::isfinite(norm))
    throw FileError(path, line,
                    "the quaternion (qx qy qz qw) = (" + number_text(v[4]) + ", " + number_text(v[5]) + ", " +
                        number_text(v[6]) + ", " + number_text(v[7]) + ") has norm " + number_text(norm) +
                        ": not a rotation");
  StampedPose p;
  p.stamp = v[0];
  p.line = line;
  p.pose = {v[1], v[2], yaw_of_quaternion(v[4], v[5], v[6], v[7])};
  return p;
}

std::vector<StampedPose> read_tum(const std::string &path, const PoseReadLimits &limits) {
  TextLines lines(path);
  PoseBudget budget(path, limits);
  std::vector<StampedPose> poses;
  std::string line;
  while (lines.next(line)) {
    const auto fields = split_fields(line);
    if (is_comment_or_blank(fields)) continue;
    budget.charge(lines.number());
    poses.push_back(tum_pose(path, lines.number(), fields));
  }
  if (poses.empty()) throw FileError(path, "no poses: expected TUM lines 't x y z qx qy qz qw'");
  return poses;
}

// "VERTEX_SE2 id x y theta"; fields are numbered after the name, as in g2o.
StampedPose g2o_vertex(const std::string &path, long line, const std::vector<std::string_view> &fields) {
  if (fields.size() != 5)
    throw FileError(path, line,
                    "VERTEX_SE2 with " + std::to_string(fields.size() - 1) +
                        " fields, expected 4: 'VERTEX_SE2 id x y theta'");
  StampedPose p;
  p.stamp = std::numeric_limits<double>::quiet_NaN();
  p.line = line;
  p.id = parse_index(FieldAt{path, line, 1}, fields[1]);
  p.pose.x = parse_double(FieldAt{path, line, 2}, fields[2]);
  p.pose.y = parse_double(FieldAt{path, line, 3}, fields[3]);
  p.pose.theta = parse_double(FieldAt{path, line, 4}, fields[4]);
  return p;
}

std::vector<StampedPose> read_g2o(const std::string &path, const PoseReadLimits &limits) {
  TextLines lines(path);
  std::vector<StampedPose> poses;
  std::unordered_map<long, long> line_of_id;
  // An id's node in line_of_id: the pair, the bucket's pointer and the node's own.
  PoseBudget budget(path, limits, sizeof(std::pair<const long, long>) + 3 * sizeof(void *));
  std::string line;
  while (lines.next(line)) {
    const auto fields = split_fields(line);
    if (fields.empty() || fields[0] != "VERTEX_SE2") continue;  // edges, landmarks, FIX, comments
    budget.charge(lines.number());
    poses.push_back(g2o_vertex(path, lines.number(), fields));
    const auto seen = line_of_id.emplace(poses.back().id, lines.number());
    if (!seen.second)
      throw FileError(path, lines.number(),
                      "vertex id " + std::to_string(poses.back().id) + " repeated (first at line " +
                          std::to_string(seen.first->second) + ")");
  }
  if (poses.empty()) throw FileError(path, "no poses: no VERTEX_SE2 lines");
  return poses;
}

// The laser poses of the front laser's lines (RLASER / ROBOTLASER2 are the
// rear laser's, whose poses are of another sensor).
std::vector<StampedPose> read_carmen(const std::string &path, const PoseReadLimits &limits) {
  carmen::LogReader reader(path);
  carmen::LogMessage msg;
  PoseBudget budget(path, limits);
  std::vector<StampedPose> poses;
  while (reader.next(msg)) {
    if (!is_scan_message(msg.type)) continue;
    budget.charge(msg.line);
    StampedPose p;
    p.stamp = msg.laser.timestamp;
    p.line = msg.line;
    p.pose = {msg.laser.laser_pose.x, msg.laser.laser_pose.y, msg.laser.laser_pose.theta};
    poses.push_back(p);
  }
  if (poses.empty()) throw FileError(path, "no poses: no " + scan_message_names() + " lines");
  return poses;
}

PoseFileFormat format_of_name(const std::string &path) {
  using carmen::has_extension;
  if (has_extension(path, ".g2o")) return PoseFileFormat::G2o;
  for (const char *ext : {".log", ".clf", ".log.gz", ".clf.gz"})
    if (has_extension(path, ext)) return PoseFileFormat::CarmenLog;
  return PoseFileFormat::Tum;
}

// ---------------------------------------------------------------------------
// Matching.

// What names the scans in messages.
struct Scans {
  size_t count;
  const std::vector<double> &stamps;
  const std::string &source;
  const std::vector<long> &lines;
};

// "intel.log line 812 (scan 403, stamp 1083.25)", with what is known.
std::string scan_name(const Scans &scans, size_t s) {
  std::string where = scans.source;
  if (s < scans.lines.size() && scans.lines[s] > 0)
    where += (where.empty() ? "line " : " line ") + std::to_string(scans.lines[s]);
  std::string which = "scan " + std::to_string(s);
  if (s < scans.stamps.size()) which += ", stamp " + number_text(scans.stamps[s]);
  return where.empty() ? which : where + " (" + which + ")";
}

std::string scan_count(const Scans &scans) {
  return std::to_string(scans.count) + " scans" + (scans.source.empty() ? "" : " in " + scans.source);
}

// Scans left without a pose: counted when skip_unmatched, else the first is
// an error.
void finish_unmatched(const PoseFile &file, const Scans &scans, const PoseMatchOptions &options,
                      const std::string &what, PoseMatch &m) {
  size_t first = scans.count;
  uint64_t missing = 0;
  for (size_t s = 0; s < scans.count; ++s)
    if (!m.matched[s]) {
      if (missing++ == 0) first = s;
    }
  if (missing == 0) return;
  if (!options.skip_unmatched)
    throw FileError(file.path, "no " + what + " for " + scan_name(scans, first) + " (" +
                                   std::to_string(missing) + " of " + scan_count(scans) + " have none)");
  m.unmatched = missing;
}

void match_in_order(const PoseFile &file, const Scans &scans, PoseMatch &m) {
  if (file.poses.size() != scans.count)
    throw FileError(file.path, std::to_string(file.poses.size()) + " poses but " + scan_count(scans) +
                                   ": matching in order needs one pose per scan (match by time or id instead)");
  for (size_t s = 0; s < scans.count; ++s) {
    m.pose[s] = file.poses[s].pose;
    m.matched[s] = 1;
  }
}

std::unordered_map<long, long> id_map_of(const std::vector<std::pair<long, long>> &pairs) {
  std::unordered_map<long, long> map;
  for (const auto &p : pairs)
    if (!map.emplace(p.first, p.second).second)
      throw carmen::Error(ErrorCode::Usage, "the id map gives vertex id " + std::to_string(p.first) + " twice");
  return map;
}

// The scan a vertex belongs to, checked against the log.
size_t scan_of_vertex(const PoseFile &file, const StampedPose &p, const std::unordered_map<long, long> &map,
                      const Scans &scans) {
  long scan = p.id;
  if (!map.empty()) {
    const auto it = map.find(p.id);
    if (it == map.end())
      throw FileError(file.path, p.line, "vertex id " + std::to_string(p.id) + " is not in the id map");
    scan = it->second;
  }
  if (scan < 0 || static_cast<uint64_t>(scan) >= scans.count)
    throw FileError(file.path, p.line,
                    "vertex id " + std::to_string(p.id) +
                        (map.empty() ? "" : " (mapped to scan " + std::to_string(scan) + ")") + " is outside the " +
                        scan_count(scans) +
                        (scans.count > 0 ? " (0 to " + std::to_string(scans.count - 1) + ")" : ""));
  return static_cast<size_t>(scan);
}

void match_by_id(const PoseFile &file, const Scans &scans, const PoseMatchOptions &options, PoseMatch &m) {
  if (file.format != PoseFileFormat::G2o)
    throw FileError(file.path, std::string("a ") + pose_file_format_name(file.format) +
                                   " file has no vertex ids: match by order or time",
                    ErrorCode::Usage);
  const auto map = id_map_of(options.id_map);
  std::vector<const StampedPose *> owner(scans.count, nullptr);
  for (const StampedPose &p : file.poses) {
    const size_t s = scan_of_vertex(file, p, map, scans);
    if (owner[s] != nullptr)
      throw FileError(file.path, p.line,
                      "vertex id " + std::to_string(p.id) + " and vertex id " + std::to_string(owner[s]->id) +
                          " (line " + std::to_string(owner[s]->line) + ") are both for scan " + std::to_string(s));
    owner[s] = &p;
    m.pose[s] = p.pose;
    m.matched[s] = 1;
  }
  finish_unmatched(file, scans, options, "vertex", m);
}

Pose2 interpolate(const StampedPose &p0, const StampedPose &p1, double t) {
  return pose_between(p0.pose, p1.pose, (t - p0.stamp) / (p1.stamp - p0.stamp));
}

// A distance in seconds for messages: few digits, but enough that it
// never reads as the limit it exceeds (5.0000001 is not "5").
std::string seconds_text(double d, double limit) {
  for (int digits = 6; digits < 17; ++digits) {
    char a[40], b[40];
    std::snprintf(a, sizeof a, "%.*g", digits, d);
    std::snprintf(b, sizeof b, "%.*g", digits, limit);
    if (std::strcmp(a, b) != 0) return a;
  }
  return number_text(d);
}

// How a scan's stamp was matched; Invalid: two poses whose interpolation is
// not a number (coordinates so large that their difference overflows).
enum class StampMatch { None, Exact, Interpolated, Nearest, Invalid };

// The pose at stamp t (PoseMatchOptions: exact, interpolated within a gap
// of at most max_gap, else the nearest pose within tolerance), or None with
// why there is none: how far the stamp is from the poses, against which
// limit.
StampMatch pose_at(const std::vector<StampedPose> &poses, double t, const PoseMatchOptions &o, Pose2 &pose,
                   std::string &why) {
  if (!std::isfinite(t)) {
    why = "the scan has no timestamp";
    return StampMatch::None;
  }
  const auto it = std::lower_bound(poses.begin(), poses.end(), t,
                                   [](const StampedPose &p, double stamp) { return p.stamp < stamp; });
  if (it != poses.end() && it->stamp == t) {
    pose = it->pose;  // exactly as in the file, no arithmetic
    return StampMatch::Exact;
  }
  const std::string tolerance = "--pose-tolerance " + number_text(o.tolerance);
  if (it == poses.begin() || it == poses.end()) {
    const bool before = it == poses.begin();
    const StampedPose &end = before ? poses.front() : poses.back();
    const double d = before ? end.stamp - t : t - end.stamp;
    if (d <= o.tolerance) {
      pose = end.pose;
      return StampMatch::Nearest;
    }
    why = seconds_text(d, o.tolerance) + " s " + (before ? "before the first" : "after the last") + " pose (" +
          number_text(end.stamp) + "), more than " + tolerance;
    return StampMatch::None;
  }
  const StampedPose &p0 = *(it - 1), &p1 = *it;
  const double gap = p1.stamp - p0.stamp;
  if (gap <= o.max_gap) {
    pose = interpolate(p0, p1, t);
    if (std::isfinite(pose.x) && std::isfinite(pose.y) && std::isfinite(pose.theta)) return StampMatch::Interpolated;
    why = "the poses of lines " + std::to_string(p0.line) + " and " + std::to_string(p1.line) +
          " around it interpolate to a pose that is not finite: their coordinates are too large";
    return StampMatch::Invalid;
  }
  // A hole in the trajectory: its sides are ends, as the trajectory's are.
  const double d0 = t - p0.stamp, d1 = p1.stamp - t;
  if (std::min(d0, d1) <= o.tolerance) {
    pose = d0 <= d1 ? p0.pose : p1.pose;
    return StampMatch::Nearest;
  }
  why = "the poses around it (" + number_text(p0.stamp) + " and " + number_text(p1.stamp) + ") are " +
        seconds_text(gap, o.max_gap) + " s apart, more than --pose-max-gap " + number_text(o.max_gap) +
        ", and the nearer is " + seconds_text(std::min(d0, d1), o.tolerance) + " s away, more than " + tolerance;
  return StampMatch::None;
}

void check_stamped(const PoseFile &file, const Scans &scans) {
  if (!file.has_stamps())
    throw FileError(file.path, "a g2o file has no stamps: match its poses by order or id", ErrorCode::Usage);
  if (scans.stamps.size() != scans.count)
    throw carmen::Error(ErrorCode::Usage, "matching by time needs one stamp per scan: " +
                                              std::to_string(scans.stamps.size()) + " stamps for " +
                                              std::to_string(scans.count) + " scans");
}

void match_by_time(const PoseFile &file, const Scans &scans, const PoseMatchOptions &options, PoseMatch &m) {
  check_stamped(file, scans);
  const std::vector<StampedPose> poses = by_stamp(file.path, file.poses);
  for (size_t s = 0; s < scans.count; ++s) {
    std::string why = "the file has no poses";
    const StampMatch how = poses.empty() ? StampMatch::None : pose_at(poses, scans.stamps[s], options, m.pose[s], why);
    if (how == StampMatch::Invalid) throw FileError(file.path, "no pose for " + scan_name(scans, s) + ": " + why);
    if (how != StampMatch::None) {
      m.matched[s] = 1;
      m.interpolated += how == StampMatch::Interpolated;
      m.nearest += how == StampMatch::Nearest;
      continue;
    }
    if (!options.skip_unmatched) throw FileError(file.path, "no pose for " + scan_name(scans, s) + ": " + why);
    ++m.unmatched;
  }
}

}  // namespace

PoseFileFormat pose_file_format_from_name(const std::string &name) {
  for (PoseFileFormat f : {PoseFileFormat::Auto, PoseFileFormat::Tum, PoseFileFormat::G2o, PoseFileFormat::CarmenLog})
    if (name == pose_file_format_name(f)) return f;
  throw carmen::Error(ErrorCode::Usage,
                      "unknown pose file format '" + carmen::printable(name) + "': expected one of auto, tum, g2o, carmen");
}

const char *pose_file_format_name(PoseFileFormat format) {
  switch (format) {
    case PoseFileFormat::Auto: return "auto";
    case PoseFileFormat::Tum: return "tum";
    case PoseFileFormat::G2o: return "g2o";
    case PoseFileFormat::CarmenLog: return "carmen";
  }
  return "auto";
}

PoseFile read_pose_file(const std::string &path, PoseFileFormat format, const PoseReadLimits &limits) {
  PoseFile file;
  file.path = path;
  file.format = format == PoseFileFormat::Auto ? format_of_name(path) : format;
  switch (file.format) {
    case PoseFileFormat::G2o: file.poses = read_g2o(path, limits); break;
    case PoseFileFormat::CarmenLog: file.poses = read_carmen(path, limits); break;
    default: file.poses = read_tum(path, limits); break;
  }
  return file;
}

PoseMatching pose_matching_from_name(const std::string &name) {
  if (name == "auto") return PoseMatching::Auto;
  if (name == "order") return PoseMatching::Order;
  if (name == "id") return PoseMatching::Id;
  if (name == "time") return PoseMatching::Timestamp;
  throw carmen::Error(ErrorCode::Usage,
                      "unknown pose matching '" + carmen::printable(name) + "': expected one of auto, order, id, time");
}

PoseMatch match_poses(const PoseFile &file, size_t num_scans, const std::vector<double> &scan_stamps,
                      const std::string &scan_source, const std::vector<long> &scan_lines,
                      const PoseMatchOptions &options) {
  if (!std::isfinite(options.tolerance) || options.tolerance < 0)
    throw carmen::Error(ErrorCode::Usage, "the pose tolerance " + number_text(options.tolerance) +
                                              " s is not a finite number >= 0 (--pose-tolerance)");
  if (std::isnan(options.max_gap) || options.max_gap < 0)
    throw carmen::Error(ErrorCode::Usage, "the largest gap between poses " + number_text(options.max_gap) +
                                              " s is not a number >= 0 (--pose-max-gap; inf: any gap)");
  PoseMatch m;
  m.used = options.matching;
  if (m.used == PoseMatching::Auto) m.used = file.has_stamps() ? PoseMatching::Timestamp : PoseMatching::Order;
  m.pose.resize(num_scans);
  m.matched.assign(num_scans, 0);
  const Scans scans{num_scans, scan_stamps, scan_source, scan_lines};
  switch (m.used) {
    case PoseMatching::Id: match_by_id(file, scans, options, m); break;
    case PoseMatching::Timestamp: match_by_time(file, scans, options, m); break;
    default: match_in_order(file, scans, m); break;
  }
  return m;
}

std::vector<std::pair<long, long>> read_pose_id_map(const std::string &path) {
  TextLines lines(path);
  std::vector<std::pair<long, long>> pairs;
  std::unordered_map<long, long> line_of_id;
  std::string line;
  while (lines.next(line)) {
    const auto fields = split_fields(line);
    if (is_comment_or_blank(fields)) continue;
    const long n = lines.number();
    if (fields.size() != 2)
      throw FileError(path, n, std::to_string(fields.size()) + " fields, expected 2: 'id scan'");
    const long id = parse_index(FieldAt{path, n, 1}, fields[0]);
    const long scan = parse_index(FieldAt{path, n, 2}, fields[1]);
    const auto seen = line_of_id.emplace(id, n);
    if (!seen.second)
      throw FileError(path, n, "id " + std::to_string(id) + " repeated (first at line " +
                                   std::to_string(seen.first->second) + ")");
    pairs.emplace_back(id, scan);
  }
  if (pairs.empty()) throw FileError(path, "no 'id scan' lines");
  return pairs;
}

Pose2 compose(const Pose2 &a, const Pose2 &b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, a.theta + b.theta};
}

Pose2 inverse(const Pose2 &a) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {-c * a.x - s * a.y, s * a.x - c * a.y, -a.theta};
}

// Normalised first, so that the 1 - 2(qy^2 + qz^2) form is right for a
// quaternion written with few digits; NaN for one that is no rotation.
double yaw_of_quaternion(double qx, double qy, double qz, double qw) {
  const double n = quaternion_norm(qx, qy, qz, qw);
  if (!(n > 0) || !std::isfinite(n)) return std::numeric_limits<double>::quiet_NaN();
  qx /= n;
  qy /= n;
  qz /= n;
  qw /= n;
  return std::atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz));
}

}  // namespace vasco
