// Grids past 2^30 cells (issue 25 item 4): no fixed cell cap, a grid is
// limited by the memory it needs (the session's host budget; a GPU's free
// memory), and every cell index is 64-bit. Nothing here allocates a large
// grid: the sizing and the budget are checked on a renderer that keeps no
// cells, and the index arithmetic on virtual grids of more than 2^32 cells
// (the walker's indices, the finish's helpers) against the same beams and
// blocks in a small grid.
#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "beam_updates.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/internal/finish_math.h"
#include "vasco_gpu/internal/oracle.h"
#include "vasco_gpu/internal/sensor_params.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/renderer.h"

namespace vasco {
namespace {

constexpr uint64_t kTwo30 = uint64_t(1) << 30, kTwo31 = uint64_t(1) << 31;

// One scan of 181 beams at (x, y), all 3 m long.
void add_scan(ScanBatch &b, double x, double y, long line) {
  std::vector<float> r(181, 3.0f);
  b.add_scan(x, y, 0.0, -M_PI / 2, M_PI / 180, r.data(), 181, line);
}

// A robot that starts in a corner of a `side` m square site and drives to
// the opposite corner: the PROTOCOL frame is centred on the first pose, so
// the grid spans twice the site in each axis.
ScanBatch corner_to_corner(double side) {
  ScanBatch b;
  add_scan(b, 0, 0, 1);
  add_scan(b, side / 2, side / 2, 2);
  add_scan(b, side, side, 3);
  return b;
}

// A renderer that keeps no cells (a host grid as far as the budget knows:
// 4 bytes a cell): it records the grids it is asked for, so that the
// session's sizing and budget can be checked on grids of billions of cells.
class VirtualRenderer : public Renderer {
 public:
  std::string name() const override { return "virtual"; }
  void reset(const GridGeometry &geo, const MapperParams &) override {
    last = geo;
    ++resets;
  }
  void apply(const ScanBatch &, size_t first, size_t last_scan, MapStats *stats) override {
    applied += last_scan - first;
    if (stats != nullptr) *stats = MapStats{};
  }
  FinishedMap finish(int, int) override { return FinishedMap{}; }
  std::vector<float> read(const GridWindow &w) override {
    return std::vector<float>(static_cast<size_t>(w.width) * static_cast<size_t>(w.height), -1.0f);
  }
  RendererTraits traits() const override { return {true, false, 4, 0}; }

  GridGeometry last;
  int resets = 0;
  size_t applied = 0;
};

std::string message_of(const std::function<void()> &f, ErrorCode *code = nullptr) {
  try {
    f();
  } catch (const Error &e) {
    if (code != nullptr) *code = e.code();
    return e.what();
  }
  return "";
}

TEST(LargeGrid, TheProtocolFrameOfALargeSiteIsSizedPast2To31Cells) {
  // 600 m x 600 m from a corner at 2.5 cm: 48,802 cells a side, 2.38e9 cells.
  const ScanBatch b = corner_to_corner(600);
  const GridGeometry g = size_grid(b, MapperParams{});
  EXPECT_EQ(g.size_x, 2 * static_cast<int>(std::ceil((600 + (10.0 + 0.025)) / 0.025)) + 2);
  EXPECT_EQ(g.size_x, g.size_y);
  EXPECT_GT(g.num_cells(), kTwo31);
  // A side beyond kMaxGridSide is still refused while the frame is sized.
  ScanBatch far = b;
  add_scan(far, 3e7, 0, 9);
  ErrorCode code = ErrorCode::Internal;
  const std::string m = message_of([&] { size_grid(far, MapperParams{}); }, &code);
  EXPECT_EQ(code, ErrorCode::TooLarge);
  EXPECT_NE(m.find("each side at most 2147482624 cells"), std::string::npos) << m;
  EXPECT_NE(m.find("to line 9 in x"), std::string::npos) << m;
}

TEST(LargeGrid, AGridPast2To31CellsIsAcceptedWhenTheBudgetAllowsIt) {
  const ScanBatch b = corner_to_corner(600);
  const GridGeometry g = size_grid(b, MapperParams{});
  // 4 bytes a cell, the finish's 8 / 4^2 at vasco_downsample 4, 68 a beam.
  const double need = 4.5 * static_cast<double>(g.num_cells()) + 68.0 * static_cast<double>(b.num_beams());
  BackendOptions o;
  o.max_memory_bytes = static_cast<uint64_t>(need) + 1;
  auto renderer = std::make_unique<VirtualRenderer>();
  VirtualRenderer *r = renderer.get();
  Mapper m(MapperParams{}, std::move(renderer), o);
  EXPECT_DOUBLE_EQ(m.memory_need(g, b.num_beams()), need);
  m.insert(b);
  EXPECT_EQ(r->resets, 1);
  EXPECT_EQ(r->applied, 3u);
  EXPECT_EQ(r->last.size_x, g.size_x);
  EXPECT_EQ(r->last.num_cells(), g.num_cells());
  EXPECT_GT(m.grid_frame().num_cells(), kTwo31);
  EXPECT_DOUBLE_EQ(m.memory_need(), need);
  // A budget below the need is refused, keeping the old one.
  ErrorCode code = ErrorCode::Internal;
  message_of([&] { m.set_max_memory_bytes(o.max_memory_bytes - 1024); }, &code);
  EXPECT_EQ(code, ErrorCode::OutOfMemory);
}

TEST(LargeGrid, OverTheBudgetTheRefusalNamesTheNeed) {
  const ScanBatch b = corner_to_corner(500);  // 1.66e9 cells: past 2^30, a 2 GiB budget holds 4.8e8
  const GridGeometry g = size_grid(b, MapperParams{});
  ASSERT_GT(g.num_cells(), kTwo30);
  BackendOptions o;
  o.budget_hint = "--max-memory MiB";
  auto renderer = std::make_unique<VirtualRenderer>();
  VirtualRenderer *r = renderer.get();
  Mapper m(MapperParams{}, std::move(renderer), o);
  ErrorCode code = ErrorCode::Internal;
  const std::string msg = message_of([&] { m.insert(b); }, &code);
  EXPECT_EQ(code, ErrorCode::OutOfMemory) << msg;
  const double need_mib = m.memory_need(g, b.num_beams()) / (1 << 20);
  const std::string shown = std::to_string(static_cast<long long>(std::ceil(need_mib)));
  EXPECT_NE(msg.find("the map needs about " + shown + " MiB"), std::string::npos) << msg;
  EXPECT_NE(msg.find(std::to_string(g.size_x) + " x " + std::to_string(g.size_y) + " = " +
                     std::to_string(g.num_cells()) + " cells"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("4.5 bytes a cell on virtual"), std::string::npos) << msg;
  EXPECT_NE(msg.find("more than the budget of 2048 MiB: raise it (--max-memory MiB)"), std::string::npos) << msg;
  EXPECT_EQ(r->resets, 0) << "refused before the renderer was asked for the grid";
  EXPECT_EQ(m.num_scans(), 0u);
  // With no budget it goes through.
  m.set_max_memory_bytes(0);
  m.insert(b);
  EXPECT_EQ(r->last.num_cells(), g.num_cells());
}

TEST(LargeGrid, AFixedFramePast2To31CellsIsCheckedAgainstTheBudgetAtItsFirstInsert) {
  GridGeometry frame;
  frame.size_x = frame.size_y = 50000;  // 2.5e9 cells (it was refused past 2^30 cells)
  frame.resolution = MapperParams{}.resolution;
  Mapper m(MapperParams{}, frame, "cpu_double");  // nothing allocated yet
  ScanBatch b;
  add_scan(b, 0, 0, 1);
  ErrorCode code = ErrorCode::Internal;
  const std::string msg = message_of([&] { m.insert(b); }, &code);
  EXPECT_EQ(code, ErrorCode::OutOfMemory) << msg;
  EXPECT_NE(msg.find("50000 x 50000 = 2500000000 cells"), std::string::npos) << msg;
  GridGeometry wide = frame;
  wide.size_x = kMaxGridSide + 1;
  code = ErrorCode::Internal;
  message_of([&] { Mapper w(MapperParams{}, wide, "cpu_double"); }, &code);
  EXPECT_EQ(code, ErrorCode::TooLarge);
}

TEST(LargeGrid, EachBackendStatesItsHostBytesACell) {
  EXPECT_EQ(make_renderer("cpu_double")->traits().host_bytes_per_cell, 4.0);
  EXPECT_EQ(make_renderer("cpu_threads")->traits().host_bytes_per_cell, 4.0);
  EXPECT_EQ(make_renderer("cpu_float")->traits().host_bytes_per_cell, 8.0);  // the grid and a float scratch
  Mapper f(MapperParams{}, "cpu_float");
  GridGeometry g;
  g.size_x = g.size_y = 40000;
  EXPECT_DOUBLE_EQ(f.memory_need(g, 0), 8.5 * 1.6e9);
}

TEST(LargeGrid, CellIndicesAre64Bit) {
  EXPECT_EQ(egrid::cell_index(46341, 46340, 46341), int64_t(46341) * 46341 + 46340);  // past 2^31
  EXPECT_EQ(egrid::cell_index(70000, 5, 70000), int64_t(4900000005));                 // past 2^32
  const int side = kMaxGridSide;
  EXPECT_EQ(egrid::cell_index(side - 1, side - 1, side), int64_t(side) * side - 1);  // the largest grid's last cell
}

// The oracle's updates of one beam (oracle::trace_beam's walk, sensor model
// and odds update) on a virtual grid: cells kept by index in a map, absent
// ones unknown.
using SparseGrid = std::unordered_map<int64_t, float>;

void oracle_beam(SparseGrid &cells, int size_x, int size_y, int x1, int y1, int x2, int y2, double range,
                 const MapperParams &p) {
  const egrid::SensorModel<double> model = sensor_model_of(p);
  egrid::walk_beam_cells(x1, y1, x2, y2, p.table_size(), size_x, size_y, [&](int cx, int cy, int i, int j) {
    double prob;
    if (!egrid::sensor_model(model, oracle::table_distance(i, j, p.table_size(), nullptr, p.resolution), range,
                             &prob))
      return false;
    const int64_t c = egrid::cell_index(cx, cy, size_y);
    const auto it = cells.find(c);
    cells[c] = egrid::odds_update(it == cells.end() ? egrid::kUnknown : it->second, model.prior, prob);
    return true;
  });
}

// The exact CPU backends' walker (beam_updates::collect, cpu_double's and
// cpu_threads' pass 1) on a grid of 70000 x 70000 cells (4.9e9, past 2^32):
// the cells and factors it lists for beams near the far corner are the
// oracle's there, by 64-bit index, and the same beams' in a small grid
// shifted by a whole number of cells.
TEST(LargeGrid, TheExactWalkerAddressesAGridPast2To32Cells) {
  const MapperParams p;
  const beam_updates::Evidence evidence(sensor_model_of(p), p.resolution, p.table_size());
  const int big = 70000, small = 1000;
  const int x_shift = big - small - 100, y_shift = big - small - 50;  // the small grid's cell (0, 0) in the big one
  struct Beam {
    int x1, y1, x2, y2;
    double range;
  };
  const Beam beams[] = {{500, 500, 800, 300, 7.4}, {520, 490, 430, 895, 9.9}, {500, 500, 200, 210, 3.1},
                        {990, 10, 999, 400, 8.2}, {500, 500, 500, 500, 0.0}};
  beam_updates::BeamUpdates big_updates(p.table_size()), small_updates(p.table_size());
  for (const Beam &b : beams) {
    SCOPED_TRACE(std::to_string(b.x1) + "," + std::to_string(b.y1) + " -> " + std::to_string(b.x2) + "," +
                 std::to_string(b.y2));
    ASSERT_TRUE(beam_updates::walkable(p.table_size(), b.x1, b.y1, b.x2, b.y2));
    beam_updates::collect(evidence, {0, big, 0, big}, big, b.x1 + x_shift, b.y1 + y_shift, b.x2 + x_shift,
                          b.y2 + y_shift, b.range, &big_updates);
    beam_updates::collect(evidence, {0, small, 0, small}, small, b.x1, b.y1, b.x2, b.y2, b.range, &small_updates);
    ASSERT_EQ(big_updates.count, small_updates.count);
    ASSERT_GT(big_updates.count, 0);
    EXPECT_EQ(big_updates.n_free, small_updates.n_free);
    EXPECT_EQ(big_updates.n_const, small_updates.n_const);
    SparseGrid oracle;
    oracle_beam(oracle, big, big, b.x1 + x_shift, b.y1 + y_shift, b.x2 + x_shift, b.y2 + y_shift, b.range, p);
    EXPECT_EQ(oracle.size(), static_cast<size_t>(big_updates.count));
    for (int k = 0; k < big_updates.count; ++k) {
      const int64_t s = small_updates.index[k];
      const int64_t want = egrid::cell_index(static_cast<int>(s / small) + x_shift, static_cast<int>(s % small) + y_shift, big);
      ASSERT_EQ(big_updates.index[k], want) << k;
      EXPECT_GT(big_updates.index[k], int64_t(kTwo31) * 2) << k;  // past 2^32
      if (k >= big_updates.n_const) {
        EXPECT_EQ(big_updates.factor[k], small_updates.factor[k]) << k;
      }
      // The oracle updated this cell once from unknown: what pass 2 makes of it.
      const double f = k < big_updates.n_free    ? evidence.free_factor()
                       : k < big_updates.n_const ? evidence.occupied_factor()
                                                 : big_updates.factor[k];
      ASSERT_EQ(oracle.count(want), 1u) << k;
      EXPECT_EQ(egrid::odds_apply(egrid::kUnknown, p.p_prior, f), oracle[want]) << k;
    }
  }
}

// finish_math.h's helpers (the host's finish and the GPU's) at block
// coordinates whose cells lie past 2^32.
TEST(LargeGrid, TheFinishAddressesBlocksPast2To32Cells) {
  const int size_y = 70000, ds = 4, bx = 17000, by = 16000;  // cells x in [68000, 68004): index ~4.76e9
  std::vector<int64_t> asked;
  const auto cell_at = [&](int64_t c) {
    asked.push_back(c);
    return c == egrid::cell_index(bx * ds + 2, by * ds + 1, size_y) ? 0.75f : -1.0f;
  };
  const finish::BlockMean m = finish::block_mean(cell_at, size_y, ds, bx, by);
  EXPECT_TRUE(m.known);
  EXPECT_EQ(m.value, 0.75f);
  ASSERT_EQ(asked.size(), static_cast<size_t>(ds * ds));
  for (int i = 0; i < ds; ++i)
    for (int j = 0; j < ds; ++j)
      EXPECT_EQ(asked[static_cast<size_t>(i * ds + j)], egrid::cell_index(bx * ds + i, by * ds + j, size_y));
  const finish::Blocks blocks = finish::blocks_of(size_y, size_y, ds);
  EXPECT_EQ(blocks.count(), int64_t(17500) * 17500);
  finish::Crop crop;
  crop.min_x = 16000;
  crop.min_y = 3;
  crop.size_x = 1500;
  crop.size_y = 17000;
  EXPECT_EQ(finish::cropped_block(crop, blocks, 1499, 16996), int64_t(17499) * 17500 + 16999);
  EXPECT_EQ(crop.count(), int64_t(1500) * 17000);
}

// The finish of a grid read a strip of columns at a time (how a grown
// session finishes frame()'s window of its grid) gives finish_grid's bytes
// whatever the strip.
TEST(LargeGrid, FinishingByColumnStripsEqualsFinishingTheWholeGrid) {
  const int sx = 203, sy = 157;
  std::vector<float> cells(static_cast<size_t>(sx) * sy, -1.0f);
  uint32_t state = 12345;
  for (float &c : cells) {
    state = state * 1664525u + 1013904223u;
    if ((state >> 28) < 5) c = static_cast<float>((state >> 8) & 0xffff) / 65536.0f;
  }
  for (int ds : {1, 3, 4, 50}) {
    const FinishedMap want = finish_grid(cells.data(), sx, sy, 0.05, ds, 2);
    for (uint64_t strip : {uint64_t(1), uint64_t(sy) * ds * 3, uint64_t(sy) * 37, uint64_t(1) << 30}) {
      int reads = 0, columns = 0;
      const ColumnStrip read = [&](int x0, int width) {
        EXPECT_EQ(x0, columns);
        EXPECT_EQ(width % ds, 0);
        ++reads;
        columns += width;
        return cells.data() + egrid::cell_index(x0, 0, sy);
      };
      const FinishedMap got = finish_grid_by_columns(read, sx, sy, 0.05, ds, 2, strip);
      EXPECT_EQ(got.cells, want.cells) << ds << " " << strip;
      EXPECT_EQ(got.size_x, want.size_x);
      EXPECT_EQ(got.min_y, want.min_y);
      EXPECT_EQ(columns, sx / ds * ds) << "every block column once, the remainder dropped";
      if (strip == 1) {
        EXPECT_EQ(reads, sx / ds);
      }
    }
  }
}

}  // namespace
}  // namespace vasco
