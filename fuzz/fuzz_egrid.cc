// CARMEN's egrid.h C API driven by the input: parameters, a few scans with
// any float ranges (NaN, inf, negative), clear, the general update, finish.
#include <cmath>
#include <vector>

#include "carmen/egrid.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz::Bytes b(data, size);
  const int sx = 1 + b.u8() % 200, sy = 1 + b.u8() % 200;
  const double res = b.in(0.01, 1.0), prior = b.in(0.05, 0.95);
  const double occ = b.in(0.05, 0.999), emp = b.in(0.001, 0.95);
  const double sure = b.in(0.0, 5.0), max = sure + b.in(0.0, 5.0), wall = b.in(0.0, 1.0);
  evidence_grid g;
  carmen_mapper_initialize_evidence_grid(&g, sx, sy, res, b.in(-10, 10), prior, occ, emp, 0.99, sure, max, wall);
  const int scans = b.u8() % 8;
  for (int s = 0; s < scans && b.left() > 0; ++s) {
    const double x = b.in(-20, 20), y = b.in(-20, 20), t = b.in(-100, 100);
    const int n = b.u8() % 64;
    std::vector<float> r(static_cast<size_t>(n)), a(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      r[i] = b.f32();
      a[i] = static_cast<float>(b.in(-4, 4));
    }
    switch (b.u8() % 8) {
      case 0: carmen_mapper_clear_evidence_grid(&g); break;
      case 1: carmen_mapper_update_evidence_grid_general(&g, x, y, t, n, r.data(), a.data(), 0.0, 0.0); break;
      default: carmen_mapper_update_evidence_grid(&g, x, y, t, n, r.data(), b.in(-0.1, 0.1), b.in(-4, 4));
    }
  }
  const int downsample = 1 + b.u8() % 5, border = b.u8() % 30;
  // A grid that mapped nothing stops the process where CARMEN's finish dies
  // (egrid.h): the one case finish is not called for.
  if (!vasco_egrid_finish_would_stop(&g, downsample, border)) carmen_mapper_finish_evidence_grid(&g, downsample, border);
  carmen_mapper_free_evidence_grid(&g);
  return 0;
}
