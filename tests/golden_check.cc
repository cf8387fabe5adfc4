// golden_check — every public CARMEN golden case through our paths (`make
// golden`): one line per case and path, then a summary.
//
//   golden_check [--golden DIR] [--data DIR] [--paths LIST] [--case SUBSTRING]
//
// Exact paths (cpu_double, cpu_threads/1, /2, /7, egrid_c_api, a mapping
// session fed the scans in pieces then rendered again with its poses
// (mapper/cpu_threads), egrid.h on a
// cpu_threads session, and cuda_exact, the same split in two bands
// (cuda_exact/split: GPUs 0 and 1, or twice GPU 0), mapper/cuda,
// mapper/cuda_split and egrid_c_api/cuda_exact in exact mode when a GPU is
// usable) must give CARMEN's GRIDMAP payload
// digest.
// Float paths (cpu_float, cuda_float) and the session fed in pieces as it is
// (mapper-grown/..., whose grown grid may round a boundary cell the other
// way: mapper.hpp) are reported against the golden map with
// the DESIGN §4 table; the golden cells are those of cpu_double once its
// digest has matched CARMEN's. Exit 0 when every exact path matched every
// case, 1 when one did not, 2 on a usage error, 77 when DIR holds no goldens.
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "golden_support.h"
#include "vasco_gpu/internal/timing.h"

namespace {

using namespace vasco;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string golden_dir, data_dir;
  std::vector<std::string> paths;  // empty: every exact path available here, then the float ones
  std::string filter;
};

std::vector<std::string> split(const std::string &s) {
  std::vector<std::string> out;
  size_t a = 0;
  while (a <= s.size()) {
    const size_t b = std::min(s.find(',', a), s.size());
    if (b > a) out.push_back(s.substr(a, b - a));
    a = b + 1;
  }
  return out;
}

std::vector<golden::Path> select_paths(const Options &opt, std::vector<golden::Path> *floats) {
  std::string why;
  const bool gpu = golden::cuda_available(&why);
  if (!gpu) std::printf("CUDA paths skipped: %s\n", why.c_str());
  std::map<std::string, golden::Path> all;
  std::vector<std::string> exact_names, float_names = {"cpu_float", "mapper-grown/cpu_threads"};
  for (auto &p : golden::exact_cpu_paths()) {
    exact_names.push_back(p.name);
    all.emplace(p.name, p);
  }
  all.emplace("cpu_float", golden::backend_path("cpu_float", "cpu_float"));
  all.emplace("mapper-grown/cpu_threads", golden::mapper_grown_path("cpu_threads"));
  if (gpu) {
    exact_names.push_back("cuda_exact");
    float_names.push_back("cuda_float");
    all.emplace("cuda_exact", golden::cuda_path(CudaMode::Exact));
    all.emplace("cuda_float", golden::cuda_path(CudaMode::Float));
    BackendOptions exact;
    exact.cuda_mode = CudaMode::Exact;
    exact_names.push_back("mapper/cuda");
    all.emplace("mapper/cuda", golden::mapper_path("cuda", exact));
    float_names.push_back("mapper-grown/cuda");
    all.emplace("mapper-grown/cuda", golden::mapper_grown_path("cuda", exact));
    exact_names.push_back("cuda_exact/split");
    all.emplace("cuda_exact/split", golden::cuda_split_path());
    exact_names.push_back("mapper/cuda_split");
    golden::Path split_session = golden::mapper_path("cuda", golden::split_exact_options());
    split_session.name = "mapper/cuda_split";
    all.emplace("mapper/cuda_split", split_session);
    exact_names.push_back("egrid_c_api/cuda_exact");
    all.emplace("egrid_c_api/cuda_exact", golden::egrid_path("cuda_exact"));
  }
  std::vector<golden::Path> exact;
  const std::vector<std::string> wanted = opt.paths.empty() ? exact_names : opt.paths;
  for (const auto &n : wanted) {
    if (!all.count(n)) throw std::invalid_argument("unknown or unavailable path '" + n + "'");
    const bool is_float = n == "cpu_float" || n == "cuda_float" || n.rfind("mapper-grown/", 0) == 0;
    (is_float ? *floats : exact).push_back(all.at(n));
  }
  if (opt.paths.empty())
    for (const auto &n : float_names) floats->push_back(all.at(n));
  return exact;
}

// Runs one case; returns the number of exact paths that differed.
int run_case(const golden::Case &c, const std::string &log, const std::string &ini,
             const std::vector<golden::Path> &exact, const std::vector<golden::Path> &floats,
             std::map<std::string, int> *matched) {
  const LogInput in = golden::load_case(log, ini);
  int differ = 0;
  FinishedMap reference;  // a map whose digest is CARMEN's
  bool have_reference = false;
  for (const auto &p : exact) {
    const auto t0 = Clock::now();
    const FinishedMap m = p.run(in);
    const std::string got = golden::digest(m);
    const bool ok = got == c.sha256;
    std::printf("%-9s %-52s %-13s %7.2f s%s\n", ok ? "identical" : "DIFFERS", c.name.c_str(),
                p.name.c_str(), seconds_since(t0), ok ? "" : ("  got " + got.substr(0, 16)).c_str());
    std::fflush(stdout);
    if (ok) {
      ++(*matched)[p.name];
      if (!have_reference && p.name != "egrid_c_api") reference = m, have_reference = true;
    } else {
      ++differ;
    }
  }
  for (const auto &p : floats) {
    if (!have_reference) {
      std::printf("%-9s %-52s %-13s no exact path matched: nothing to compare with\n", "-",
                  c.name.c_str(), p.name.c_str());
      continue;
    }
    const carmen::Agreement a = golden::compare_finished(reference, p.run(in));
    std::printf("%-9s %-52s %-13s max|dp| %.3g, |dp|>0.1 %llu, status differs %llu, class %.4f%%\n",
                "float", c.name.c_str(), p.name.c_str(), a.max_abs_diff,
                (unsigned long long)a.large_diffs, (unsigned long long)a.status_differs,
                100.0 * a.class_agreement());
  }
  return differ;
}

int run(const Options &opt) {
  const std::string sums = opt.golden_dir + "/SHA256SUMS";
  if (!golden::file_exists(sums)) {
    std::printf("golden_check: no golden maps at %s (SHA256SUMS missing): nothing checked\n",
                opt.golden_dir.c_str());
    return 77;
  }
  std::vector<golden::Path> floats;
  const std::vector<golden::Path> exact = select_paths(opt, &floats);
  const std::vector<std::string> log_dirs = {opt.golden_dir, opt.data_dir,
                                             opt.data_dir + "/ple_radish_corrected"};
  std::map<std::string, int> matched;
  int cases = 0, differ = 0, missing = 0;
  for (const auto &c : golden::read_cases(sums)) {
    if (!opt.filter.empty() && c.name.find(opt.filter) == std::string::npos) continue;
    ++cases;
    const std::string log = golden::find_log(c.log, log_dirs);
    const std::string ini = opt.golden_dir + "/params/" + c.params + ".ini";
    if (log.empty() || !golden::file_exists(ini)) {
      std::printf("%-9s %-52s no %s\n", "MISSING", c.name.c_str(), log.empty() ? "log" : "ini");
      ++missing;
      continue;
    }
    differ += run_case(c, log, ini, exact, floats, &matched);
  }
  std::printf("\nsummary: %d cases\n", cases);
  for (const auto &p : exact)
    std::printf("  %-13s %d of %d identical to CARMEN\n", p.name.c_str(), matched[p.name], cases);
  if (missing) std::printf("  %d cases had no log or ini\n", missing);
  return differ == 0 && missing == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char **argv) {
  Options opt;
  opt.golden_dir = VASCO_SHARED_DIR "/golden";
  opt.data_dir = VASCO_SHARED_DIR "/data";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--golden" && has_value) opt.golden_dir = argv[++i];
    else if (a == "--data" && has_value) opt.data_dir = argv[++i];
    else if (a == "--paths" && has_value) opt.paths = split(argv[++i]);
    else if (a == "--case" && has_value) opt.filter = argv[++i];
    else {
      std::fprintf(stderr,
                   "usage: golden_check [--golden DIR] [--data DIR] [--paths a,b,...] [--case SUBSTRING]\n"
                   "paths: cpu_double cpu_threads/1 cpu_threads/2 cpu_threads/7 egrid_c_api mapper/cpu_threads "
                   "egrid_c_api/cpu_threads cuda_exact cuda_exact/split mapper/cuda mapper/cuda_split "
                   "egrid_c_api/cuda_exact cpu_float cuda_float "
                   "mapper-grown/cpu_threads mapper-grown/cuda\n");
      return 2;
    }
  }
  try {
    return run(opt);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "golden_check: %s\n", e.what());
    return 2;
  }
}
