// The C API of the mapping session (vasco_gpu/mapper_c.h) on vasco::Mapper.
#include "vasco_gpu/mapper_c.h"

#include <cstring>
#include <mutex>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>

#include "vasco_gpu/error.h"
#include "vasco_gpu/mapper.hpp"

struct vasco_mapper {
  std::unique_ptr<vasco::Mapper> mapper;
  vasco::FinishedMap finished;  // what the last vasco_mapper_finish returned points into
  std::string error;
  mutable std::mutex lock;  // one call at a time (mapper_c.h: Threads)
};

namespace {

thread_local std::string create_error;

vasco_status status_of(vasco::ErrorCode code) {
  switch (code) {
    case vasco::ErrorCode::Usage:
    case vasco::ErrorCode::BadInput: return VASCO_ERR_INVALID_ARGUMENT;
    case vasco::ErrorCode::TooLarge: return VASCO_ERR_TOO_LARGE;
    case vasco::ErrorCode::OutOfMemory: return VASCO_ERR_OUT_OF_MEMORY;
    case vasco::ErrorCode::NoGpu: return VASCO_ERR_BACKEND;
    case vasco::ErrorCode::State: return VASCO_ERR_STATE;
    case vasco::ErrorCode::Io: return VASCO_ERR_IO;
    case vasco::ErrorCode::Internal: return VASCO_ERR_INTERNAL;
  }
  return VASCO_ERR_INTERNAL;
}

// Runs `f`, turning exceptions into a status (by the error's code, never by
// its words) and a message kept in `error`. std::invalid_argument is a bad
// argument from code that does not throw vasco::Error yet.
template <class F>
vasco_status guarded(std::string *error, F &&f) {
  try {
    f();
    return VASCO_OK;
  } catch (const vasco::Error &e) {
    *error = e.what();
    return status_of(e.code());
  } catch (const std::bad_alloc &) {
    *error = "out of memory";
    return VASCO_ERR_OUT_OF_MEMORY;
  } catch (const std::invalid_argument &e) {
    *error = e.what();
    return VASCO_ERR_INVALID_ARGUMENT;
  } catch (const std::exception &e) {
    *error = e.what();
    return VASCO_ERR_INTERNAL;
  } catch (...) {
    *error = "unknown error";
    return VASCO_ERR_INTERNAL;
  }
}

vasco::MapperParams to_params(const vasco_mapper_params &p) {
  vasco::MapperParams m;
  m.resolution = p.resolution;
  m.p_prior = p.p_prior;
  m.p_occ = p.p_occ;
  m.p_emp = p.p_emp;
  m.range_sure = p.range_sure;
  m.range_max = p.range_max;
  m.wall_size = p.wall_size;
  m.downsample = p.downsample;
  m.border = p.border;
  return m;
}

vasco_status create(const vasco_mapper_params *params, const char *backend, const vasco::GridGeometry *frame,
                    vasco_mapper **out) {
  if (out == nullptr || params == nullptr) {
    create_error = "vasco_mapper_create: NULL argument";
    return VASCO_ERR_INVALID_ARGUMENT;
  }
  *out = nullptr;
  vasco::BackendOptions opt;
  opt.budget_hint = "vasco_mapper_set_max_memory";
  std::string name;
  // An unknown name is the one failure of resolving it: VASCO_ERR_BACKEND.
  const vasco_status known = guarded(&create_error, [&] {
    name = vasco::resolve_backend_name(backend != nullptr ? backend : "cpu_double", &opt);
  });
  if (known != VASCO_OK) return known == VASCO_ERR_INVALID_ARGUMENT ? VASCO_ERR_BACKEND : known;
  return guarded(&create_error, [&] {
    auto h = std::make_unique<vasco_mapper>();
    const vasco::MapperParams p = to_params(*params);
    h->mapper = frame ? std::make_unique<vasco::Mapper>(p, *frame, name, opt)
                      : std::make_unique<vasco::Mapper>(p, name, opt);
    *out = h.release();
  });
}

vasco_status fail(vasco_mapper *m, vasco_status code, const std::string &what) {
  if (m != nullptr) m->error = what;
  return code;
}

}  // namespace

extern "C" {

void vasco_mapper_params_default(vasco_mapper_params *params) {
  if (params == nullptr) return;
  const vasco::MapperParams d;
  *params = {d.resolution, d.p_prior, d.p_occ, d.p_emp, d.range_sure, d.range_max, d.wall_size,
             static_cast<int>(d.downsample), static_cast<int>(d.border)};
}

vasco_status vasco_mapper_create(const vasco_mapper_params *params, const char *backend, vasco_mapper **out) {
  return create(params, backend, nullptr, out);
}

vasco_status vasco_mapper_create_fixed(const vasco_mapper_params *params, const char *backend, int size_x,
                                       int size_y, double theta_offset, vasco_mapper **out) {
  vasco::GridGeometry frame;
  frame.size_x = size_x;
  frame.size_y = size_y;
  frame.resolution = params != nullptr ? params->resolution : 0;
  frame.theta_offset = theta_offset;
  return create(params, backend, &frame, out);
}

void vasco_mapper_destroy(vasco_mapper *m) { delete m; }

vasco_status vasco_mapper_insert(vasco_mapper *m, size_t num_scans, const double *poses,
                                 const int *beam_counts, const float *ranges, const double *first_angles,
                                 const double *angle_steps) {
  if (m == nullptr) return VASCO_ERR_INVALID_ARGUMENT;
  const std::lock_guard<std::mutex> hold(m->lock);
  if (num_scans > 0 && (poses == nullptr || beam_counts == nullptr || first_angles == nullptr ||
                        angle_steps == nullptr))
    return fail(m, VASCO_ERR_INVALID_ARGUMENT, "vasco_mapper_insert: NULL argument");
  for (size_t s = 0; s < num_scans; ++s)
    if (beam_counts[s] < 0 || (beam_counts[s] > 0 && ranges == nullptr))
      return fail(m, VASCO_ERR_INVALID_ARGUMENT,
                  "vasco_mapper_insert: scan " + std::to_string(s) + " has a bad beam count or no ranges");
  return guarded(&m->error, [&] {
    vasco::ScanBatch b;
    const float *r = ranges;
    for (size_t s = 0; s < num_scans; ++s) {
      b.add_scan(poses[3 * s], poses[3 * s + 1], poses[3 * s + 2], first_angles[s], angle_steps[s], r,
                 beam_counts[s], static_cast<long>(m->mapper->num_scans() + s + 1));
      r += beam_counts[s];
    }
    m->mapper->insert(std::move(b));
  });
}

vasco_status vasco_mapper_render(vasco_mapper *m, size_t num_scans, const double *poses) {
  if (m == nullptr) return VASCO_ERR_INVALID_ARGUMENT;
  const std::lock_guard<std::mutex> hold(m->lock);
  if (num_scans > 0 && poses == nullptr) return fail(m, VASCO_ERR_INVALID_ARGUMENT, "vasco_mapper_render: NULL poses");
  return guarded(&m->error, [&] {
    std::vector<vasco::Pose> p(num_scans);
    for (size_t s = 0; s < num_scans; ++s) p[s] = {poses[3 * s], poses[3 * s + 1], poses[3 * s + 2]};
    m->mapper->render(p);
  });
}

vasco_status vasco_mapper_finish(vasco_mapper *m, int downsample, int border, vasco_map *out) {
  if (m == nullptr) return VASCO_ERR_INVALID_ARGUMENT;
  const std::lock_guard<std::mutex> hold(m->lock);
  if (out == nullptr) return fail(m, VASCO_ERR_INVALID_ARGUMENT, "vasco_mapper_finish: NULL map");
  return guarded(&m->error, [&] {
    m->finished = m->mapper->finish(downsample, border);
    out->size_x = m->finished.size_x;
    out->size_y = m->finished.size_y;
    out->resolution = m->finished.resolution;
    out->offset_x = m->finished.min_x;
    out->offset_y = m->finished.min_y;
    out->cells = m->finished.cells.data();
  });
}

vasco_status vasco_mapper_grid_size(const vasco_mapper *m, int *size_x, int *size_y) {
  if (m == nullptr || size_x == nullptr || size_y == nullptr) return VASCO_ERR_INVALID_ARGUMENT;
  const std::lock_guard<std::mutex> hold(m->lock);
  *size_x = m->mapper->frame().size_x;
  *size_y = m->mapper->frame().size_y;
  return VASCO_OK;
}

vasco_status vasco_mapper_read(vasco_mapper *m, int x0, int y0, int width, int height, float *out) {
  if (m == nullptr) return VASCO_ERR_INVALID_ARGUMENT;
  const std::lock_guard<std::mutex> hold(m->lock);
  if (out == nullptr && width != 0 && height != 0)
    return fail(m, VASCO_ERR_INVALID_ARGUMENT, "vasco_mapper_read: NULL output");
  return guarded(&m->error, [&] {
    const std::vector<float> w = m->mapper->read(vasco::GridWindow{x0, y0, width, height});
    if (!w.empty()) std::memcpy(out, w.data(), w.size() * sizeof(float));
  });
}

vasco_status vasco_mapper_set_max_memory(vasco_mapper *m, unsigned long long bytes) {
  if (m == nullptr) return VASCO_ERR_INVALID_ARGUMENT;
  const std::lock_guard<std::mutex> hold(m->lock);
  return guarded(&m->error, [&] { m->mapper->set_max_memory_bytes(bytes); });
}

size_t vasco_mapper_num_scans(const vasco_mapper *m) {
  if (m == nullptr) return 0;
  const std::lock_guard<std::mutex> hold(m->lock);
  return m->mapper->num_scans();
}

const char *vasco_last_error(const vasco_mapper *m) {
  if (m == nullptr) return create_error.c_str();
  const std::lock_guard<std::mutex> hold(m->lock);
  return m->error.c_str();
}

}  // extern "C"
