#include "carmen_compat/usable_cores.h"

#include <algorithm>
#include <exception>
#include <fstream>
#include <string>
#include <thread>

#ifdef __linux__
#include <sched.h>
#endif

namespace carmen {
namespace {

// cgroup v2's "quota period" (e.g. "1600000 100000" = 16 cores); 0 if none.
int cgroup_cpu_quota() {
  std::ifstream in("/sys/fs/cgroup/cpu.max");
  std::string quota;
  long long period = 0;
  if (!(in >> quota >> period) || quota == "max" || period <= 0) return 0;
  try {
    const long long q = std::stoll(quota);
    return q > 0 ? static_cast<int>((q + period - 1) / period) : 0;
  } catch (const std::exception &) {
    return 0;
  }
}

}  // namespace

int usable_cores() {
  int n = static_cast<int>(std::thread::hardware_concurrency());
#ifdef __linux__
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof(set), &set) == 0) n = CPU_COUNT(&set);
#endif
  const int quota = cgroup_cpu_quota();
  if (quota > 0) n = std::min(n, quota);
  return std::max(1, n);
}

}  // namespace carmen
