// The whole mapping pipeline on scans made from the input: cpu_threads (3
// threads) and a Mapper fed the scans in two pieces, then rendered again,
// must give cpu_double's grid bit for bit, and finish must work on it.
#include <cstdlib>
#include <cstring>
#include <vector>

#include "fuzz_support.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/renderer.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/mapper.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz::Bytes b(data, size);
  vasco::MapperParams p;
  p.resolution = b.in(0.05, 0.5);
  p.range_max = b.in(0.5, 8.0);
  p.range_sure = b.in(0.0, p.range_max);
  p.wall_size = b.in(0.0, 0.5);
  p.p_occ = b.in(0.51, 0.99);
  p.p_emp = b.in(0.01, 0.49);
  p.downsample = 1 + b.u8() % 4;
  vasco::ScanBatch batch;
  const int scans = 1 + b.u8() % 12;
  for (int s = 0; s < scans; ++s) {
    const int n = b.u8() % 40;
    std::vector<float> r(static_cast<size_t>(n));
    for (float &v : r) v = b.u8() < 40 ? b.f32() : static_cast<float>(b.in(-1, 12));
    batch.add_scan(b.in(-15, 15), b.in(-15, 15), b.in(-7, 7), b.in(-3.2, 0), b.in(0, 0.2), r.data(), n, s + 1);
  }
  const vasco::GridGeometry geo = vasco::size_grid(batch, p);
  const std::vector<float> ref = vasco::render_grid(*vasco::make_renderer("cpu_double"), batch, p, geo);
  vasco::BackendOptions three;
  three.threads = 3;
  const std::vector<float> thr = vasco::render_grid(*vasco::make_renderer("cpu_threads", three), batch, p, geo);
  if (ref.size() != thr.size() || (!ref.empty() && std::memcmp(ref.data(), thr.data(), ref.size() * sizeof(float)) != 0))
    std::abort();
  vasco::Mapper m(p, "cpu_threads", three);
  const size_t half = batch.num_scans() / 2;
  m.insert(batch.select(0, static_cast<long>(half)));
  m.insert(batch.select(static_cast<long>(half), -1));
  // Grown with a margin, a cell position may round unlike in the PROTOCOL
  // frame (mapper.hpp): render(poses()) renders in that frame itself.
  m.render(m.poses());
  const std::vector<float> ses = m.read();
  if (ses.size() != ref.size() || (!ref.empty() && std::memcmp(ref.data(), ses.data(), ref.size() * sizeof(float)) != 0))
    std::abort();
  m.finish();
  return 0;
}
