// The live node's Path onto its stored scans (ros.live_map.LiveMap.repose) by
// vasco_gpu/pose_series.h and internal/se2.h, in one call instead of dozens
// of NumPy calls (each costing a live node several times what it costs in a
// loop).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/tuple.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "arrays.h"
#include "bindings.h"
#include "carmen_compat/error.h"
#include "vasco_gpu/internal/se2.h"
#include "vasco_gpu/pose_series.h"

namespace vasco_py {

using namespace nb::literals;
using vasco::Pose2;
using vasco::SeriesPlace;

namespace {

static_assert(sizeof(Pose2) == 3 * sizeof(double), "Pose2 read as rows of (x, y, theta)");

using Rows = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

[[noreturn]] void bad(const std::string &what) { throw carmen::Error(carmen::ErrorCode::BadInput, what); }

// The rows of an (n, 3) array (xy_theta_rows) as Pose2s; a row count other than n is bad input.
const Pose2 *as_poses(const nb::ndarray<const double, nb::c_contig, nb::device::cpu> &a, size_t n, const char *what) {
  if (a.shape(0) != n) bad(std::string(what) + ": " + std::to_string(a.shape(0)) + " rows for " + std::to_string(n) + " stamps");
  return reinterpret_cast<const Pose2 *>(a.data());
}

// The base pose composed with a laser's mount; the base unchanged for a zero mount.
Pose2 on_mount(const Pose2 &base, const Pose2 &mount) {
  if (mount.x == 0 && mount.y == 0 && mount.theta == 0) return base;
  return vasco::compose(base, mount);
}

nb::tuple repose(nb::handle path_ns_obj, nb::handle path_poses_obj, nb::handle scan_ns_obj, nb::handle mounts_obj,
                 Rows laser, int64_t max_gap_ns) {
  const auto path_ns = as_array<int64_t>(path_ns_obj, "int64", "path stamps", 1);
  const auto path_poses = xy_theta_rows(path_poses_obj, "path poses", "pose");
  const auto scan_ns = as_array<int64_t>(scan_ns_obj, "int64", "scan stamps", 1);
  const auto mounts = xy_theta_rows(mounts_obj, "mounts", "scan");
  const size_t k = path_ns.shape(0), n = scan_ns.shape(0);
  const Pose2 *given = as_poses(path_poses, k, "path poses");
  const Pose2 *mount = as_poses(mounts, n, "mounts");
  if (laser.shape(0) != n || laser.shape(1) != 3) bad("laser poses: expected (" + std::to_string(n) + ", 3)");
  Pose2 *out = reinterpret_cast<Pose2 *>(laser.data());
  size_t moved = 0, outside = 0, in_gap = 0, no_mount = 0;
  {
    nb::gil_scoped_release release;
    std::vector<int64_t> stamps(path_ns.data(), path_ns.data() + k);
    std::vector<Pose2> poses(given, given + k);
    vasco::sort_series(stamps, poses);
    const vasco::PoseSeriesView series{stamps.data(), poses.data(), stamps.size()};
    for (size_t i = 0; i < n; ++i) {
      Pose2 base;
      const SeriesPlace place = vasco::pose_at_stamp(series, scan_ns.data()[i], max_gap_ns, base);
      const Pose2 &m = mount[i];
      if (place == SeriesPlace::Outside) {
        ++outside;
      } else if (!(std::isfinite(m.x) && std::isfinite(m.y) && std::isfinite(m.theta))) {
        ++no_mount;  // within the span: counted whatever the gap
      } else if (place == SeriesPlace::InGap) {
        ++in_gap;
      } else {
        out[i] = on_mount(base, m);
        ++moved;
      }
    }
  }
  return nb::make_tuple(moved, outside, in_gap, no_mount);
}

}  // namespace

void bind_pose_series(nb::module_ &m) {
  m.def("_repose", &repose, "path_ns"_a, "path_poses"_a, "scan_ns"_a, "mounts"_a, "laser_poses"_a, "max_gap_ns"_a,
        "A Path of base poses (any order; of repeated stamps the last) onto stored scans: each scan\n"
        "whose stamp lies in the Path's span, with a finite mount, between poses at most max_gap_ns\n"
        "apart (or on one), gets laser_poses[i] = its base pose composed with mounts[i] (in place).\n"
        "Returns (moved, outside, in_gap, no_mount).");
}

}  // namespace vasco_py
