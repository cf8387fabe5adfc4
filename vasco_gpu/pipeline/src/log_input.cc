#include "vasco_gpu/pipeline/log_input.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "carmen_compat/error.h"
#include "carmen_compat/ini_file.h"
#include "vasco_gpu/internal/se2.h"

namespace vasco {

namespace {

// options.map_resolution (or the tool's default) over the keys: the one
// rule of MapperParams::set_map_resolution. A usage error when it cannot be.
void apply_map_resolution(MapperParams &p, const LogInputOptions &options, const carmen::ParamFile &params) {
  double cell = options.map_resolution.value_or(0);
  if (!options.map_resolution && !params.has("vasco_resolution")) cell = options.default_map_resolution;
  if (!options.map_resolution && cell == 0) return;
  try {
    p.set_map_resolution(cell, params.has("vasco_downsample"));
  } catch (const ParamError &e) {
    throw carmen::Error(carmen::ErrorCode::Usage, e.what());
  }
}

// The ini and the command line, validated now, before a long log is read.
carmen::ParamFile command_line_params(const LogInputOptions &options, std::vector<std::string> *warnings) {
  carmen::ParamFile params;
  if (!options.param_file.empty()) params = carmen::ParamFile::load(options.param_file, options.robot);
  for (const auto &kv : options.overrides) params.set_override(kv.first, kv.second);
  for (const auto &w : params.warnings()) warnings->push_back(w.str());
  MapperParams p = MapperParams::from_params(params, nullptr);
  apply_map_resolution(p, options, params);
  return params;
}

// The scan named in messages: "intel.log line 812 (scan 403)".
std::string scan_name(const std::string &source, const ScanBatch &b, size_t s) {
  std::string n = source;
  if (s < b.line.size() && b.line[s] > 0) n += " line " + std::to_string(b.line[s]);
  return n + " (scan " + std::to_string(s) + ")";
}

// The laser pose of a robot pose from the pose file: by the given mount, or
// by the scan's own.
Pose2 laser_pose_of(const Pose2 &robot, const StampedScans &scans, size_t s, const PoseSource &src,
                    const std::string &source) {
  if (src.has_mount) return compose(robot, src.mount);
  if (s < scans.has_mount.size() && scans.has_mount[s]) return compose(robot, scans.mounts[s]);
  throw carmen::FileError(src.file, "the poses are of the robot, but " + scan_name(source, scans.batch, s) +
                                        " says nothing of where its laser sits on the robot (a FLASER line): "
                                        "give the mount with --laser-mount X,Y,THETA",
                          carmen::ErrorCode::Usage);
}

// Replaces the scans' poses by the pose file's (DESIGN §3 step 1 gets its
// poses from elsewhere). Returns which scans have one (empty: all do); those
// without are left out by keep_posed once the run is selected, so that
// vasco_first_scan and vasco_num_scans count the log's laser messages
// whatever the pose file lacks.
std::vector<uint8_t> apply_pose_file(StampedScans &scans, const PoseSource &src, const std::string &source,
                                     const Pose2 &transform, const PoseReadLimits &limits) {
  if (src.file.empty()) return {};
  const bool moved = transform.x != 0 || transform.y != 0 || transform.theta != 0;
  PoseFile file = read_pose_file(src.file, src.format, limits);
  PoseMatchOptions match = src.match;
  if (!src.id_map_file.empty()) match.id_map = read_pose_id_map(src.id_map_file);
  const PoseMatch m = match_poses(file, scans.batch.num_scans(), scans.stamps, source, scans.batch.line, match);
  ScanBatch &b = scans.batch;
  for (size_t s = 0; s < b.num_scans(); ++s) {
    if (!m.matched[s]) continue;
    Pose2 p = src.robot_frame ? laser_pose_of(m.pose[s], scans, s, src, source) : m.pose[s];
    if (moved) p = compose(transform, p);  // the file's poses are in the log's own frame, as its own were
    b.x[s] = p.x;
    b.y[s] = p.y;
    b.theta[s] = p.theta;
  }
  std::vector<uint8_t> matched(b.num_scans(), 1);
  for (size_t s = 0; s < b.num_scans(); ++s) matched[s] = m.matched[s];
  return matched;
}

// The selected run's scans without a pose from the file left out (and
// counted); none left is an error naming the file.
void keep_posed(LogInput &in, const std::vector<uint8_t> &matched, size_t first, const PoseSource &src,
                const std::string &source) {
  if (matched.empty()) return;  // no pose file
  const size_t n = in.batch.num_scans();
  std::vector<uint8_t> run(matched.begin() + static_cast<std::ptrdiff_t>(first),
                           matched.begin() + static_cast<std::ptrdiff_t>(first + n));
  const size_t unmatched = static_cast<size_t>(std::count(run.begin(), run.end(), uint8_t{0}));
  in.posed_from_file = n - unmatched;
  in.unposed_skipped += unmatched;
  if (unmatched == 0) return;
  if (unmatched == n)
    throw carmen::FileError(src.file, "none of the " + std::to_string(n) + " scans of " + source +
                                          (n < matched.size() ? " in the selected run" : std::string()) +
                                          " has a pose in this file (all left out by --skip-unposed)");
  StampedScans kept{std::move(in.batch), std::move(in.stamps), {}, {}, 0};
  kept.keep_only(run);
  in.batch = std::move(kept.batch);
  in.stamps = std::move(kept.stamps);
}

// The stamps of the scans select() keeps.
void select_stamps(std::vector<double> &stamps, size_t first, size_t kept) {
  const size_t begin = std::min(first, stamps.size());
  stamps.erase(stamps.begin(), stamps.begin() + static_cast<std::ptrdiff_t>(begin));
  stamps.resize(kept);
}

// A block larger than the grid leaves nothing to finish: say so, naming
// where the value came from.
void check_downsample(const LogInput &in, const carmen::ParamFile &params, const std::string &source) {
  if (in.params.downsample <= in.geo.size_x && in.params.downsample <= in.geo.size_y) return;
  const std::string m = "vasco_downsample = " + std::to_string(in.params.downsample) + " is larger than the grid (" +
                        std::to_string(in.geo.size_x) + " x " + std::to_string(in.geo.size_y) +
                        " cells): the finished map would be empty";
  const auto where = params.find("vasco_downsample");
  if (where && where->line > 0) throw carmen::FileError(where->file, where->line, m);
  throw carmen::FileError(where ? where->file : source, m);
}

// The steps after reading, the same for logs and bags: poses from a file,
// the effective parameters, the selected run, the grid.
LogInput finish_input(StampedScans scans, carmen::ParamFile &params, const LogInputOptions &options,
                      LogInput in, const std::string &scan_kind) {
  // The pose file gets what the scans left of the budget (at least a byte, so that 0 stays "no limit").
  PoseReadLimits limits;
  limits.budget_option = options.budget_option;
  if (options.memory_budget > 0)
    limits.memory_budget = std::max<uint64_t>(1, options.memory_budget - std::min(options.memory_budget,
                                                                                  in.load.log.kept_bytes));
  const std::vector<uint8_t> matched = apply_pose_file(scans, options.poses, options.log, options.transform, limits);
  in.params = MapperParams::from_params(params, &in.warnings);
  apply_map_resolution(in.params, options, params);  // the log's PARAM lines may have set vasco_downsample
  const long laser_messages = in.load.laser_messages;
  const size_t first = std::min<size_t>(static_cast<size_t>(std::max(in.params.first_scan, 0L)),
                                        scans.batch.num_scans());
  in.stamps = std::move(scans.stamps);
  in.batch = std::move(scans.batch).select(in.params.first_scan, in.params.num_scans);  // no copy of the ranges
  select_stamps(in.stamps, first, in.batch.num_scans());
  keep_posed(in, matched, first, options.poses, options.log);
  in.load.scans_used = static_cast<long>(in.batch.num_scans());
  if (in.batch.num_scans() == 0)
    throw carmen::FileError(
        options.log, std::string("no ") + scan_kind + " to map" +
                         std::string(laser_messages > 0 ? " in the selected range (vasco_first_scan " +
                                                              std::to_string(in.params.first_scan) + " of " +
                                                              std::to_string(laser_messages) + " laser messages)"
                                                        : ""));
  try {
    in.geo = size_grid(in.batch, in.params);  // the frame a Mapper's first insert of in.batch takes
  } catch (const carmen::Error &e) {
    // The poses came from the pose file where one was given: it is the file to name.
    if (!options.poses.file.empty())
      throw carmen::FileError(options.poses.file, std::string(e.what()) + " (with the poses of this file)", e.code());
    throw carmen::FileError(options.log, e.what(), e.code());
  }
  check_downsample(in, params, options.log);
  return in;
}

// The counts of a further session's log added to the first's.
void add_counts(LogLoadStats &to, const LogLoadStats &from) {
  carmen::LogStats &a = to.log;
  const carmen::LogStats &b = from.log;
  for (int t = 0; t < carmen::kNumMessageTypes; ++t) a.messages[t] += b.messages[t];
  for (int c = 0; c < carmen::kNumBadLineClasses; ++c) a.bad_lines[c] += b.bad_lines[c];
  a.lines += b.lines;
  a.blank_lines += b.blank_lines;
  a.comment_lines += b.comment_lines;
  a.unknown_lines += b.unknown_lines;
  a.nan_ranges += b.nan_ranges;
  a.inf_ranges += b.inf_ranges;
  a.negative_ranges += b.negative_ranges;
  a.kept_bytes += b.kept_bytes;
  to.laser_messages += from.laser_messages;
}

void check_sessions(const LogInputOptions &options) {
  if (!options.more_logs.empty() && !options.poses.file.empty())
    throw carmen::Error(carmen::ErrorCode::Usage,
                        "a pose file applies to one input: map several sessions with their own poses by "
                        "writing each session's poses into its log first (log2map --poses, then bag2carmen "
                        "or the Python API)");
  auto finite = [](const Pose2 &t) { return std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.theta); };
  if (!finite(options.transform)) throw carmen::Error(carmen::ErrorCode::Usage, options.log + ": the transform is not finite");
  for (const SessionInput &s : options.more_logs)
    if (!finite(s.transform)) throw carmen::Error(carmen::ErrorCode::Usage, s.path + ": the transform is not finite");
}

// Finds an "@auto" session's transform: its map aligned to the map of
// `scans`, the sessions before it. A refusal throws, naming the session.
AddedSession align_added(const StampedScans &scans, const StampedScans &session, const SessionInput &s,
                         const MapperParams &p, const SessionAlignOptions &align) {
  AddedSession a{s.path, s.transform, true, {}, 0};
  if (scans.batch.num_scans() == 0 || session.batch.num_scans() == 0)
    throw carmen::FileError(s.path, "no scans to align this session by (\"@auto\")");
  const auto t0 = std::chrono::steady_clock::now();
  a.result = align_session(scans.batch, session.batch, p, s.hint, align.threads);
  a.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (a.result.verdict != AlignVerdict::Aligned)
    throw carmen::FileError(s.path, std::string("not placed by alignment (\"@auto\"): ") +
                                        align_verdict_name(a.result.verdict) + ": " + align_candidates_text(a.result) +
                                        "; give its transform (@X,Y,THETA) or a hint (@auto:X,Y,THETA+-R)");
  a.transform = Pose2{a.result.best.x, a.result.best.y, a.result.best.theta};
  if (align.aligned) align.aligned(a);
  return a;
}

// Appends every further session to `scans` (the first input's, in the
// shared frame), in order: "@auto" ones at the transform that aligns each
// to all the sessions before it. The maps for the alignment take the run's
// parameters (`params`: the command line's, the ini's and every log's).
std::vector<AddedSession> append_sessions(StampedScans &scans, std::vector<StampedScans> more,
                                          const LogInputOptions &options, const carmen::ParamFile &params) {
  std::vector<AddedSession> added;
  MapperParams p;
  const bool any_auto = std::any_of(options.more_logs.begin(), options.more_logs.end(),
                                    [](const SessionInput &s) { return s.auto_transform; });
  if (any_auto) {
    p = MapperParams::from_params(params, nullptr);
    apply_map_resolution(p, options, params);
  }
  for (size_t i = 0; i < more.size(); ++i) {
    const SessionInput &s = options.more_logs[i];
    AddedSession a = s.auto_transform ? align_added(scans, more[i], s, p, options.align)
                                      : AddedSession{s.path, s.transform, false, {}, 0};
    scans.append(std::move(more[i]), a.transform);
    added.push_back(std::move(a));
  }
  return added;
}

}  // namespace

void StampedScans::append(StampedScans &&more, const Pose2 &transform) {
  more.batch.transform(transform.x, transform.y, transform.theta);  // the mounts are in the robot's frame: unchanged
  more.stamps.resize(more.batch.num_scans(), std::numeric_limits<double>::quiet_NaN());
  more.mounts.resize(more.batch.num_scans());
  more.has_mount.resize(more.batch.num_scans(), 0);
  stamps.resize(batch.num_scans(), std::numeric_limits<double>::quiet_NaN());
  mounts.resize(batch.num_scans());
  has_mount.resize(batch.num_scans(), 0);
  batch.append(more.batch);
  stamps.insert(stamps.end(), more.stamps.begin(), more.stamps.end());
  mounts.insert(mounts.end(), more.mounts.begin(), more.mounts.end());
  has_mount.insert(has_mount.end(), more.has_mount.begin(), more.has_mount.end());
  unposed += more.unposed;
}

void StampedScans::keep_only(const std::vector<uint8_t> &keep) {
  StampedScans kept;
  for (size_t s = 0; s < batch.num_scans(); ++s) {
    if (!keep[s]) continue;
    kept.batch.add_scan(batch.x[s], batch.y[s], batch.theta[s], batch.first_angle[s], batch.angle_step[s],
                        batch.ranges_of(s), batch.beams_in(s), batch.line[s]);
    kept.stamps.push_back(s < stamps.size() ? stamps[s] : std::numeric_limits<double>::quiet_NaN());
    kept.mounts.push_back(s < mounts.size() ? mounts[s] : Pose2{});
    kept.has_mount.push_back(s < has_mount.size() ? has_mount[s] : 0);
  }
  kept.unposed = unposed;
  *this = std::move(kept);
}

StampedScans read_stamped_scans(const std::string &path, const LogInputOptions &options, LogLoadStats *stats) {
  // Every laser message: the run is selected later, once the log's own
  // PARAM lines (which may set vasco_first_scan / vasco_num_scans) are known.
  MapperParams all;
  all.first_scan = 0;
  all.num_scans = -1;
  carmen::LogReaderOptions reader;
  reader.strict = !options.lenient;
  reader.memory_budget = options.memory_budget;
  reader.budget_option = options.budget_option;
  reader.budget_types = scan_message_bits() | carmen::message_type_bit(carmen::MessageType::PARAM);  // what load_scans keeps
  StampedScans out;
  out.batch = load_scans(path, all, reader, stats, options.progress);
  out.stamps = stats->stamps;
  out.mounts.resize(out.batch.num_scans());
  out.has_mount = stats->robot_pose_known;
  for (size_t s = 0; s < out.batch.num_scans(); ++s) {
    if (!out.has_mount[s]) continue;
    const carmen::Point &r = stats->robot_poses[s];
    out.mounts[s] = compose(inverse(Pose2{r.x, r.y, r.theta}),
                            Pose2{out.batch.x[s], out.batch.y[s], out.batch.theta[s]});
  }
  return out;
}

LogInput load_log_input(const LogInputOptions &options) {
  check_sessions(options);
  LogInput in;
  carmen::ParamFile params = command_line_params(options, &in.warnings);
  StampedScans scans = read_stamped_scans(options.log, options, &in.load);
  scans.batch.transform(options.transform.x, options.transform.y, options.transform.theta);
  auto add_params = [&](const LogLoadStats &load, const std::string &path) {
    for (size_t i = 0; i < load.params.size(); ++i)
      params.add_fallback(load.params[i].first, load.params[i].second, path, load.param_lines[i]);
  };
  add_params(in.load, options.log);
  std::vector<StampedScans> more_scans;
  for (const SessionInput &more : options.more_logs) {
    // The budget is for all sessions together: each log gets what is left.
    LogInputOptions rest = options;
    if (rest.memory_budget > 0)
      rest.memory_budget = rest.memory_budget > in.load.log.kept_bytes ? rest.memory_budget - in.load.log.kept_bytes : 1;
    LogLoadStats load;
    more_scans.push_back(read_stamped_scans(more.path, rest, &load));
    add_params(load, more.path);
    add_counts(in.load, load);
  }
  // Every log's PARAM lines are known: the maps an "@auto" session is aligned on take them.
  std::vector<AddedSession> added = append_sessions(scans, std::move(more_scans), options, params);
  LogInput out = finish_input(std::move(scans), params, options, std::move(in), scan_message_names() + " scans");
  out.added_sessions = std::move(added);
  return out;
}

LogInput log_input_from_scans(StampedScans scans, const LogInputOptions &options) {
  if (!options.more_logs.empty())
    throw carmen::Error(carmen::ErrorCode::Usage, "log_input_from_scans: append further sessions to the scans");
  check_sessions(options);
  scans.batch.validate();
  LogInput in;
  carmen::ParamFile params = command_line_params(options, &in.warnings);
  in.load.laser_messages = static_cast<long>(scans.batch.num_scans() + scans.unposed);
  in.unposed_skipped = scans.unposed;
  scans.batch.transform(options.transform.x, options.transform.y, options.transform.theta);
  return finish_input(std::move(scans), params, options, std::move(in), "scans");
}

LogInput log_input_from_sessions(StampedScans first, std::vector<StampedScans> more, const LogInputOptions &options) {
  if (more.size() != options.more_logs.size())
    throw carmen::Error(carmen::ErrorCode::Usage, "log_input_from_sessions: one set of scans per further session");
  check_sessions(options);
  std::vector<std::string> warnings;  // said by log_input_from_scans below
  const carmen::ParamFile params = command_line_params(options, &warnings);
  // --transform moves the first input alone, as load_log_input's: the
  // others come with their own.
  first.batch.transform(options.transform.x, options.transform.y, options.transform.theta);
  std::vector<AddedSession> added = append_sessions(first, std::move(more), options, params);
  LogInputOptions merged = options;
  merged.more_logs.clear();
  merged.transform = Pose2{};
  LogInput in = log_input_from_scans(std::move(first), merged);
  in.added_sessions = std::move(added);
  return in;
}

}  // namespace vasco
