#include "align_refine.h"

#include <cmath>

#include "align_score.h"

namespace vasco {
namespace align_detail {

double continuous_sum(const RefineInput &in, const Placement &at) {
  const Points &p = *in.points;
  return sum_bilinear(in.field->value.data(), in.field->size_x, in.field->size_y, in.h, p.x.data(), p.y.data(),
                      static_cast<int>(p.size()), in.c_x, in.c_y, at.theta, at.tx, at.ty);
}

// Why a pattern search and not Gauss-Newton: the field is piecewise bilinear
// with a kink at every cell edge, and a 2-cell reach; the six probes of a
// pattern search need no gradient and cannot step past the peak's basin.
Placement refine(const RefineInput &in, const Placement &start, double theta_step, double *sum) {
  Placement at = start;
  double best = continuous_sum(in, at);
  double dt = in.h / 2, da = theta_step / 2;
  const double finest = in.h / 64;
  for (int iteration = 0; iteration < 400 && dt >= finest; ++iteration) {
    const Placement probes[6] = {{at.theta + da, at.tx, at.ty}, {at.theta - da, at.tx, at.ty},
                                 {at.theta, at.tx + dt, at.ty}, {at.theta, at.tx - dt, at.ty},
                                 {at.theta, at.tx, at.ty + dt}, {at.theta, at.tx, at.ty - dt}};
    int chosen = -1;
    for (int i = 0; i < 6; ++i) {
      const double s = continuous_sum(in, probes[i]);
      if (s > best) {
        best = s;
        chosen = i;
      }
    }
    if (chosen >= 0) {
      at = probes[chosen];
    } else {
      dt /= 2;
      da /= 2;
    }
  }
  *sum = best;
  return at;
}

void count_overlap(const RefineInput &in, const Placement &at, int *on_known, int *on_walls) {
  const Points &p = *in.points;
  const Field &f = *in.field;
  const double c = std::cos(at.theta), s = std::sin(at.theta);
  *on_known = 0;
  *on_walls = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const double dx = p.x[i] - in.c_x, dy = p.y[i] - in.c_y;
    const double x = std::floor((c * dx - s * dy + at.tx) / in.h), y = std::floor((s * dx + c * dy + at.ty) / in.h);
    if (!(x >= 0 && y >= 0 && x < f.size_x && y < f.size_y)) continue;
    const size_t cell = static_cast<size_t>(x) * f.size_y + static_cast<size_t>(y);
    *on_known += f.known[cell] != 0;
    *on_walls += f.value[cell] >= 0.5f;
  }
}

}  // namespace align_detail
}  // namespace vasco
