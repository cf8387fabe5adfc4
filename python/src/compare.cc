// The class Comparison and compare(): DESIGN section 4's agreement table of
// one map against another.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <string>
#include <tuple>
#include <vector>

#include "bindings.h"
#include "map_files.h"
#include "carmen_compat/map_compare.h"

namespace vasco_py {

using namespace nb::literals;
using carmen::GridComparison;

namespace {

constexpr const char *kCompareDoc =
    "Compares map B with map A (the reference): DESIGN section 4's table (class agreement,\n"
    "known/unknown differences, |dp| > 0.1, max |dp|, bit-identical cells). Maps whose origins\n"
    "are a whole number of cells apart are aligned by them (``align=False``: cell (0, 0) on cell\n"
    "(0, 0)). ``top``: how many of the largest differences to keep in ``.largest``. A map holding a\n"
    "cell that is not -1 or a probability (NaN among them) raises BadInputError (a ValueError).";

// Every count of a comparison as a dict (Comparison.to_dict).
nb::dict comparison_dict(const GridComparison &c) {
  const carmen::Agreement &a = c.agreement;
  nb::dict d;
  d["cells"] = a.cells;
  d["both_known"] = a.both_known;
  d["status_differs"] = a.status_differs;
  d["identical"] = a.identical;
  d["max_abs_diff"] = a.max_abs_diff;
  d["large_diffs"] = a.large_diffs;
  d["class_agree"] = a.class_agree;
  d["class_agreement"] = a.class_agreement();
  d["occupied_ref"] = a.occupied_ref;
  d["occupied_agree"] = a.occupied_agree;
  d["free_ref"] = a.free_ref;
  d["free_agree"] = a.free_agree;
  d["unknown_ref"] = a.unknown_ref;
  d["unknown_agree"] = a.unknown_agree;
  d["shift_x"] = c.shift_x;
  d["shift_y"] = c.shift_y;
  d["outside"] = c.outside;
  d["outside_known"] = c.outside_known;
  d["same_cells"] = c.same_cells();
  return d;
}

// Comparison's agreement counts over the overlap.
void bind_comparison_counts(nb::class_<GridComparison> &cls) {
  cls.def_prop_ro("cells", [](const GridComparison &c) { return c.agreement.cells; }, "Cells compared (the overlap).")
      .def_prop_ro("both_known", [](const GridComparison &c) { return c.agreement.both_known; })
      .def_prop_ro("status_differs", [](const GridComparison &c) { return c.agreement.status_differs; },
                   "Known in one map, unknown in the other.")
      .def_prop_ro("identical", [](const GridComparison &c) { return c.agreement.identical; }, "Bit-identical cells.")
      .def_prop_ro("max_abs_diff", [](const GridComparison &c) { return c.agreement.max_abs_diff; },
                   "max |a - b| over cells known in both.")
      .def_prop_ro("large_diffs", [](const GridComparison &c) { return c.agreement.large_diffs; },
                   "Cells known in both with |a - b| > 0.1.")
      .def_prop_ro("class_agree", [](const GridComparison &c) { return c.agreement.class_agree; })
      .def_prop_ro("class_agreement", [](const GridComparison &c) { return c.agreement.class_agreement(); },
                   "Share of cells in the same class (occupied p > 0.5, free p < 0.5, unknown).")
      .def_prop_ro("occupied_ref", [](const GridComparison &c) { return c.agreement.occupied_ref; })
      .def_prop_ro("occupied_agree", [](const GridComparison &c) { return c.agreement.occupied_agree; })
      .def_prop_ro("free_ref", [](const GridComparison &c) { return c.agreement.free_ref; })
      .def_prop_ro("free_agree", [](const GridComparison &c) { return c.agreement.free_agree; })
      .def_prop_ro("unknown_ref", [](const GridComparison &c) { return c.agreement.unknown_ref; })
      .def_prop_ro("unknown_agree", [](const GridComparison &c) { return c.agreement.unknown_agree; });
}

// The largest differences as (x, y, a, b) tuples.
std::vector<std::tuple<int, int, float, float>> largest(const GridComparison &c) {
  std::vector<std::tuple<int, int, float, float>> v;
  for (const auto &d : c.largest) v.emplace_back(d.x, d.y, d.a, d.b);
  return v;
}

// Comparison's alignment, the cells outside the overlap and the largest differences.
void bind_comparison_extent(nb::class_<GridComparison> &cls) {
  cls.def_ro("shift_x", &GridComparison::shift_x, "B's cell (bx, by) lies on A's (bx + shift_x, by + shift_y).")
      .def_ro("shift_y", &GridComparison::shift_y)
      .def_ro("outside", &GridComparison::outside, "Cells of A or B outside the overlap (they differ).")
      .def_ro("outside_known", &GridComparison::outside_known)
      .def_prop_ro("differing_cells", &GridComparison::differing_cells)
      .def_prop_ro("same_cells", &GridComparison::same_cells, "Bit-identical over the overlap and nothing outside it.")
      .def_prop_ro("largest", &largest,
                   "Up to `top` cells known in both whose bits differ, largest |a - b| first: (x, y, a, b).");
}

// Comparison's table, dict, str and repr.
void bind_comparison_methods(nb::class_<GridComparison> &cls) {
  cls.def("table", [](const GridComparison &c, const std::string &title) { return c.agreement.table(title); },
          "title"_a = "B against A", "The table as text.")
      .def("to_dict", &comparison_dict, "Every count as a dict.")
      .def("__str__", [](const GridComparison &c) { return c.agreement.table("B against A"); })
      .def("__repr__", [](const GridComparison &c) {
        const carmen::Agreement &a = c.agreement;
        return nb::str("Comparison(cells={}, class_agreement={:.6f}, status_differs={}, large_diffs={}, "
                       "max_abs_diff={}, identical={}, outside={})")
            .format(a.cells, a.class_agreement(), a.status_differs, a.large_diffs, a.max_abs_diff, a.identical,
                    c.outside);
      });
}

GridComparison compare(const Map &a, const Map &b, bool align, size_t top) {
  nb::gil_scoped_release release;
  check_cells(a, "compare: map a");
  check_cells(b, "compare: map b");
  int64_t sx = 0, sy = 0;
  if (align && a.has_origin && b.has_origin) {
    std::string why;
    if (!carmen::offset_shift(a.origin, b.origin, a.grid.resolution, &sx, &sy, &why)) sx = sy = 0;
  }
  return carmen::compare_grids(a.grid, b.grid, sx, sy, top);
}

}  // namespace

void bind_compare(nb::module_ &m) {
  nb::class_<GridComparison> cls(
      m, "Comparison", "DESIGN section 4's agreement table of map B against map A (the reference), over their overlap.");
  bind_comparison_counts(cls);
  bind_comparison_extent(cls);
  bind_comparison_methods(cls);
  m.def("compare", &compare, "a"_a, "b"_a, "align"_a = true, "top"_a = 0, kCompareDoc);
}

}  // namespace vasco_py
