// auto's one rule (vasco_gpu/backend_choice.h): the rule itself, a Mapper on
// "auto" choosing at its first insert, log2map --backend auto and a Mapper
// choosing alike on the same log, and the session's option table.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "test_support.h"
#include "tool_support.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/backend_choice.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/option_schema.h"
#include "vasco_gpu/pipeline/log_input.h"

namespace vasco {
namespace {

using tooltest::contains;

const std::string kIntel = std::string(VASCO_LOGS_DIR) + "/intel.gfs.log.gz";

// The cell updates at which one render on `cores` cores takes as long as the
// GPU's start-up and that render: below it the CPU wins a single render.
double break_even_cells(int cores) {
  const CostModel &m = auto_cost_model();
  const double per_cell = 1 / (m.cpu_cells_per_core_second * cores) - 1 / m.gpu_cells_per_second;
  return m.gpu_start_seconds / per_cell;
}

TEST(AutoRule, OneRenderWeighsTheStartUp) {
  const double even = break_even_cells(8);
  const AutoChoice small = choose_auto(even / 2, 8, 1, true);
  EXPECT_FALSE(small.gpu_faster);
  EXPECT_EQ(small.backend, "cpu_threads");
  EXPECT_LT(small.cpu_s, small.gpu_s);
  const AutoChoice large = choose_auto(even * 2, 8, 1, true);
  EXPECT_TRUE(large.gpu_faster);
  EXPECT_EQ(large.backend, "cuda");
  EXPECT_NEAR(large.gpu_s - large.cell_updates / auto_cost_model().gpu_cells_per_second,
              auto_cost_model().gpu_start_seconds, 1e-12);
  EXPECT_TRUE(contains(large.why, "cell updates: about ")) << large.why;
  EXPECT_TRUE(contains(large.why, "s on 8 cores, ")) << large.why;
  EXPECT_TRUE(contains(large.why, "s on the GPU (")) << large.why;
}

TEST(AutoRule, WithoutAUsableGpuNoGpuTimeIsGiven) {
  const AutoChoice c = choose_auto(break_even_cells(8) * 10, 8, 1, false, "no usable GPU: none here");
  EXPECT_TRUE(c.gpu_faster);  // the rule's verdict stays what it is
  EXPECT_EQ(c.backend, "cpu_threads");
  EXPECT_FALSE(contains(c.why, "GPU (")) << c.why;
  EXPECT_TRUE(contains(c.why, "s on 8 cores; no usable GPU: none here")) << c.why;
}

TEST(AutoRule, ExpectedRendersWeighTheStartUpLess) {
  const double cells = break_even_cells(8) / 2;  // the CPU wins one render of it
  EXPECT_EQ(choose_auto(cells, 8, 1, true).backend, "cpu_threads");
  const AutoChoice many = choose_auto(cells, 8, 20, true);  // the start-up shared by 20 renders
  EXPECT_EQ(many.backend, "cuda");
  EXPECT_NEAR(many.cpu_s, 20 * choose_auto(cells, 8, 1, true).cpu_s, 1e-12);
  EXPECT_TRUE(contains(many.why, "cell updates, 20 renders: about")) << many.why;
}

TEST(AutoRule, WithoutEndTheRatesAloneDecide) {
  const CostModel &m = auto_cost_model();
  for (int cores : {1, 16, 1024}) {
    const bool gpu = m.gpu_cells_per_second > m.cpu_cells_per_core_second * cores;
    for (double cells : {0.0, 1.0, 1e12}) EXPECT_EQ(choose_auto(cells, cores, 0, true).gpu_faster, gpu) << cores;
  }
}

// The first insert's scans are the workload: the Mapper's estimate is the
// rule's for them, and a failed first insert leaves the session undecided.
TEST(MapperAuto, ChoosesAtItsFirstInsert) {
  const MapperParams params;
  const testing_support::LoadedLog log = testing_support::load_log(kIntel, params);
  BackendOptions o;
  o.threads = 3;
  Mapper m(params, "auto", o);
  EXPECT_EQ(m.backend_name(), "auto");
  EXPECT_EQ(m.auto_choice(), nullptr);
  EXPECT_FALSE(m.backend_traits().grid_on_device);
  m.insert(log.batch);
  ASSERT_NE(m.auto_choice(), nullptr);
  const AutoChoice &c = *m.auto_choice();
  EXPECT_EQ(c.cell_updates, estimated_cell_updates(log.batch, params));
  EXPECT_EQ(c.cores, 3);
  EXPECT_EQ(c.renders, 1);
  EXPECT_EQ(c.gpu_faster, choose_auto(c.cell_updates, 3, 1, true).gpu_faster);
  EXPECT_EQ(m.backend_name().rfind(c.backend, 0), 0u) << m.backend_name();  // cuda: cuda_float
  if (!c.gpu_usable) EXPECT_EQ(m.backend_name(), "cpu_threads");
}

TEST(MapperAuto, AFailedFirstInsertLeavesItUndecided) {
  const MapperParams params;
  const testing_support::LoadedLog log = testing_support::load_log(kIntel, params);
  BackendOptions o;
  o.max_memory_bytes = 1024;  // far too little for the grid
  Mapper m(params, "auto", o);
  try {
    m.insert(log.batch);
    ADD_FAILURE() << "expected the budget to refuse the insert";
  } catch (const Error &e) {
    EXPECT_EQ(e.code(), ErrorCode::OutOfMemory) << e.what();
  }
  EXPECT_EQ(m.backend_name(), "auto");
  EXPECT_EQ(m.auto_choice(), nullptr);
  EXPECT_EQ(m.num_scans(), 0u);
}

TEST(MapperAuto, AWorkloadWithoutEndChoosesWhenMade) {
  BackendOptions o;
  o.expected_renders = 0;
  const Mapper m(MapperParams{}, "auto", o);
  ASSERT_NE(m.auto_choice(), nullptr);
  EXPECT_EQ(m.auto_choice()->renders, 0);
  EXPECT_NE(m.backend_name(), "auto");
  EXPECT_EQ(m.backend_name(), make_renderer("auto", o)->name());  // the registry's auto: the same rule
  o.expected_renders = -1;
  EXPECT_THROW(Mapper(MapperParams{}, "auto", o), Error);
}

// log2map --backend auto and a Mapper on "auto" fed the same log: the same
// estimate (cell updates, cores, CPU time) and, as usable GPUs go, the same backend.
TEST(MapperAuto, ChoosesAsLog2MapDoes) {
  const std::string out = ::testing::TempDir() + "backend_choice_test.map";
  const tooltest::ToolRun r = tooltest::run_tool("log2map", {"--backend", "auto", "--threads", "4", kIntel, out});
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string tag = "--backend auto: ";
  const size_t at = r.output.find(tag);
  ASSERT_NE(at, std::string::npos) << r.output;
  const std::string note = r.output.substr(at + tag.size(), r.output.find('\n', at) - at - tag.size());

  LogInputOptions in;
  in.log = kIntel;
  const LogInput input = load_log_input(in);
  BackendOptions o;
  o.threads = 4;
  Mapper m(input.params, "auto", o);
  m.insert(input.batch);
  ASSERT_NE(m.auto_choice(), nullptr);
  const AutoChoice &c = *m.auto_choice();
  const std::string estimate = c.why.substr(0, c.why.find(" cores") + 6);  // "1.9e+07 cell updates: about 0.068 s on 4 cores"
  EXPECT_EQ(note.rfind(estimate, 0), 0u) << note << "\nthe Mapper's: " << c.why;
  const bool log2map_gpu = contains(note, ": using cuda");
  EXPECT_TRUE(log2map_gpu || contains(note, ": using cpu_threads")) << note;
  EXPECT_EQ(log2map_gpu, c.backend == "cuda") << note << "\nthe Mapper's: " << c.why;
  if (!c.gpu_usable) {  // no GPU here: both on the CPU
    EXPECT_FALSE(log2map_gpu) << note;
    EXPECT_EQ(m.backend_name(), "cpu_threads");
  }
  std::remove(out.c_str());
}

TEST(SessionOptions, RowsSayWhatTheEngineTakes) {
  const OptionTable &t = session_option_table();
  const OptionSpec &backend = option_row(t, "backend");
  EXPECT_EQ(backend.type, OptionType::Choice);
  EXPECT_EQ(backend.choices, backend_names());
  EXPECT_EQ(backend.default_text, "auto");
  EXPECT_EQ(option_row(t, "cuda_mode").choices, (std::vector<std::string>{"float", "exact"}));
  EXPECT_EQ(option_row(t, "threads").hi, kMaxThreads);
  EXPECT_EQ(option_row(t, "max_memory").default_text, std::to_string(kDefaultMaxMemoryBytes >> 20));
  EXPECT_EQ(option_row(t, "max_memory").flag(), "--max-memory");
  EXPECT_EQ(option_row(t, "expected_renders").default_text, std::to_string(BackendOptions{}.expected_renders));
  EXPECT_EQ(find_option(t, "--cuda-mode"), &option_row(t, "cuda_mode"));
  EXPECT_EQ(find_option(t, "bogus"), nullptr);
  EXPECT_THROW(option_row(t, "bogus"), Error);
}

TEST(SessionOptions, ChecksRefuseWhatTheRowsDoNotAllow) {
  const OptionTable &t = session_option_table();
  EXPECT_NO_THROW(check_option_choice(option_row(t, "cuda_mode"), "exact", "cuda_mode"));
  try {
    check_option_choice(option_row(t, "cuda_mode"), "fast", "cuda_mode");
    ADD_FAILURE() << "fast accepted";
  } catch (const Error &e) {
    EXPECT_EQ(e.code(), ErrorCode::Usage);
    EXPECT_EQ(std::string(e.what()), "cuda_mode 'fast': expected one of: float, exact");
  }
  EXPECT_NO_THROW(check_option_number(option_row(t, "threads"), kMaxThreads, "threads"));
  EXPECT_THROW(check_option_number(option_row(t, "threads"), kMaxThreads + 1, "threads"), Error);
  EXPECT_THROW(check_option_number(option_row(t, "threads"), 1.5, "threads"), Error);
  EXPECT_THROW(check_option_number(option_row(t, "expected_renders"), -1, "expected_renders"), Error);
  EXPECT_THROW(check_option_number(option_row(t, "threads"), std::nan(""), "threads"), Error);
}

}  // namespace
}  // namespace vasco
