#include "vasco_gpu/compare.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace vasco {
namespace {

enum class CellClass { Unknown, Free, Occupied, Even };

CellClass class_of(float v) {
  if (v == -1.0f) return CellClass::Unknown;
  if (v > 0.5f) return CellClass::Occupied;
  if (v < 0.5f) return CellClass::Free;
  return CellClass::Even;
}

std::string pct(uint64_t part, uint64_t whole) {
  char buf[64];
  if (whole == 0) return "-";
  std::snprintf(buf, sizeof buf, "%.4f%%", 100.0 * double(part) / double(whole));
  return buf;
}

}  // namespace

Agreement compare_maps(const std::vector<float> &ref, const std::vector<float> &test) {
  if (ref.size() != test.size())
    throw std::invalid_argument("compare_maps: the maps differ in size (" + std::to_string(ref.size()) +
                                " vs " + std::to_string(test.size()) + " cells)");
  Agreement a;
  a.cells = ref.size();
  for (size_t i = 0; i < ref.size(); ++i) {
    const float r = ref[i], t = test[i];
    if (std::memcmp(&r, &t, sizeof r) == 0) ++a.identical;
    const bool rk = r != -1.0f, tk = t != -1.0f;
    if (rk && tk) {
      ++a.both_known;
      const double d = std::fabs(double(r) - double(t));
      if (d > a.max_abs_diff || std::isnan(d)) a.max_abs_diff = std::isnan(d) ? INFINITY : d;
      if (!(d <= 0.1)) ++a.large_diffs;
    } else if (rk != tk) {
      ++a.status_differs;
    }
    const CellClass rc = class_of(r), tc = class_of(t);
    if (rc == tc) ++a.class_agree;
    switch (rc) {
      case CellClass::Occupied:
        ++a.occupied_ref;
        a.occupied_agree += tc == rc;
        break;
      case CellClass::Free:
        ++a.free_ref;
        a.free_agree += tc == rc;
        break;
      case CellClass::Unknown:
        ++a.unknown_ref;
        a.unknown_agree += tc == rc;
        break;
      case CellClass::Even:
        break;
    }
  }
  return a;
}

std::string Agreement::table(const std::string &title) const {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "%s\n"
                "  cells %llu, known in both %llu, bit-identical %s\n"
                "  max |dp| (known in both) %.3g, |dp| > 0.1 in %llu cells (%s of known), known/unknown differs %llu (%s)\n"
                "  class agreement %s: occupied %s of %llu, free %s of %llu, unknown %s of %llu\n",
                title.c_str(), (unsigned long long)cells, (unsigned long long)both_known,
                pct(identical, cells).c_str(), max_abs_diff, (unsigned long long)large_diffs,
                pct(large_diffs, both_known).c_str(), (unsigned long long)status_differs,
                pct(status_differs, cells).c_str(), pct(class_agree, cells).c_str(),
                pct(occupied_agree, occupied_ref).c_str(), (unsigned long long)occupied_ref,
                pct(free_agree, free_ref).c_str(), (unsigned long long)free_ref,
                pct(unknown_agree, unknown_ref).c_str(), (unsigned long long)unknown_ref);
  return buf;
}

}  // namespace vasco
