// The backend registry: one list of names that make_renderer, the session
// APIs' resolution, egrid.h and --backend's help all read.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "carmen/egrid.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/renderer.h"

namespace vasco {
namespace {

bool contains(const std::vector<std::string> &v, const std::string &s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

TEST(BackendRegistry, CompiledBackendsAreWhatMakeRendererAcceptsAutoIncluded) {
  const std::vector<std::string> names = compiled_backends();
  for (const char *n : {"cpu_double", "cpu_threads", "cpu_float", "auto"}) EXPECT_TRUE(contains(names, n)) << n;
#if defined(VASCO_HAVE_CUDA)
  EXPECT_TRUE(contains(names, "cuda"));
#else
  EXPECT_FALSE(contains(names, "cuda"));
#endif
  for (const std::string &n : names) {
    if (n == "cuda") continue;  // needs a GPU
    EXPECT_NO_THROW(make_renderer(n)) << n;
  }
}

TEST(BackendRegistry, RenderersSayWhatTheRegistrySays) {
  for (const char *n : {"cpu_double", "cpu_threads", "cpu_float"}) {
    SCOPED_TRACE(n);
    const BackendInfo *info = find_backend(n);
    ASSERT_NE(info, nullptr);
    const auto r = make_renderer(n);
    EXPECT_EQ(r->name(), n);
    EXPECT_EQ(r->traits().exact, info->exactness == Exactness::Exact);
    EXPECT_EQ(r->traits().grid_on_device, info->grid_on_device);
  }
}

TEST(BackendRegistry, AliasesSelectTheCudaMode) {
  BackendOptions o;
  EXPECT_EQ(resolve_backend_name("cuda_exact", &o), "cuda");
  EXPECT_EQ(o.cuda_mode, CudaMode::Exact);
  EXPECT_EQ(resolve_backend_name("cuda_float", &o), "cuda");
  EXPECT_EQ(o.cuda_mode, CudaMode::Float);
  EXPECT_EQ(resolve_backend_name("cpu_float", &o), "cpu_float");
}

TEST(BackendRegistry, AnUnknownNameIsAUsageError) {
  for (const char *n : {"gpu9000", "", "CPU_DOUBLE"}) {
    try {
      make_renderer(n);
      ADD_FAILURE() << "expected an error for '" << n << "'";
    } catch (const Error &e) {
      EXPECT_EQ(e.code(), ErrorCode::Usage) << e.what();
      EXPECT_NE(std::string(e.what()).find("cpu_double"), std::string::npos) << "lists the known names";
    }
  }
}

TEST(BackendRegistry, WithoutCudaTheCudaNamesAreANoGpuError) {
#if defined(VASCO_HAVE_CUDA)
  GTEST_SKIP() << "built with CUDA: cuda_backend_test checks this on a machine without a GPU";
#else
  for (const char *n : {"cuda", "cuda_exact", "cuda_float"}) {
    try {
      make_renderer(n);
      ADD_FAILURE() << "expected an error for " << n;
    } catch (const Error &e) {
      EXPECT_EQ(e.code(), ErrorCode::NoGpu) << e.what();
    }
  }
#endif
}

// egrid.h reported names (cuda_float) its own setter refused; now every name
// of the registry is accepted, and nothing else.
TEST(BackendRegistry, EgridAcceptsEveryRegistryName) {
  for (const std::string &n : backend_names()) EXPECT_EQ(vasco_egrid_set_backend(n.c_str()), 0) << n;
  for (const char *n : {"cuda_float", "cuda_exact", "cpu_threads", "auto"}) EXPECT_EQ(vasco_egrid_set_backend(n), 0) << n;
  EXPECT_EQ(vasco_egrid_set_backend("gpu9000"), -1);
  EXPECT_EQ(vasco_egrid_set_backend(""), 0);
}

TEST(BackendRegistry, HelpListsEveryCompiledBackendWithItsSummary) {
  const std::string help = backend_help();
  for (const BackendInfo &b : backend_registry()) {
    const bool listed = help.find(std::string(b.name) + ": " + b.summary) != std::string::npos;
    EXPECT_EQ(listed, b.compiled) << b.name;
  }
}

}  // namespace
}  // namespace vasco
