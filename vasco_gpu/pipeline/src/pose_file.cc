// Pose files of SLAM back ends (TUM, g2o, CARMEN logs); see pose_file.h.
#include "vasco_gpu/pipeline/pose_file.h"

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

#include "carmen_compat/error.h"
#include "carmen_compat/file_names.h"
#include "carmen_compat/input_file.h"
#include "carmen_compat/log_reader.h"
#include "number_text.h"
#include "vasco_gpu/internal/se2.h"
#include "vasco_gpu/pipeline/log_scans.h"

namespace vasco {

namespace {

using carmen::ErrorCode;
using carmen::FileError;

// Longer lines are refused before they are stored: a pose line is well under
// 1 KiB, so a longer one is a binary or foreign file, not a reason to
// allocate without bound.
constexpr size_t kMaxLineLength = size_t(64) << 10;

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

// ---------------------------------------------------------------------------
// The formats.

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

}  // namespace vasco
