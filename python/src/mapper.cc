// The class Mapper: one mapping session (vasco::Mapper).
//
// Threads and the GIL. Calls that map (insert, render, finish) run through
// run_interruptible: on a worker thread, the GIL released, Ctrl-C seen while
// they run. Calls on one Mapper are serialised by the session lock, which is
// only ever taken with the GIL released, so a thread waiting for it never
// stops the others. What len, frame, params, last_stats, renders and repr
// report comes from a snapshot published after every call, read under a lock
// that is held only to copy it: they answer at once, even during an insert.
// start_over (a new session on the same backend) takes the session lock with
// the GIL released too, so it lands between two calls, never inside one.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>

#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "arrays.h"
#include "bindings.h"
#include "carmen_compat/error.h"
#include "inputs.h"
#include "interruptible.h"
#include "map_files.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/backend_choice.h"
#include "vasco_gpu/map_output.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/option_schema.h"
#include "vasco_gpu/pipeline/session_align.h"
#include "vasco_gpu/pipeline/mapped.h"

namespace vasco_py {

using namespace nb::literals;
using carmen::Error;
using carmen::ErrorCode;

namespace {

static_assert(sizeof(vasco::Pose) == 3 * sizeof(double), "Pose must be three packed doubles");


// What the state properties report, as of the end of the last call.
struct Snapshot {
  size_t num_scans = 0;
  vasco::GridGeometry frame;
  vasco::MapStats stats;
  size_t renders = 0;
  vasco::MapperParams params;  // start_over replaces them
  std::string backend;         // "auto" until an auto session chooses (its first insert)
  std::optional<vasco::AutoChoice> auto_choice;
};

struct Session {
  std::unique_ptr<vasco::Mapper> mapper;
  std::mutex lock;  // serialises calls on mapper; taken only with the GIL released
  std::mutex snapshot_lock;  // held only to copy `snapshot`
  Snapshot snapshot;

  // Publishes the mapper's state; call with `lock` held.
  void publish() {
    Snapshot s{mapper->num_scans(), mapper->frame(), mapper->last_stats(), mapper->renders(), mapper->params(),
               mapper->backend_name(), std::nullopt};
    if (mapper->auto_choice() != nullptr) s.auto_choice = *mapper->auto_choice();
    std::lock_guard<std::mutex> g(snapshot_lock);
    snapshot = s;
  }
  Snapshot state() {
    std::lock_guard<std::mutex> g(snapshot_lock);
    return snapshot;
  }
  // Runs fn(mapper) under the session lock and publishes the state after
  // it, failed or not. Without the GIL.
  template <typename Fn>
  auto locked(Fn &&fn) -> decltype(fn(*mapper)) {
    std::lock_guard<std::mutex> g(lock);
    struct Publish {
      Session *s;
      ~Publish() { s->publish(); }
    } publish_after{this};
    return fn(*mapper);
  }
};

// The keywords checked by the session's option table (option_schema.h).
const vasco::OptionSpec &session_row(const char *name) {
  return vasco::option_row(vasco::session_option_table(), name);
}

vasco::CudaMode cuda_mode_of(const std::string &mode) {
  vasco::check_option_choice(session_row("cuda_mode"), mode, "cuda_mode");
  return mode == "exact" ? vasco::CudaMode::Exact : vasco::CudaMode::Float;
}

vasco::BackendOptions backend_options(const std::string &backend, const std::optional<std::string> &cuda_mode,
                                      int threads, int cuda_device, uint64_t max_memory_bytes, int expected_renders,
                                      std::string *name) {
  vasco::BackendOptions o;
  if (cuda_mode) o.cuda_mode = cuda_mode_of(*cuda_mode);
  vasco::check_option_number(session_row("threads"), threads, "threads");
  vasco::check_option_number(session_row("expected_renders"), expected_renders, "expected_renders");
  o.threads = threads;
  o.cuda_device = cuda_device;
  o.max_memory_bytes = max_memory_bytes;
  o.expected_renders = expected_renders;
  o.budget_hint = "Mapper(max_memory_bytes=...)";
  const vasco::CudaMode asked = o.cuda_mode;
  *name = vasco::resolve_backend_name(backend, &o);
  if (cuda_mode && o.cuda_mode != asked)
    throw Error(ErrorCode::Usage, "backend '" + backend + "' contradicts cuda_mode='" + *cuda_mode + "'");
  return o;
}

nb::dict stats_dict(const vasco::MapStats &s) {
  nb::dict d;
  d["scans"] = s.scans;
  d["beams_used"] = s.beams_used;
  d["beams_skipped"] = s.beams_skipped;
  d["cell_updates"] = s.cell_updates;
  d["prep_s"] = s.prep_s;
  d["upload_s"] = s.upload_s;
  d["map_s"] = s.map_s;
  d["download_s"] = s.download_s;
  return d;
}

std::vector<vasco::Pose> poses_from(nb::handle obj) {
  auto a = xy_theta_rows(obj, "poses", "scan");
  std::vector<vasco::Pose> p(a.shape(0));
  const double *d = a.data();
  for (size_t s = 0; s < p.size(); ++s) p[s] = {d[3 * s], d[3 * s + 1], d[3 * s + 2]};
  return p;
}

// frame_centre=(x, y): the fixed frame's centre, in metres (GridGeometry::centre_given).
void set_frame_centre(nb::handle centre, std::optional<vasco::GridGeometry> *frame) {
  if (centre.is_none()) return;
  if (!*frame)
    throw nb::type_error("Mapper: frame_centre=(x, y) centres a fixed frame: give frame=Frame(...) with it");
  const auto not_a_pair = [&] {
    return nb::type_error(("Mapper: frame_centre must be two numbers (x, y) in metres, not " +
                           std::string(nb::repr(centre).c_str()))
                              .c_str());
  };
  if (PyUnicode_Check(centre.ptr()) || PyBytes_Check(centre.ptr()) || !PySequence_Check(centre.ptr()) ||
      nb::len(centre) != 2)
    throw not_a_pair();
  double xy[2];
  for (size_t i = 0; i < 2; ++i)
    if (!nb::try_cast<double>(centre[i], xy[i])) throw not_a_pair();
  if (!std::isfinite(xy[0]) || !std::isfinite(xy[1]))
    throw nb::value_error(
        ("Mapper: frame_centre must be finite, not " + std::string(nb::repr(centre).c_str())).c_str());
  (*frame)->x0 = xy[0];
  (*frame)->y0 = xy[1];
  (*frame)->centre_given = true;
}

void init_mapper(Session *self, std::optional<vasco::MapperParams> params, const std::string &backend,
                 std::optional<std::string> cuda_mode, int threads, std::optional<vasco::GridGeometry> frame,
                 int cuda_device, uint64_t max_memory_bytes, int expected_renders, nb::handle frame_centre) {
  set_frame_centre(frame_centre, &frame);
  std::string name;
  const vasco::BackendOptions o =
      backend_options(backend, cuda_mode, threads, cuda_device, max_memory_bytes, expected_renders, &name);
  const vasco::MapperParams p = params ? *params : vasco::MapperParams();
  std::unique_ptr<vasco::Mapper> mp;
  {
    nb::gil_scoped_release release;
    p.validate();
    mp = frame ? std::make_unique<vasco::Mapper>(p, *frame, name, o) : std::make_unique<vasco::Mapper>(p, name, o);
  }
  auto *s = new (self) Session();
  s->mapper = std::move(mp);
  s->publish();
}

// Where insert(scans, transform="auto") puts the scans: aligned to the grid
// the session holds (its finish()), as log2map's --add B@auto aligns B to
// the sessions before it. A refusal throws before anything is stored.
vasco::Pose2 aligned_placement(vasco::Mapper &m, const vasco::ScanBatch &scans, const vasco::SessionInput &how,
                               vasco::AlignResult *found) {
  const std::string call = how.hint ? "Mapper.insert(transform=(\"auto\", hint))" : "Mapper.insert(transform=\"auto\")";
  if (m.num_scans() == 0)
    throw Error(ErrorCode::State, call + ": the session holds no scans to align to; the first scans set the shared "
                                         "frame (insert them without a transform)");
  *found = vasco::align_session_to(vasco::align_map_of(m.finish(), m.frame()), scans, m.params(), how.hint, 0);
  if (found->verdict != vasco::AlignVerdict::Aligned)
    throw Error(ErrorCode::BadInput, call + ": the scans are not aligned to the session's " +
                                         std::to_string(m.num_scans()) + " scans: " +
                                         vasco::align_candidates_text(*found) +
                                         "; give transform=(x, y, theta), or (\"auto\", (x, y, theta)) near it");
  return {found->best.x, found->best.y, found->best.theta};
}

// insert(scans, transform): None stores the scans as they are; (x, y,
// theta), "auto" or ("auto", hint) store them taken into the session's
// frame (Scans.transform's convention), the caller's Scans unchanged.
// Returns the alignment's dict for "auto", else None.
nb::object insert(Session &s, const vasco::ScanBatch &scans, nb::handle transform) {
  if (transform.is_none()) {
    run_interruptible([&] { s.locked([&](vasco::Mapper &m) { m.insert(scans); }); });
    return nb::none();
  }
  vasco::SessionInput how;
  session_transform_of(transform, how, "Mapper.insert");
  std::optional<vasco::AlignResult> found;
  run_interruptible([&] {
    s.locked([&](vasco::Mapper &m) {
      vasco::AlignResult r;
      const vasco::Pose2 t = how.auto_transform ? aligned_placement(m, scans, how, &r) : how.transform;
      vasco::ScanBatch moved = scans;
      moved.transform(t.x, t.y, t.theta);
      m.insert(std::move(moved));
      if (how.auto_transform) found = std::move(r);
    });
  });
  if (!found) return nb::none();
  nb::dict d = align_result_dict(*found);
  d["aligned"] = "auto";
  return d;
}

void render(Session &s, nb::handle poses) {
  const std::vector<vasco::Pose> p = poses_from(poses);
  run_interruptible([&] { s.locked([&](vasco::Mapper &m) { m.render(p); }); });
}

// finish's downsample and border: those given, else the params in force when
// the call runs (read under the lock: a start_over from another thread lands
// before or after, never between).
std::pair<int, int> finish_arguments(const vasco::Mapper &m, std::optional<int> downsample, std::optional<int> border) {
  return {downsample ? *downsample : static_cast<int>(m.params().downsample),
          border ? *border : static_cast<int>(m.params().border)};
}

Map finish(Session &s, std::optional<int> downsample, std::optional<int> border) {
  return run_interruptible([&] {
    return s.locked([&](vasco::Mapper &m) {
      const auto [ds, b] = finish_arguments(m, downsample, border);
      return map_from_finished(m.finish(ds, b), m.frame());
    });
  });
}

// finish as OccupancyGrid data (Mapper::finish_occupancy): ((size_x, size_y, resolution,
// origin), data). The data goes into `out` (a writable buffer of bytes) when the map has its
// size, else into new bytes.
nb::tuple finish_occupancy_grid(Session &s, const std::string &mode, double free_thresh, double occupied_thresh,
                                nb::handle out, std::optional<int> downsample, std::optional<int> border) {
  const carmen::OccupancyValues values = occupancy_values(mode, free_thresh, occupied_thresh);
  std::optional<WritableBytes> given;
  if (!out.is_none()) given.emplace(out, "Mapper._finish_occupancy_grid: out");
  std::vector<int8_t> scratch;  // when out is not given or has another size
  bool into_out = false;
  const vasco::OccupancyOut where = [&](size_t n) {
    into_out = given && given->size() == n;
    if (into_out) return given->data();
    scratch.resize(n);
    return scratch.data();
  };
  const auto [f, origin] = run_interruptible([&] {
    return s.locked([&](vasco::Mapper &m) {
      const auto [ds, b] = finish_arguments(m, downsample, border);
      vasco::FinishedMap map = m.finish_occupancy(values, where, ds, b);
      const carmen::GlobalOffset at = vasco::world_origin(map, m.frame());
      return std::make_pair(std::move(map), at);
    });
  });
  nb::object data = into_out ? nb::borrow(out)
                             : nb::steal(PyBytes_FromStringAndSize(reinterpret_cast<const char *>(scratch.data()),
                                                                   Py_ssize_t(scratch.size())));
  if (!data.is_valid()) throw nb::python_error();
  return nb::make_tuple(nb::make_tuple(f.size_x, f.size_y, f.resolution, nb::make_tuple(origin.x, origin.y, origin.theta)),
                        data);
}

void start_over(Session &s, const vasco::MapperParams &params) {
  const vasco::MapperParams p = params;  // copied while the GIL guards the Params object
  nb::gil_scoped_release release;
  s.locked([&](vasco::Mapper &m) { m.start_over(p); });
}

nb::ndarray<nb::numpy, float> read(Session &s, std::optional<std::tuple<int, int, int, int>> window) {
  std::vector<float> v;
  vasco::GridWindow gw;
  {
    nb::gil_scoped_release release;
    s.locked([&](vasco::Mapper &m) {
      gw = window ? vasco::GridWindow{std::get<0>(*window), std::get<1>(*window), std::get<2>(*window),
                                      std::get<3>(*window)}
                  : vasco::GridWindow{0, 0, m.frame().size_x, m.frame().size_y};
      v = m.read(gw);
    });
  }
  return owned(std::move(v), {static_cast<size_t>(gw.width), static_cast<size_t>(gw.height)});
}

nb::ndarray<nb::numpy, double> poses(Session &s) {
  std::vector<vasco::Pose> p;
  {
    nb::gil_scoped_release release;
    p = s.locked([](vasco::Mapper &m) { return m.poses(); });
  }
  std::vector<double> flat(3 * p.size());
  for (size_t i = 0; i < p.size(); ++i) {
    flat[3 * i] = p[i].x;
    flat[3 * i + 1] = p[i].y;
    flat[3 * i + 2] = p[i].theta;
  }
  return owned(std::move(flat), {p.size(), 3});
}

// A copy of every stored scan's ranges: the node keeps none of its own (a
// large site's scans stored twice cost 0.65 bytes a map cell).
nb::ndarray<nb::numpy, float> stored_ranges(Session &s) {
  std::vector<float> r;
  {
    nb::gil_scoped_release release;
    r = s.locked([](vasco::Mapper &m) { return m.scans().range; });
  }
  const size_t n = r.size();
  return owned(std::move(r), {n});
}

nb::dict auto_choice_dict(const vasco::AutoChoice &c) {
  nb::dict d;
  d["cell_updates"] = c.cell_updates;
  d["cores"] = c.cores;
  d["expected_renders"] = c.renders;
  d["cpu_s"] = c.cpu_s;
  d["gpu_s"] = c.gpu_s;
  d["gpu_faster"] = c.gpu_faster;
  d["gpu_usable"] = c.gpu_usable;
  d["backend"] = c.backend;
  d["why"] = c.why;
  return d;
}

nb::dict auto_choice(double cell_updates, int threads, int expected_renders, std::optional<bool> gpu_usable,
                     int cuda_device) {
  vasco::BackendOptions o;
  o.threads = threads;
  o.cuda_device = cuda_device;
  const int cores = vasco::auto_cores(o);
  std::string why;
  bool usable = false;
  if (gpu_usable) {
    usable = *gpu_usable;
    why = "no usable GPU (given)";
  } else {
    nb::gil_scoped_release release;
    usable = vasco::gpu_usable(cuda_device, &why);
  }
  return auto_choice_dict(vasco::choose_auto(cell_updates, cores, expected_renders, usable, why));
}

void bind_auto_choice(nb::module_ &m) {
  m.def("estimated_cell_updates", &vasco::estimated_cell_updates, "scans"_a, "params"_a,
        "The cells the used beams of ``scans`` cross with ``params`` (each traced from the laser to\n"
        "min(range + wall, range_max), one cell a resolution step): the workload auto weighs.");
  m.def("auto_choice", &auto_choice, "cell_updates"_a, "threads"_a = 0, "expected_renders"_a = 1,
        "gpu_usable"_a = nb::none(), "cuda_device"_a = 0,
        "What backend='auto' runs for ``cell_updates`` (estimated_cell_updates) mapped\n"
        "``expected_renders`` times (0: a workload without end) on cpu_threads' ``threads`` (0: every\n"
        "core) or the GPU: the rule log2map --backend auto and Mapper(backend='auto') share. A dict\n"
        "with 'cell_updates', 'cores', 'expected_renders', 'cpu_s', 'gpu_s', 'gpu_faster',\n"
        "'gpu_usable', 'backend' ('cuda' or 'cpu_threads') and 'why' (log2map's note).\n"
        "``gpu_usable``: True or False, or None to ask about ``cuda_device`` (which starts CUDA).");
}

constexpr const char *kMapperDoc =
    "A mapping session (DESIGN section 7): scans stored once (on the GPU for ``cuda``), poses\n"
    "replaceable as a whole, the evidence grid kept between calls.\n\n"
    "    mapper = vasco_gpu.Mapper(params, backend='cuda', cuda_mode='exact')\n"
    "    mapper.insert(log.scans)          # new scans continue the grid\n"
    "    mapper.render(new_poses)          # a loop closure: every pose moved, recomputed\n"
    "    m = mapper.finish()               # CARMEN's finish -> Map\n\n"
    "Backends: cpu_double (CARMEN's routine, bit-identical), cpu_threads (the same bytes on every\n"
    "core), cpu_float (single precision), cuda (cuda_mode 'float', the default, or 'exact':\n"
    "CARMEN's bytes), auto (cuda or cpu_threads, by the cost model log2map --backend auto uses);\n"
    "'cuda_exact' and\n"
    "'cuda_float' name the CUDA modes too. The GIL is released while the session maps; calls on\n"
    "one Mapper from several threads are serialised, and len, frame, last_stats, renders and\n"
    "repr answer at once even while another thread maps (as of the end of the last call).\n\n"
    "Ctrl-C during insert, render or finish runs Python's handler at once; a call cannot stop\n"
    "half-way, so KeyboardInterrupt is raised when the call has finished: the session then holds\n"
    "what the call did (the scans inserted, the poses rendered), or, if the call failed, what it\n"
    "held before.";

constexpr const char *kMapperInitDoc =
    "A session with ``params`` (vasco's defaults when None) on ``backend``.\n\n"
    "cuda_mode: 'float' (default) or 'exact'. threads: cpu_threads' threads (0: all cores; at\n"
    "most 1024, as log2map's --threads). frame: a fixed Frame (cells outside it are skipped, as\n"
    "CARMEN does) instead of the PROTOCOL frame, which grows as scans arrive; centred on the first\n"
    "scan, as CARMEN's egrid.c, or on frame_centre=(x, y) (metres, finite; only with frame): then\n"
    "the grid lies there with the world's axes whatever the scans' poses (its lower-left corner at\n"
    "x - size_x * resolution / 2, y - size_y * resolution / 2; theta_offset moves nothing), through\n"
    "inserts, render and start_over. A frame read from a session centred so keeps its centre.\n"
    "max_memory_bytes:\n"
    "host memory the session may use (0: no limit). expected_renders: what auto weighs the GPU's\n"
    "start-up against (vasco_gpu.auto_choice): 1, the default, chooses at the first insert by its\n"
    "scans, as log2map --backend auto does for a log; more, a session that will render its scans\n"
    "again; 0, a workload without end (a live map): the GPU when one is usable, chosen now.\n"
    "Raises ValueError for bad parameters, an unknown backend or a frame_centre not finite,\n"
    "TypeError for a frame_centre that is not two numbers or comes without frame, RuntimeError\n"
    "when the backend cannot run here (e.g. cuda without a GPU).";

// The constructor's signature for the stubs: frame_centre is taken as any
// object and checked by set_frame_centre, for messages clearer than a cast's.
const char *mapper_init_signature() {
  static const std::string sig =
      "def __init__(self, params: Params | None = None, backend: str = 'cpu_double', cuda_mode: str | None = None, "
      "threads: int = 0, frame: Frame | None = None, cuda_device: int = 0, max_memory_bytes: int = " +
      std::to_string(vasco::kDefaultMaxMemoryBytes) +
      ", expected_renders: int = 1, frame_centre: tuple[float, float] | None = None) -> None";
  return sig.c_str();
}

void bind_mapper_constructor(nb::class_<Session> &cls) {
  cls.def("__init__", &init_mapper, "params"_a = nb::none(), "backend"_a = "cpu_double", "cuda_mode"_a = nb::none(),
          "threads"_a = 0, "frame"_a = nb::none(), "cuda_device"_a = 0,
          "max_memory_bytes"_a = vasco::kDefaultMaxMemoryBytes, "expected_renders"_a = 1,
          "frame_centre"_a = nb::none(), nb::sig(mapper_init_signature()), kMapperInitDoc);
}

void bind_mapper_mapping(nb::class_<Session> &cls) {
  cls.def("insert", &insert, "scans"_a, "transform"_a = nb::none(),
          nb::sig("def insert(self, scans: Scans, transform: tuple[float, float, float] | str | "
                  "tuple[str, typing.Sequence[float]] | None = None) -> dict[str, typing.Any] | None"),
          "Stores ``scans`` after those stored and applies them to the grid (exact backends: the bytes\n"
          "of mapping everything at once). Raises BadInputError (a ValueError) for a batch whose\n"
          "arrays disagree, RuntimeError when the frame would be too large or the session would\n"
          "exceed max_memory_bytes (nothing is stored then).\n\n"
          "``transform`` places a session recorded in another frame (another run, another robot):\n"
          "(x, y, theta) takes its poses into this session's frame first (as Scans.transform; the\n"
          "caller's Scans unchanged); ``\"auto\"`` finds that transform by aligning the scans' map to\n"
          "the session's grid (as log2map's ``--add B@auto``: mapped on the CPU, matched at 0.1 m or\n"
          "the map cell where coarser), ``(\"auto\", (x, y, theta[, radius_m, radius_rad]))`` searches\n"
          "near a guess. With \"auto\" it returns the alignment's dict (as align_sessions': 'transform',\n"
          "'score', 'second_transform', ...); a session holding no scans yet raises StateError, scans\n"
          "that do not overlap the grid or fit two places raise BadInputError naming the best\n"
          "candidates, and nothing is stored.")
      .def("render", &render, "poses"_a, nb::sig("def render(self, poses: numpy.typing.ArrayLike) -> None"),
           "New poses for every stored scan, an (n, 3) float64 array of (x, y, theta), and the grid\n"
           "recomputed from scratch with them (only the poses travel to the GPU).")
      .def("finish", &finish, "downsample"_a = nb::none(), "border"_a = nb::none(),
           "CARMEN's finish of the current grid (block means, crop to the known area plus ``border``),\n"
           "on the GPU for cuda; ``downsample``/``border`` default to the params'. Returns a Map whose\n"
           "cells are moved, not copied, out of the session.")
      .def("_finish_occupancy_grid", &finish_occupancy_grid, "mode"_a, "free_thresh"_a, "occupied_thresh"_a,
           "out"_a = nb::none(), "downsample"_a = nb::none(), "border"_a = nb::none(),
           "finish as nav_msgs/OccupancyGrid data (the ROS node's /map): ((size_x, size_y, resolution,\n"
           "origin), data), data by ``mode`` and the thresholds as Map's _occupancy_grid_data makes it\n"
           "(converted on the GPU for cuda: a byte a cell comes back), written into ``out`` (a writable\n"
           "buffer, returned) when it has the map's size, else new bytes.")
      .def("start_over", &start_over, "params"_a,
           "A new session on the same backend: the stored scans, the frame and the grid dropped,\n"
           "``params`` in force (validated first: a refusal raises ValueError and changes nothing; a\n"
           "fixed frame stays, and its resolution must equal the new one). The backend is kept, with\n"
           "its CUDA context and GPU scratch memory, so that many logs mapped in turn pay its start-up\n"
           "once (map_logs does this). ``renders`` keeps counting.");
}

void bind_mapper_arrays(nb::class_<Session> &cls) {
  cls.def("read", &read, "window"_a = nb::none(),
          nb::sig("def read(self, window: tuple[int, int, int, int] | None = None) -> "
                  "numpy.typing.NDArray[numpy.float32]"),
          "The full-resolution grid, or the window (x0, y0, width, height) of it, as a (width, height)\n"
          "float32 array, x-major (a new array that owns the cells C++ returned; no further copy).")
      .def_prop_ro("poses", &poses, nb::rv_policy::reference, "The stored scans' poses, (n, 3) float64 (a new array).")
      .def("_stored_ranges", &stored_ranges, "The stored scans' ranges, float32, scan after scan (a new array).");
}

void bind_mapper_state(nb::class_<Session> &cls) {
  cls.def("__len__", [](Session &s) { return s.state().num_scans; })
      .def_prop_ro("num_scans", [](Session &s) { return s.state().num_scans; }, "Scans stored.")
      .def_prop_ro("frame", [](Session &s) { return s.state().frame; },
                   "The current frame (a copy); a fixed frame at frame_centre has centre_given True.")
      .def_prop_ro("params", [](Session &s) { return s.state().params; },
                   "The session's parameters (a copy; start_over replaces them).")
      .def_prop_ro("backend", [](Session &s) { return s.state().backend; },
                   "The backend's name (cpu_double, cpu_threads, cpu_float, cuda_float, cuda_exact); 'auto'\n"
                   "while an auto session has not chosen (until its first insert).")
      .def_prop_ro(
          "auto_choice",
          [](Session &s) -> nb::object {
            const Snapshot st = s.state();
            return st.auto_choice ? nb::object(auto_choice_dict(*st.auto_choice)) : nb::none();
          },
          nb::sig("def auto_choice(self) -> dict[str, typing.Any] | None"),
          "What backend='auto' chose and why (a dict as vasco_gpu.auto_choice returns); None for\n"
          "another backend and while auto has not chosen.")
      .def_prop_ro("last_stats", [](Session &s) { return stats_dict(s.state().stats); },
                   "Counts and phase times of the last insert or render.")
      .def_prop_ro("renders", [](Session &s) { return s.state().renders; },
                   "Full renders since construction (each render(), each growth, the first insert).")
      .def(
          "_check_mapped",
          [](Session &s, const Map &m, const std::string &input) {
            nb::gil_scoped_release release;
            s.locked([&](vasco::Mapper &mp) { vasco::pipeline::check_mapped(m.grid.cells, mp.scans(), input); });
          },
          "map"_a, "input"_a,
          "FileError naming ``input`` when ``map`` (this session's finished map) has no known cell, saying\n"
          "why (the pipeline's rule: such a map is not written).")
      .def("__repr__", [](Session &s) {
        const Snapshot st = s.state();
        return nb::str("Mapper(backend='{}', {} scans)").format(st.backend, st.num_scans);
      });
}

}  // namespace

void bind_mapper(nb::module_ &m) {
  bind_auto_choice(m);
  nb::class_<Session> cls(m, "Mapper", kMapperDoc);
  bind_mapper_constructor(cls);
  bind_mapper_mapping(cls);
  bind_mapper_arrays(cls);
  bind_mapper_state(cls);
}

}  // namespace vasco_py
