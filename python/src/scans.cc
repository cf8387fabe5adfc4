// The class Scans (vasco::ScanBatch): laser scans from NumPy arrays, and
// views of their memory. The arrays that say where each scan's beams lie
// (beam_offsets) are read-only views, so Python cannot make a batch whose
// offsets point outside its ranges; every batch is still checked where it
// enters the engine (ScanBatch::validate: select, ranges_of, beam_counts,
// and the Mapper's insert), as a batch filled by other means might disagree.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "arrays.h"
#include "bindings.h"
#include "carmen_compat/error.h"
#include "carmen_compat/log_reader.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco_py {

using namespace nb::literals;
using carmen::Error;
using carmen::ErrorCode;
using vasco::ScanBatch;

namespace {

// beam_counts as whole numbers in [0, kMaxCount]: a fraction (181.7) is an
// error, not truncated.
std::vector<int> beam_counts_from(nb::handle obj, size_t n) {
  auto counts = as_array<double>(obj, "float64", "beam_counts", 1);
  if (counts.shape(0) != n)
    throw Error(ErrorCode::BadInput, "beam_counts: " + std::to_string(counts.shape(0)) + " counts for " +
                                         std::to_string(n) + " poses");
  std::vector<int> out(n);
  for (size_t s = 0; s < n; ++s) {
    const double c = counts.data()[s];
    if (!(c >= 0 && c <= carmen::kMaxCount && c == std::floor(c))) {
      std::ostringstream os;
      os << "beam_counts[" << s << "] = " << c << ": must be a whole number between 0 and " << carmen::kMaxCount;
      throw Error(ErrorCode::BadInput, os.str());
    }
    out[s] = static_cast<int>(c);
  }
  return out;
}

// first_angle or angle_step: a number for every scan, or one per scan.
std::vector<double> per_scan(nb::handle obj, const char *what, size_t n) {
  static nb::handle ndim = nb::object(nb::module_::import_("numpy").attr("ndim")).release();
  if (nb::cast<int>(ndim(obj)) == 0)
    return std::vector<double>(n, nb::cast<double>(nb::module_::import_("builtins").attr("float")(obj)));
  auto arr = nb::cast<nb::ndarray<const double, nb::c_contig, nb::device::cpu>>(contiguous(obj, "float64"));
  if (arr.ndim() != 1 || arr.shape(0) != n)
    throw Error(ErrorCode::BadInput, std::string(what) + ": expected a number or one value per scan (" +
                                         std::to_string(n) + ")");
  return std::vector<double>(arr.data(), arr.data() + n);
}

ScanBatch make_scans(nb::handle poses_obj, nb::handle ranges_obj, nb::handle counts_obj, nb::handle first_obj,
                     nb::handle step_obj) {
  auto poses = xy_theta_rows(poses_obj, "poses", "scan");
  const size_t n = poses.shape(0);
  auto ranges = as_array<float>(ranges_obj, "float32", "ranges", 1);
  const std::vector<int> counts = beam_counts_from(counts_obj, n);
  const std::vector<double> first = per_scan(first_obj, "first_angle", n);
  const std::vector<double> step = per_scan(step_obj, "angle_step", n);
  uint64_t total = 0;
  for (int c : counts) total += static_cast<uint64_t>(c);
  if (total != ranges.shape(0))
    throw Error(ErrorCode::BadInput, "ranges: " + std::to_string(ranges.shape(0)) +
                                         " ranges, but the beam counts add up to " + std::to_string(total));
  ScanBatch b;
  const float *r = ranges.data();
  const double *p = poses.data();
  for (size_t s = 0; s < n; ++s) {
    b.add_scan(p[3 * s], p[3 * s + 1], p[3 * s + 2], first[s], step[s], r, counts[s], static_cast<long>(s + 1));
    r += counts[s];
  }
  return b;
}

Array1<float> ranges_of(nb::handle_t<ScanBatch> self, long s) {
  ScanBatch &b = nb::cast<ScanBatch &>(self);
  if (s < 0) s += static_cast<long>(b.num_scans());
  if (s < 0 || static_cast<size_t>(s) >= b.num_scans()) throw nb::index_error("scan index out of range");
  float *first = const_cast<float *>(b.checked_ranges_of(static_cast<size_t>(s)));
  return counted_view1(first, static_cast<size_t>(b.beams_in(s)), &b, self);
}

constexpr const char *kScansDoc =
    "Laser scans, stored as CARMEN reads them: a pose (x, y, theta of the laser, float64) and beam\n"
    "geometry (first_angle relative to theta, angle_step) per scan, ranges as float32, all scans'\n"
    "beams concatenated.\n\n"
    "``ranges``, ``x``, ``y``, ``theta``, ``first_angle``, ``angle_step`` and ``lines`` are writable\n"
    "NumPy views of the object's memory (they keep it alive); ``beam_offsets`` is a read-only view\n"
    "(which beams are whose must stay consistent with the ranges); ``poses`` and ``beam_counts``\n"
    "are new arrays.";

void bind_scans_constructor(nb::class_<ScanBatch> &cls) {
  cls.def(
         "__init__",
         [](ScanBatch *self, nb::handle poses, nb::handle ranges, nb::handle beam_counts, nb::handle first_angle,
            nb::handle angle_step) { new (self) ScanBatch(make_scans(poses, ranges, beam_counts, first_angle, angle_step)); },
         "poses"_a, "ranges"_a, "beam_counts"_a, "first_angle"_a, "angle_step"_a,
         nb::sig("def __init__(self, poses: numpy.typing.ArrayLike, ranges: numpy.typing.ArrayLike, "
                 "beam_counts: numpy.typing.ArrayLike, first_angle: float | numpy.typing.ArrayLike, "
                 "angle_step: float | numpy.typing.ArrayLike) -> None"),
         "Scans from arrays (copied): poses (n, 3), ranges (sum of beam_counts,), beam_counts (n,) whole\n"
         "numbers, first_angle and angle_step a number or one value per scan (radians; CARMEN's 181-beam\n"
         "SICK: first_angle=-pi/2, angle_step=pi/180).")
      .def("__len__", &ScanBatch::num_scans)
      .def_prop_ro("num_beams", &ScanBatch::num_beams);
}

// A property that is a writable view of the member `field`.
template <typename T>
void view_property(nb::class_<ScanBatch> &cls, const char *name, std::vector<T> ScanBatch::*field, const char *doc) {
  cls.def_prop_ro(
      name,
      [field](nb::handle_t<ScanBatch> self) {
        ScanBatch &b = nb::cast<ScanBatch &>(self);
        return counted_view1((b.*field).data(), (b.*field).size(), &b, self);
      },
      nb::rv_policy::reference, doc);
}

void bind_scans_views(nb::class_<ScanBatch> &cls) {
  view_property(cls, "ranges", &ScanBatch::range, "All beams' ranges, float32, scan after scan (a view).");
  view_property(cls, "x", &ScanBatch::x, "Laser x per scan (a view).");
  view_property(cls, "y", &ScanBatch::y, "Laser y per scan (a view).");
  view_property(cls, "theta", &ScanBatch::theta, "Laser heading per scan (a view).");
  view_property(cls, "first_angle", &ScanBatch::first_angle, "Angle of beam 0 relative to theta, per scan (a view).");
  view_property(cls, "angle_step", &ScanBatch::angle_step, "Angle added after every beam, per scan (a view).");
  view_property(cls, "lines", &ScanBatch::line, "Line of each scan in its log (a view).");
  cls.def_prop_ro(
      "beam_offsets",
      [](nb::handle_t<ScanBatch> self) {
        const ScanBatch &b = nb::cast<ScanBatch &>(self);
        return counted_view1(b.beam_offset.data(), b.beam_offset.size(), &b, self);
      },
      nb::rv_policy::reference,
      "Scan s owns ranges[beam_offsets[s]:beam_offsets[s + 1]] (uint64, n + 1 entries, a read-only view).");
}

void bind_scans_methods(nb::class_<ScanBatch> &cls) {
  cls.def_prop_ro(
         "poses", [](const ScanBatch &b) { return poses_of(b); }, nb::rv_policy::reference,
         "(n, 3) float64 array of (x, y, theta): a new array.")
      .def_prop_ro(
          "beam_counts",
          [](const ScanBatch &b) {
            b.validate();
            std::vector<int64_t> c(b.num_scans());
            for (size_t s = 0; s < c.size(); ++s) c[s] = b.beams_in(s);
            return owned(std::move(c), {c.size()});
          },
          nb::rv_policy::reference, "Beams per scan (int64): a new array.")
      .def("ranges_of", &ranges_of, "s"_a, nb::rv_policy::reference, "The ranges of scan s (a view).")
      .def(
          "transform",
          [](ScanBatch &b, double x, double y, double theta) {
            if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(theta))
              throw Error(ErrorCode::BadInput, "transform: x, y and theta must be finite");
            b.validate();
            b.transform(x, y, theta);
          },
          "x"_a, "y"_a, "theta"_a,
          "Takes every pose into another frame, in place: x' = x0 + cos(a) x - sin(a) y, y' = y0 + sin(a) x\n"
          "+ cos(a) y, theta' = theta + a for the transform (x0, y0, a) of this session into the shared frame\n"
          "of several (the identity changes no bit).")
      .def(
          "extend",
          [](ScanBatch &b, const ScanBatch &other) {
            if (const long n = live_views(&b))
              throw Error(ErrorCode::State,
                          "Scans.extend: " + std::to_string(n) + " NumPy view" + (n == 1 ? " is" : "s are") +
                              " alive of these scans' arrays (ranges, x, ..., ranges_of, or Log.ranges): extending "
                              "moves the memory they show; delete them first, or extend a copy (scans.select(0))");
            b.append(other);
          },
          "other"_a,
          "Appends other's scans (copied) after this batch's: several sessions into one batch. Refused\n"
          "(RuntimeError) while a NumPy view of this batch's arrays is alive: it would point at moved memory.")
      .def("select", [](const ScanBatch &b, long first, long count) { return b.select(first, count); }, "first"_a, "count"_a = -1,
           "Scans [first, first + count) as new Scans (count -1: to the end), clipped to the batch.")
      .def("__repr__", [](const ScanBatch &b) {
        return nb::str("Scans({} scans, {} beams)").format(b.num_scans(), b.num_beams());
      });
}

}  // namespace

nb::ndarray<nb::numpy, double> poses_of(const ScanBatch &b) {
  const size_t n = b.num_scans();
  std::vector<double> p(3 * n);
  for (size_t s = 0; s < n; ++s) {
    p[3 * s] = b.x[s];
    p[3 * s + 1] = b.y[s];
    p[3 * s + 2] = b.theta[s];
  }
  return owned(std::move(p), {n, 3});
}

void bind_scans(nb::module_ &m) {
  nb::class_<ScanBatch> cls(m, "Scans", kScansDoc);
  bind_scans_constructor(cls);
  bind_scans_views(cls);
  bind_scans_methods(cls);
}

}  // namespace vasco_py
