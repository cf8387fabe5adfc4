// Whether a finished map is worth writing (mapped.h).
#include "vasco_gpu/pipeline/mapped.h"

#include <sstream>

#include "carmen_compat/error.h"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace pipeline {

uint64_t known_cells(const std::vector<float> &cells) {
  uint64_t known = 0;
  for (float v : cells) known += v != -1.0f;
  return known;
}

std::string why_nothing_was_mapped(const ScanBatch &b) {
  uint64_t used = 0;
  for (float r : b.range) used += egrid::is_beam_used(r);
  std::ostringstream m;
  m << "no beam updated any cell: ";
  if (used == 0) {
    m << "every one of the " << b.num_beams() << " ranges of the " << b.num_scans() << " scans mapped is "
      << egrid::kLaserRangeLimit << " m or more, NaN or +inf (CARMEN uses a beam only below "
      << egrid::kLaserRangeLimit << " m)";
  } else {
    m << used << " beams were used, but none reached a cell of the grid";
  }
  return m.str();
}

void check_mapped(const std::vector<float> &cells, const ScanBatch &mapped, const std::string &input) {
  if (known_cells(cells) == 0) throw carmen::FileError(input, why_nothing_was_mapped(mapped));
}

}  // namespace pipeline
}  // namespace vasco
