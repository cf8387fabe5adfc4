// _align_maps: vasco::align_maps (align.h) on two Maps, the result as a
// dict; vasco_gpu.align_sessions (align.py) maps the sessions and calls it.
#include <nanobind/nanobind.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "bindings.h"
#include "carmen_compat/error.h"
#include "map_files.h"
#include "vasco_gpu/align.h"

namespace vasco_py {

using namespace nb::literals;

nb::dict align_result_dict(const vasco::AlignResult &r) {
  const auto transform_of = [](const vasco::AlignCandidate &c) { return nb::make_tuple(c.x, c.y, c.theta); };
  nb::dict d;
  d["verdict"] = vasco::align_verdict_name(r.verdict);
  d["reason"] = r.reason;
  d["transform"] = transform_of(r.best);
  d["score"] = r.best.score;
  d["second_transform"] = r.has_second ? nb::object(transform_of(r.second)) : nb::none();
  d["second_score"] = r.has_second ? nb::object(nb::float_(r.second.score)) : nb::none();
  d["overlap"] = r.overlap;
  d["matched"] = r.matched;
  d["moving_points"] = r.moving_points;
  d["rotations"] = r.rotations;
  d["gpu"] = r.gpu;
  return d;
}

vasco::AlignHint align_hint_of(nb::handle h, const std::string &what) {
  std::vector<double> v;
  if (!nb::try_cast(h, v) || (v.size() != 3 && v.size() != 5) || !std::isfinite(v[0]) || !std::isfinite(v[1]) ||
      !std::isfinite(v[2]) || (v.size() == 5 && !(std::isfinite(v[3]) && v[3] >= 0 && std::isfinite(v[4]) && v[4] >= 0)))
    throw carmen::Error(carmen::ErrorCode::Usage,
                        what + ": a hint is (x, y, theta) or (x, y, theta, radius_m, radius_rad): finite numbers, "
                               "the radii 0 or more, not " + std::string(nb::repr(h).c_str()));
  vasco::AlignHint hint;
  hint.x = v[0];
  hint.y = v[1];
  hint.theta = v[2];
  if (v.size() == 5) {  // else AlignHint's radii
    hint.radius_m = v[3];
    hint.radius_rad = v[4];
  }
  return hint;
}

namespace {

// The map's cells copied (align_maps reads them without the GIL while the
// caller's Map stays writable from Python); its origin's heading is left
// out, as the maps' axes are the world's (align.h).
vasco::AlignMap align_map_from(const Map &m) {
  vasco::AlignMap a;
  a.size_x = m.grid.size_x;
  a.size_y = m.grid.size_y;
  a.resolution = m.grid.resolution;
  a.origin_x = m.origin.x;
  a.origin_y = m.origin.y;
  a.cells = m.grid.cells;
  return a;
}

// Where the global search runs: "auto" (the GPU where one is usable), "cpu" or "gpu".
vasco::AlignOptions::Backend search_backend(const std::string &name) {
  if (name == "auto") return vasco::AlignOptions::Backend::Auto;
  if (name == "cpu") return vasco::AlignOptions::Backend::Cpu;
  if (name == "gpu") return vasco::AlignOptions::Backend::Gpu;
  throw carmen::Error(carmen::ErrorCode::Usage, "_align_maps: search is 'auto', 'cpu' or 'gpu', not '" + name + "'");
}

nb::dict align(const Map &reference, const Map &moving, double match_resolution,
               nb::handle hint, double min_score, double ambiguity, int min_matched,
               int threads, const std::string &search, int cuda_device) {
  vasco::AlignOptions o;
  o.backend = search_backend(search);
  o.cuda_device = cuda_device;
  o.match_resolution = match_resolution;
  if (!hint.is_none()) o.hint = align_hint_of(hint, "_align_maps: hint");
  o.min_score = min_score;
  o.ambiguity = ambiguity;
  o.min_matched = min_matched;
  o.threads = threads;
  const vasco::AlignMap ref = align_map_from(reference), mov = align_map_from(moving);
  vasco::AlignResult r;
  {
    nb::gil_scoped_release release;
    r = vasco::align_maps(ref, mov, o);
  }
  return align_result_dict(r);
}

constexpr const char *kAlignDoc =
    "The rigid transform (x, y, theta) that takes ``moving``'s world frame into ``reference``'s\n"
    "(x' = x + cos(theta) mx - sin(theta) my, ...: the convention of Scans.transform and of\n"
    "load_log's ``add``), by a correlative search over every rotation and translation at\n"
    "``match_resolution`` metres, refined to a fraction of that cell (the engine's align_maps).\n"
    "The maps' axes are taken as the world's (an origin's heading is left out).\n\n"
    "``hint``: (x, y, theta) or (x, y, theta, radius_m, radius_rad) searches only near that guess\n"
    "(radii default 1 m and 0.1 rad). ``min_score``: the best candidate's score below which the maps\n"
    "do not overlap; ``ambiguity``: a distinct second candidate scoring at least this fraction of\n"
    "the best makes the result ambiguous; ``min_matched``: fewer moving walls on reference walls\n"
    "means no overlap; ``threads``: 0 for every core; ``search``: where the global search runs,\n"
    "'auto' (the GPU ``cuda_device`` where one is usable; the same candidates either way), 'cpu'\n"
    "or 'gpu' (NoGpuError without one). The GIL is released during the search.\n\n"
    "Returns a dict: 'verdict' ('aligned', 'no_overlap' or 'ambiguous'), 'reason' (why, when not\n"
    "aligned), 'transform' and 'score' of the best candidate, 'second_transform' and\n"
    "'second_score' of the best distinct other one (None when there is none), 'overlap' (the\n"
    "fraction of the moving walls on known reference cells), 'matched' (moving walls on reference\n"
    "walls), 'moving_points', 'rotations', 'gpu' (the search ran on the GPU). Raises UsageError for bad options, BadInputError for a\n"
    "map whose resolution or origin is not finite.";

// The signature for the stubs, its defaults AlignOptions'.
const char *align_signature(const vasco::AlignOptions &d) {
  static const std::string sig = [&d] {
    std::ostringstream s;
    s << "def _align_maps(reference: Map, moving: Map, match_resolution: float = " << d.match_resolution
      << ", hint: typing.Sequence[float] | None = None, min_score: float = " << d.min_score
      << ", ambiguity: float = " << d.ambiguity << ", min_matched: int = " << d.min_matched
      << ", threads: int = " << d.threads << ", search: str = 'auto', cuda_device: int = " << d.cuda_device
      << ") -> dict[str, typing.Any]";
    return s.str();
  }();
  return sig.c_str();
}

}  // namespace

void bind_align(nb::module_ &m) {
  const vasco::AlignOptions defaults;
  m.def("_align_maps", &align, "reference"_a, "moving"_a, "match_resolution"_a = defaults.match_resolution,
        "hint"_a = nb::none(), "min_score"_a = defaults.min_score, "ambiguity"_a = defaults.ambiguity,
        "min_matched"_a = defaults.min_matched, "threads"_a = defaults.threads, "search"_a = "auto",
        "cuda_device"_a = defaults.cuda_device,
        nb::sig(align_signature(defaults)), kAlignDoc);
}

}  // namespace vasco_py
