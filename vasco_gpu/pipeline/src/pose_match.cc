// Matching a pose file's poses to a log's scans; see pose_match.h.
#include "vasco_gpu/pipeline/pose_match.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <unordered_map>

#include "carmen_compat/error.h"
#include "number_text.h"
#include "vasco_gpu/internal/se2.h"

namespace vasco {

namespace {

using carmen::ErrorCode;
using carmen::FileError;

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

}  // namespace vasco
