// mapdiff's reports (mapdiff_report.h).
#include "mapdiff_report.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "carmen_compat/image_io.h"
#include "cli_support.h"
#include "picture_legend.h"

namespace mapdiff {
namespace {

// A CARMEN map's first line is its path alone; another format's names it.
std::string format_note(const Input &in) {
  if (in.carmen_map()) return "";
  std::string note = std::string(" (") + in.format->what;
  if (in.format->kind == carmen::MapFormatKind::MapServer) note += "; its origin is the offset";
  if (in.resolution_borrowed) note += "; no resolution of its own: the other map's";
  return note + ")";
}

void print_input(const char *label, const Input &in) {
  std::printf("%s: %s%s\n   size %d x %d cells, resolution %.9g m, offset %s\n   GRIDMAP sha256 %s\n", label,
              in.path.c_str(), format_note(in).c_str(), in.grid.size_x, in.grid.size_y, in.grid.resolution,
              offset_text(in.offset).c_str(), in.sha256.c_str());
}

void print_cell(const carmen::CellDifference &d, const carmen::GridComparison &c) {
  std::printf("  (%d, %d)  A %.9g  B %.9g", d.x, d.y, d.a, d.b);
  if (d.a != -1.0f && d.b != -1.0f) std::printf("  dp %+.9g", double(d.b) - double(d.a));
  if (c.shift_x != 0 || c.shift_y != 0)
    std::printf("  [B's cell (%lld, %lld)]", (long long)(d.x - c.shift_x), (long long)(d.y - c.shift_y));
  std::printf("\n");
}

void print_differences(const carmen::GridComparison &c) {
  const carmen::Agreement &g = c.agreement;
  const uint64_t known_differ = g.cells - g.identical - g.status_differs;  // both -1: equal bits
  if (!c.largest.empty()) {
    std::printf("largest |dp| (known in both; %zu of %llu cells that differ):\n", c.largest.size(),
                (unsigned long long)known_differ);
    for (const auto &d : c.largest) print_cell(d, c);
  }
  if (!c.status_changes.empty()) {
    std::printf("known/unknown changes (first %zu of %llu, -1 = unknown):\n", c.status_changes.size(),
                (unsigned long long)g.status_differs);
    for (const auto &d : c.status_changes) print_cell(d, c);
  }
}

void print_comparison(const carmen::GridComparison &c) {
  if (c.width == 0) {
    std::printf("compared: nothing (the grids do not overlap); outside the overlap %llu cells (%llu known)\n",
                (unsigned long long)c.outside, (unsigned long long)c.outside_known);
    return;
  }
  std::printf("compared: %d x %d cells, A's x %d..%d, y %d..%d; outside the overlap %llu cells (%llu known)\n",
              c.width, c.height, c.x0, c.x0 + c.width - 1, c.y0, c.y0 + c.height - 1,
              (unsigned long long)c.outside, (unsigned long long)c.outside_known);
  std::fputs(c.agreement.table("agreement (A reference, B test):").c_str(), stdout);
  print_differences(c);
}

using cli::json_string;

// JSON has no NaN or infinity.
std::string json_number(double v, const char *format = "%.17g") {
  return std::isfinite(v) ? fmt(format, v) : "null";
}

std::string json_input(const Input &in) {
  std::ostringstream j;
  j << "{\"path\":" << json_string(in.path) << ",\"size_x\":" << in.grid.size_x << ",\"size_y\":" << in.grid.size_y
    << ",\"resolution\":" << json_number(in.grid.resolution) << ",\"offset\":";
  if (in.offset) {
    j << "{\"x\":" << json_number(in.offset->x) << ",\"y\":" << json_number(in.offset->y)
      << ",\"theta\":" << json_number(in.offset->theta) << "}";
  } else {
    j << "null";
  }
  j << ",\"gridmap_sha256\":" << json_string(in.sha256)
    << ",\"format\":" << (in.format != nullptr ? json_string(in.format->extension) : "null") << "}";
  return j.str();
}

std::string json_cells(const std::vector<carmen::CellDifference> &cells) {
  std::string s = "[";
  for (size_t i = 0; i < cells.size(); ++i) {
    const auto &d = cells[i];
    s += (i ? "," : "") + std::string("{\"x\":") + std::to_string(d.x) + ",\"y\":" + std::to_string(d.y) +
         ",\"a\":" + json_number(d.a, "%.9g") + ",\"b\":" + json_number(d.b, "%.9g") + "}";
  }
  return s + "]";
}

std::string json_comparison(const carmen::GridComparison &c) {
  const carmen::Agreement &g = c.agreement;
  std::ostringstream j;
  j << "{\"shift_x\":" << c.shift_x << ",\"shift_y\":" << c.shift_y << ",\"x0\":" << c.x0 << ",\"y0\":" << c.y0
    << ",\"width\":" << c.width << ",\"height\":" << c.height << ",\"outside\":" << c.outside
    << ",\"outside_known\":" << c.outside_known << ",\"cells\":" << g.cells << ",\"both_known\":" << g.both_known
    << ",\"bit_identical\":" << g.identical << ",\"differing_cells\":" << c.differing_cells()
    << ",\"max_abs_dp\":" << json_number(g.max_abs_diff) << ",\"dp_over_0_1\":" << g.large_diffs
    << ",\"status_differs\":" << g.status_differs << ",\"class_agreement\":" << json_number(g.class_agreement())
    << ",\"occupied\":{\"in_a\":" << g.occupied_ref << ",\"agree\":" << g.occupied_agree << "}"
    << ",\"free\":{\"in_a\":" << g.free_ref << ",\"agree\":" << g.free_agree << "}"
    << ",\"unknown\":{\"in_a\":" << g.unknown_ref << ",\"agree\":" << g.unknown_agree << "}"
    << ",\"largest\":" << json_cells(c.largest) << ",\"status_changes\":" << json_cells(c.status_changes) << "}";
  return j.str();
}

bool unknown_cell(float v) { return std::isnan(v) || v < 0.0f; }

}  // namespace

void print_text(const Input &a, const Input &b, bool identical, const Alignment &al,
                const carmen::GridComparison &c, const Verdict &v) {
  print_input("A", a);
  print_input("B", b);
  std::printf("identical: %s (GRIDMAP size, resolution and cells bit for bit)\n", identical ? "yes" : "no");
  if (identical && !same_offset(a.offset, b.offset)) std::printf("note: the OFFSET chunks differ\n");
  std::printf("alignment: %s\n", al.how.c_str());
  if (al.compared) print_comparison(c);
  std::printf("verdict: %s\n", v.line.c_str());
}

void print_json(const Input &a, const Input &b, bool identical, const Alignment &al,
                const carmen::GridComparison &c, const Verdict &v) {
  std::printf("{\"a\":%s,\"b\":%s,\"identical\":%s,\"offsets_equal\":%s,\"alignment\":%s,"
              "\"comparison\":%s,\"verdict\":%s,\"exit\":%d}\n",
              json_input(a).c_str(), json_input(b).c_str(), identical ? "true" : "false",
              same_offset(a.offset, b.offset) ? "true" : "false",
              json_string(al.how).c_str(), al.compared ? json_comparison(c).c_str() : "null",
              json_string(v.line).c_str(), v.exit_status);
}

bool write_picture(const std::string &path, const Input &a, const Input &b, const Alignment &al,
                   const carmen::GridComparison &c, int *width, int *height) {
  const char *why = !al.compared ? "the resolutions differ" : c.width == 0 ? "the grids do not overlap" : nullptr;
  if (why != nullptr) {
    std::fprintf(stderr, "mapdiff: %s: not written: %s\n", path.c_str(), why);
    return false;
  }
  std::vector<uint8_t> rgb = carmen::difference_image_rgb(a.grid, b.grid, c);
  for (int row = 0; row < c.height; ++row) {
    const int y = c.y0 + c.height - 1 - row;  // row 0 is the top: y points up
    for (int x = c.x0; x < c.x0 + c.width; ++x) {
      const float va = a.grid.cells[size_t(x) * size_t(a.grid.size_y) + size_t(y)];
      const float vb = b.grid.cells[size_t((x - c.shift_x) * int64_t(b.grid.size_y) + (y - c.shift_y))];
      if (!unknown_cell(va) || std::memcmp(&va, &vb, sizeof va) != 0) continue;
      uint8_t *p = rgb.data() + (size_t(row) * size_t(c.width) + size_t(x - c.x0)) * 3;
      p[0] = carmen::kPictureUnknown.r;
      p[1] = carmen::kPictureUnknown.g;
      p[2] = carmen::kPictureUnknown.b;
    }
  }
  picture::DiffLegend legend;
  legend.differing = c.differing_cells();
  legend.identical = legend.differing == 0;
  const picture::Canvas canvas = picture::with_diff_legend(c.width, c.height, rgb, legend);
  carmen::write_rgb_png(path, canvas.width, canvas.height, canvas.rgb);
  *width = canvas.width;
  *height = canvas.height;
  return true;
}

}  // namespace mapdiff
