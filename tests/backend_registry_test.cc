// The backend registry: one list of names that make_renderer, the session
// APIs' resolution, egrid.h and --backend's help all read.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "carmen/egrid.h"
#include "tool_support.h"
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

// gpu is cuda and keeps the mode it is given.
TEST(BackendRegistry, GpuIsCudaAndKeepsTheMode) {
  const BackendInfo *b = find_backend("gpu");
  ASSERT_NE(b, nullptr);
  EXPECT_STREQ(b->name, "cuda");
  EXPECT_TRUE(contains(backend_names(), "gpu"));
  for (CudaMode mode : {CudaMode::Exact, CudaMode::Float}) {
    BackendOptions o;
    o.cuda_mode = mode;
    EXPECT_EQ(resolve_backend_name("gpu", &o), "cuda");
    EXPECT_EQ(o.cuda_mode, mode);
  }
  EXPECT_EQ(resolve_backend_name("gpu", nullptr), "cuda");
}

TEST(BackendRegistry, AnUnknownNameNamesTheNearestOne) {
  const auto message = [](const std::string &name) {
    try {
      resolve_backend_name(name, nullptr);
    } catch (const Error &e) {
      EXPECT_EQ(e.code(), ErrorCode::Usage) << e.what();
      return std::string(e.what());
    }
    ADD_FAILURE() << "no error for " << name;
    return std::string();
  };
  EXPECT_NE(message("cpu_dobule").find("unknown backend 'cpu_dobule': did you mean 'cpu_double'? (known: cpu_double"),
            std::string::npos)
      << message("cpu_dobule");
  EXPECT_NE(message("CPU_DOUBLE").find("did you mean 'cpu_double'?"), std::string::npos);
  EXPECT_NE(message("cuda-exact").find("did you mean 'cuda_exact'?"), std::string::npos);
  EXPECT_NE(message("cpu_thread").find("did you mean 'cpu_threads'?"), std::string::npos);
  EXPECT_EQ(message("gpu9000").find("did you mean"), std::string::npos) << message("gpu9000");
  EXPECT_EQ(message("").find("did you mean"), std::string::npos);
}

TEST(BackendRegistry, ClosestNameByEditDistance) {
  const std::vector<std::string> known = {"cpu_double", "cpu_threads", "cpu_float", "cuda", "auto", "gpu"};
  EXPECT_EQ(closest_name("cpu_dobule", known), "cpu_double");  // two letters swapped: one edit
  EXPECT_EQ(closest_name("cpu_floot", known), "cpu_float");
  EXPECT_EQ(closest_name("Cuda", known), "cuda");              // case ignored
  EXPECT_EQ(closest_name("cud", known), "cuda");
  EXPECT_EQ(closest_name("cpu_dbl", known), "");               // three edits from a 10-letter name: too far
  EXPECT_EQ(closest_name("opengl", known), "");
  EXPECT_EQ(closest_name("gpu", known), "gpu");
  EXPECT_EQ(closest_name("x", {}), "");
  // Up to 7 letters one edit, up to 11 two, beyond three.
  EXPECT_EQ(closest_name("abcxyzg", {"abcdefg"}), "");
  EXPECT_EQ(closest_name("abcdefx", {"abcdefg"}), "abcdefg");
  EXPECT_EQ(closest_name("--pose-tolerence", {"--pose-tolerance", "--poses"}), "--pose-tolerance");
  EXPECT_EQ(closest_name("--pose-toll", {"--pose-tolerance"}), "");
  // The first of equally close names.
  EXPECT_EQ(closest_name("cpu_flat", {"cpu_float", "cpu_flap"}), "cpu_float");
}

// log2map's --backend takes the aliases: gpu (the mode as --cuda-mode says),
// cuda_exact and cuda_float (their mode; another --cuda-mode is a usage
// error), and names the nearest backend for a typo; an option's typo names
// the nearest option.
TEST(BackendRegistry, Log2mapTakesTheAliases) {
  const std::string intel = std::string(VASCO_LOGS_DIR) + "/intel.gfs.log.gz";
  const std::string out = ::testing::TempDir() + "/backend_alias_test.map";
  using tooltest::contains;
  for (const std::vector<std::string> &args :
       std::vector<std::vector<std::string>>{{"--backend", "gpu"},
                                             {"--backend", "gpu", "--cuda-mode", "exact"},
                                             {"--backend", "cuda_exact"},
                                             {"--backend", "cuda_exact", "--cuda-mode", "exact"},
                                             {"--backend", "cuda_float", "--cuda-mode", "float"}}) {
    std::vector<std::string> a = args;
    a.insert(a.end(), {"--quiet", "--vasco_num_scans", "20", intel, out});
    const tooltest::ToolRun r = tooltest::run_tool("log2map", a);
#if defined(VASCO_HAVE_CUDA)
    EXPECT_NE(r.status, 2) << args[1] << ": " << r.output;
#else
    EXPECT_EQ(r.status, 1) << args[1] << ": " << r.output;
    EXPECT_TRUE(contains(r.output, "backend cuda: this build has no CUDA backend")) << r.output;
#endif
  }
  tooltest::ToolRun r = tooltest::run_tool("log2map", {"--backend", "cuda_exact", "--cuda-mode", "float", intel, out});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--backend cuda_exact is --cuda-mode exact: not with --cuda-mode float")) << r.output;
  r = tooltest::run_tool("log2map", {"--backend", "cpu_dobule", intel, out});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "unknown backend 'cpu_dobule': did you mean 'cpu_double'?")) << r.output;
  r = tooltest::run_tool("log2map", {"--pose-tolerence", "0.5", intel, out});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "Did you mean --pose-tolerance (not --pose-tolerence)?")) << r.output;
  r = tooltest::run_tool("log2map", {"--help"});
  EXPECT_EQ(r.status, 0);
#if defined(VASCO_HAVE_CUDA)
  EXPECT_TRUE(contains(r.output, "cuda_exact (cuda --cuda-mode exact)")) << r.output;
  EXPECT_TRUE(contains(r.output, "gpu (cuda)")) << r.output;
#else
  EXPECT_FALSE(contains(r.output, "gpu (cuda)")) << "the help lists the backends compiled in, and their aliases";
#endif
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
