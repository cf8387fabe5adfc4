// The backend registry: one row per backend, read by make_renderer, the
// session APIs' name resolution, egrid.h and the tools' --backend help.
#include "vasco_gpu/backend.h"

#include <algorithm>
#include <cctype>
#include <limits>
#include <sstream>

#include "host_renderer.h"
#include "vasco_gpu/backend_choice.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/renderer.h"

#if defined(VASCO_HAVE_CUDA)
#include "vasco_gpu/cuda_backend.h"
#endif

namespace vasco {
namespace {

#if defined(VASCO_HAVE_CUDA)
constexpr bool kCudaCompiled = true;
#else
constexpr bool kCudaCompiled = false;
#endif

std::unique_ptr<Renderer> cpu_double(const BackendOptions &) { return make_cpu_double_renderer(); }
std::unique_ptr<Renderer> cpu_threads(const BackendOptions &o) { return make_cpu_threads_renderer(o.threads); }
std::unique_ptr<Renderer> cpu_float(const BackendOptions &) { return make_cpu_float_renderer(); }

// Why cuda cannot run here; empty when it can.
std::string cuda_unusable_reason(const BackendOptions &o) {
#if defined(VASCO_HAVE_CUDA)
  std::string why;
  return cuda_usable(o.cuda_device, &why) ? std::string() : "no usable GPU: " + why;
#else
  (void)o;
  return "this build has no CUDA backend (configured without nvcc)";
#endif
}

std::unique_ptr<Renderer> cuda(const BackendOptions &o) {
  const std::string why = cuda_unusable_reason(o);
  if (!why.empty()) throw Error(ErrorCode::NoGpu, "backend cuda: " + why);
#if defined(VASCO_HAVE_CUDA)
  return make_cuda_renderer(o);
#else
  return nullptr;  // not reached: no CUDA build has a usable GPU
#endif
}

// backend_choice.h's rule without a workload, as for a workload without
// end (a session that knows its workload decides in Mapper instead): cuda
// when a GPU is usable, else cpu_threads, cpu_double's bytes on every core.
std::unique_ptr<Renderer> automatic(const BackendOptions &o) {
  return choose_auto(nullptr, MapperParams{}, o).backend == "cuda" ? cuda(o) : cpu_threads(o);
}

}  // namespace

int cuda_device_count() {
#if defined(VASCO_HAVE_CUDA)
  return cuda_visible_device_count();
#else
  return 0;
#endif
}

bool gpu_usable(int device, std::string *why) {
  BackendOptions o;
  o.cuda_device = device;
  const std::string reason = cuda_unusable_reason(o);
  if (!reason.empty() && why != nullptr) *why = reason;
  return reason.empty();
}

const std::vector<BackendInfo> &backend_registry() {
  // {name, aliases, exactness, grid on the device, compiled in, summary,
  //  uses GPUs, uses threads, chooses, factory}
  static const std::vector<BackendInfo> rows = {
      {"cpu_double", {}, Exactness::Exact, false, true,
       "CARMEN's arithmetic to the letter, one core: bit-identical to CARMEN", false, false, false, cpu_double},
      {"cpu_threads", {}, Exactness::Exact, false, true,
       "cpu_double's bytes on all cores (--threads)", false, true, false, cpu_threads},
      {"cpu_float", {}, Exactness::Float, false, true,
       "single precision on one core, fast; measured against CARMEN's maps", false, false, false, cpu_float},
      {"cuda", {{"cuda_float", CudaMode::Float}, {"cuda_exact", CudaMode::Exact}, {"gpu", CudaMode::Float, false}},
       Exactness::ByCudaMode, true,
       kCudaCompiled, "the GPU: float mode (fastest) or exact mode (bit-identical to cpu_double)", true, false, false,
       cuda},
      {"auto", {}, Exactness::ByCudaMode, false, true,
       "cuda or cpu_threads, whichever a cost model expects to finish first (cuda only where a GPU is usable)",
       true, true, true, automatic},
  };
  return rows;
}

const BackendInfo *find_backend(const std::string &name) {
  for (const BackendInfo &b : backend_registry()) {
    if (name == b.name) return &b;
    for (const BackendAlias &a : b.aliases)
      if (name == a.name) return &b;
  }
  return nullptr;
}

std::vector<std::string> compiled_backends() {
  std::vector<std::string> names;
  for (const BackendInfo &b : backend_registry())
    if (b.compiled) names.push_back(b.name);
  return names;
}

std::string resolve_backend_name(const std::string &name, BackendOptions *options) {
  const BackendInfo *b = find_backend(name);
  if (b == nullptr) {
    const std::vector<std::string> names = backend_names();
    std::string known;
    for (const std::string &n : names) known += " " + n;
    const std::string near = closest_name(name, names);
    const std::string hint = near.empty() ? "" : ": did you mean '" + near + "'?";
    throw Error(ErrorCode::Usage, "unknown backend '" + carmen::printable(name) + "'" + hint + " (known:" + known + ")");
  }
  for (const BackendAlias &a : b->aliases)
    if (name == a.name && a.sets_cuda_mode && options != nullptr) options->cuda_mode = a.cuda_mode;
  return b->name;
}

std::vector<std::string> backend_names() {
  std::vector<std::string> names;
  for (const BackendInfo &b : backend_registry()) {
    names.push_back(b.name);
    for (const BackendAlias &a : b.aliases) names.push_back(a.name);
  }
  return names;
}

std::string closest_name(const std::string &name, const std::vector<std::string> &known) {
  const auto lower = [](std::string s) {
    for (char &c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  };
  const std::string a = lower(name);
  std::string best;
  size_t best_distance = std::numeric_limits<size_t>::max();
  for (const std::string &candidate : known) {
    const std::string b = lower(candidate);
    // Optimal string alignment distance, row by row (rows i-2, i-1, i).
    std::vector<size_t> two(b.size() + 1), one(b.size() + 1), row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) one[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
      row[0] = i;
      for (size_t j = 1; j <= b.size(); ++j) {
        row[j] = std::min({one[j] + 1, row[j - 1] + 1, one[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
        if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) row[j] = std::min(row[j], two[j - 2] + 1);
      }
      std::swap(two, one);
      std::swap(one, row);
    }
    const size_t d = one[b.size()];
    const size_t limit = b.size() <= 7 ? 1 : b.size() <= 11 ? 2 : 3;
    if (d <= limit && d < best_distance) {
      best = candidate;
      best_distance = d;
    }
  }
  return best;
}

std::string backend_help() {
  std::ostringstream s;
  for (const BackendInfo &b : backend_registry()) {
    if (!b.compiled) continue;
    s << b.name << ": " << b.summary << "\n";
  }
  return s.str();
}

std::unique_ptr<Renderer> make_renderer(const std::string &backend, const BackendOptions &options) {
  BackendOptions o = options;
  const std::string name = resolve_backend_name(backend, &o);
  return find_backend(name)->make(o);
}

}  // namespace vasco
