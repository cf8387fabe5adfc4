#include "vasco_gpu/scan_batch.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <string>
#include <utility>

#include "vasco_gpu/error.h"
#include "vasco_gpu/internal/se2.h"

namespace vasco {

namespace {

[[noreturn]] void bad_scan(size_t s, const std::string &what) {
  throw Error(ErrorCode::BadInput, "scan batch: scan " + std::to_string(s) + ": " + what);
}

// A per-scan array shorter or longer than x: the first scan it lacks (or
// the first extra one) is the scan named.
void check_length(const char *name, size_t have, size_t scans) {
  if (have != scans)
    bad_scan(std::min(have, scans), std::string(name) + " has " + std::to_string(have) + " entries for " +
                                        std::to_string(scans) + " scans");
}

template <class T>
std::vector<T> slice(const std::vector<T> &v, size_t begin, size_t end) {
  return std::vector<T>(v.begin() + static_cast<std::ptrdiff_t>(begin), v.begin() + static_cast<std::ptrdiff_t>(end));
}

// Keeps [begin, end) of v in place.
template <class T>
void keep(std::vector<T> &v, size_t begin, size_t end) {
  v.erase(v.begin() + static_cast<std::ptrdiff_t>(end), v.end());
  v.erase(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(begin));
}

// Scans [begin, end) of a batch of n scans for select(first, count).
std::pair<size_t, size_t> selected(long first, long count, size_t scans) {
  const long n = static_cast<long>(scans);
  const long begin = std::min(std::max(first, 0L), n);
  const long end = (count < 0 || count > n - begin) ? n : begin + count;
  return {static_cast<size_t>(begin), static_cast<size_t>(end)};
}

}  // namespace

void ScanBatch::validate() const {
  const size_t n = num_scans();
  check_length("y", y.size(), n);
  check_length("theta", theta.size(), n);
  check_length("first_angle", first_angle.size(), n);
  check_length("angle_step", angle_step.size(), n);
  check_length("line", line.size(), n);
  if (beam_offset.size() != n + 1)
    bad_scan(beam_offset.empty() ? 0 : std::min(beam_offset.size() - 1, n), "beam_offset has " + std::to_string(beam_offset.size()) +
                                                  " entries for " + std::to_string(n) + " scans (needs n + 1)");
  if (beam_offset[0] != 0) bad_scan(0, "beam_offset[0] is " + std::to_string(beam_offset[0]) + ", not 0");
  for (size_t s = 0; s < n; ++s) {
    if (beam_offset[s + 1] < beam_offset[s]) bad_scan(s, "beam_offset decreases");
    if (beam_offset[s + 1] - beam_offset[s] > static_cast<uint64_t>(INT_MAX))
      bad_scan(s, "more than " + std::to_string(INT_MAX) + " beams");
  }
  if (beam_offset[n] != range.size())
    bad_scan(n > 0 ? n - 1 : 0, "beam_offset ends at " + std::to_string(beam_offset[n]) + " but there are " +
                                    std::to_string(range.size()) + " ranges");
}

void ScanBatch::validate_for_mapping() const {
  validate();
  for (size_t s = 0; s < num_scans(); ++s) {
    if (!std::isfinite(x[s]) || !std::isfinite(y[s]) || !std::isfinite(theta[s]))
      bad_scan(s, "the pose is not finite");
    // A NaN or infinite beam angle places every beam of the scan nowhere (or
    // at a wrapped angle): refused where it enters, as a pose is.
    if (!std::isfinite(first_angle[s])) bad_scan(s, "the first beam's angle is not finite");
    if (!std::isfinite(angle_step[s])) bad_scan(s, "the angle step is not finite");
  }
}

const float *ScanBatch::checked_ranges_of(size_t s) const {
  if (s >= num_scans())
    throw Error(ErrorCode::Usage, "scan batch: scan " + std::to_string(s) + " of " + std::to_string(num_scans()));
  validate();
  return ranges_of(s);
}

void ScanBatch::add_scan(double px, double py, double ptheta, double first, double step, const float *r,
                         int n, long source_line) {
  if (n < 0 || (n > 0 && r == nullptr))
    throw Error(ErrorCode::Usage, "scan batch: scan " + std::to_string(num_scans()) + ": " +
                                      (n < 0 ? "a negative beam count" : "no ranges"));
  const size_t before = num_scans();
  try {
    x.push_back(px);
    y.push_back(py);
    theta.push_back(ptheta);
    first_angle.push_back(first);
    angle_step.push_back(step);
    line.push_back(source_line);
    range.insert(range.end(), r, r + n);
    beam_offset.push_back(range.size());
  } catch (...) {
    truncate(before);
    throw;
  }
}

void ScanBatch::append(const ScanBatch &other) {
  other.validate();
  const size_t before = num_scans();
  const uint64_t base = range.size();
  try {
    x.insert(x.end(), other.x.begin(), other.x.end());
    y.insert(y.end(), other.y.begin(), other.y.end());
    theta.insert(theta.end(), other.theta.begin(), other.theta.end());
    first_angle.insert(first_angle.end(), other.first_angle.begin(), other.first_angle.end());
    angle_step.insert(angle_step.end(), other.angle_step.begin(), other.angle_step.end());
    line.insert(line.end(), other.line.begin(), other.line.end());
    range.insert(range.end(), other.range.begin(), other.range.end());
    beam_offset.reserve(beam_offset.size() + other.num_scans());
    for (size_t s = 1; s < other.beam_offset.size(); ++s) beam_offset.push_back(base + other.beam_offset[s]);
  } catch (...) {
    truncate(before);
    throw;
  }
}

void ScanBatch::transform(double tx, double ty, double ta) {
  if (tx == 0 && ty == 0 && ta == 0) return;
  const Pose2 t{tx, ty, ta};
  for (size_t s = 0; s < num_scans(); ++s) {
    const Pose2 p = compose(t, Pose2{x[s], y[s], theta[s]});
    x[s] = p.x;
    y[s] = p.y;
    theta[s] = p.theta;
  }
}

void ScanBatch::truncate(size_t scans) noexcept {
  if (scans >= beam_offset.size()) return;
  x.resize(std::min(x.size(), scans));
  y.resize(std::min(y.size(), scans));
  theta.resize(std::min(theta.size(), scans));
  first_angle.resize(std::min(first_angle.size(), scans));
  angle_step.resize(std::min(angle_step.size(), scans));
  line.resize(std::min(line.size(), scans));
  range.resize(std::min<uint64_t>(range.size(), beam_offset[scans]));
  beam_offset.resize(scans + 1);
}

ScanBatch ScanBatch::select(long first, long count) const & {
  validate();
  const auto [begin, end] = selected(first, count, num_scans());
  ScanBatch out;
  out.x = slice(x, begin, end);
  out.y = slice(y, begin, end);
  out.theta = slice(theta, begin, end);
  out.first_angle = slice(first_angle, begin, end);
  out.angle_step = slice(angle_step, begin, end);
  out.line = slice(line, begin, end);
  out.range = slice(range, beam_offset[begin], beam_offset[end]);
  out.beam_offset = slice(beam_offset, begin, end + 1);
  for (uint64_t &o : out.beam_offset) o -= beam_offset[begin];
  return out;
}

ScanBatch ScanBatch::select(long first, long count) && {
  validate();
  const auto [begin, end] = selected(first, count, num_scans());
  keep(x, begin, end);
  keep(y, begin, end);
  keep(theta, begin, end);
  keep(first_angle, begin, end);
  keep(angle_step, begin, end);
  keep(line, begin, end);
  keep(range, beam_offset[begin], beam_offset[end]);
  keep(beam_offset, begin, end + 1);
  const uint64_t base = beam_offset[0];
  for (uint64_t &o : beam_offset) o -= base;
  return std::move(*this);
}

}  // namespace vasco
