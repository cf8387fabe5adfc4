#include "log2map_batch.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "batch_report.h"
#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"
#include "carmen_compat/termination_signals.h"
#include "cli_support.h"
#include "log2map_steps.h"
#include "read_ahead.h"
#include "task_pool.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/pipeline/outputs.h"

namespace log2map {

namespace {

using carmen::Error;
using carmen::ErrorCode;

// The output directory, made when missing (its parent must exist); one the
// batch made is removed again at the end when nothing was written into it (a
// batch that failed, or threw, leaves no directory of its own behind).
class OutDir {
 public:
  explicit OutDir(const std::string &dir) : dir_(dir) {
    struct stat st;
    if (::stat(dir.c_str(), &st) == 0) {
      if (!S_ISDIR(st.st_mode)) throw carmen::FileError(dir, "--out-dir: not a directory", ErrorCode::Io);
      return;
    }
    if (::mkdir(dir.c_str(), 0777) != 0)
      throw carmen::FileError(dir, std::string("--out-dir: cannot make the directory: ") + std::strerror(errno),
                              ErrorCode::Io);
    made_ = true;
  }
  ~OutDir() {
    if (made_) ::rmdir(dir_.c_str());  // fails, harmlessly, unless it is empty
  }
  OutDir(const OutDir &) = delete;
  OutDir &operator=(const OutDir &) = delete;

 private:
  std::string dir_;
  bool made_ = false;
};

// DIR/STEM.FORMAT for each of opt.formats.
std::vector<std::string> outputs_of(const Options &opt, const std::string &input) {
  return vasco::pipeline::plan_outputs({input}, opt.out_dir, opt.formats)[0].outputs;
}

// Each input's entry (the pipeline's plan: two inputs writing the same
// outputs are refused).
std::vector<BatchEntry> plan_entries(const Options &opt) {
  std::vector<BatchEntry> entries;
  for (vasco::pipeline::PlannedInput &p : vasco::pipeline::plan_outputs(opt.inputs, opt.out_dir, opt.formats)) {
    BatchEntry e;
    e.input = std::move(p.input);
    e.outputs = std::move(p.outputs);
    entries.push_back(std::move(e));
  }
  return entries;
}

std::string what_of(const std::exception_ptr &error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::bad_alloc &) {
    return "out of memory";
  } catch (const std::exception &e) {
    return e.what();
  } catch (...) {
    return "unknown error";
  }
}

// How many read or mapped inputs may wait at once: bounds the memory held.
class Slots {
 public:
  explicit Slots(size_t n) : free_(n) {}
  void take() {
    std::unique_lock<std::mutex> lock(m_);
    freed_.wait(lock, [this] { return free_ > 0; });
    --free_;
  }
  void give() {
    {
      std::lock_guard<std::mutex> lock(m_);
      ++free_;
    }
    freed_.notify_one();
  }

 private:
  std::mutex m_;
  std::condition_variable freed_;
  size_t free_;
};

// A batch knob from the environment (batch_bench's A/Bs): `name`'s whole
// number in [lo, hi], or `fallback` when it is unset or empty. Anything else
// is a usage error naming the variable, its value and the range: a typo must
// not run the batch with a setting nobody asked for.
int env_knob(const char *name, int lo, int hi, int fallback) {
  const char *v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  const std::string text = v;
  int value = 0;
  const char *end = text.data() + text.size();
  const auto [stop, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || stop != end || value < lo || value > hi)
    throw Error(ErrorCode::Usage, std::string(name) + "=" + carmen::printable(text) + ": not a whole number from " +
                                      std::to_string(lo) + " to " + std::to_string(hi));
  return value;
}

// How much nicer the pool's threads (reads, writes) run than the mappers:
// with every core reading or writing, a mapper thread that waits for a core
// holds its GPU up, while the pool's work has slack (reads queue ahead).
// VASCO_BATCH_POOL_NICE sets it (0: the same priority).
int pool_nice() { return env_knob("VASCO_BATCH_POOL_NICE", 0, 19, 5); }

// How many inputs, per pool thread, may be read ahead of the mappers: deep
// enough that the pool reads on while a GPU backend starts (~0.3 s) instead
// of idling after a few inputs. VASCO_BATCH_READ_AHEAD sets it (2: what a
// batch did before; batch_bench's A/B).
size_t read_ahead_per_thread() { return static_cast<size_t>(env_knob("VASCO_BATCH_READ_AHEAD", 1, 64, 8)); }

// The memory this process may use: the machine's, or its cgroup's limit
// (cgroup v2's memory.max) where that is less.
uint64_t usable_memory() {
  uint64_t bytes = UINT64_MAX;
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0) bytes = static_cast<uint64_t>(pages) * static_cast<uint64_t>(page);
  if (FILE *f = std::fopen("/sys/fs/cgroup/memory.max", "r")) {
    unsigned long long limit = 0;
    if (std::fscanf(f, "%llu", &limit) == 1 && limit > 0) bytes = std::min<uint64_t>(bytes, limit);  // "max": none
    std::fclose(f);
  }
  return bytes;
}

// The bytes parsed inputs read ahead may hold (those being mapped
// included), the reads under way counted at what they are expected to hold:
// 1 GiB (some 140 fr079-size logs), at most an eighth of the memory. What a
// finished map holds until it is written is bounded apart (the write slots).
uint64_t read_ahead_budget() { return std::min<uint64_t>(uint64_t{1} << 30, usable_memory() / 8); }

// The same with the reads under way counted at the most they may hold
// (several times what a log parses to): an eighth of the memory, or
// VASCO_BATCH_READ_WORST_MB MiB (batch_bench's A/B: 1024 counts them so
// against the budget, as before, when the pool's reads were held to 14 at
// once and fewer the further they ran ahead).
uint64_t read_ahead_worst() {
  const int mib = env_knob("VASCO_BATCH_READ_WORST_MB", 1, 1 << 24, 0);
  return mib > 0 ? uint64_t(mib) << 20 : usable_memory() / 8;
}

// Whether every input is read before the first mapper starts, unbounded
// by the read-ahead (VASCO_BATCH_READ_FIRST=1): batch_bench's floor
// experiment, the mappers and their start-up with no read beside them.
bool cli_read_first() { return env_knob("VASCO_BATCH_READ_FIRST", 0, 1, 0) == 1; }

// The environment's batch knobs, read (and checked) before any work.
struct BatchKnobs {
  size_t ahead_per_thread = read_ahead_per_thread();
  int nice = pool_nice();
  uint64_t read_worst = read_ahead_worst();
  bool read_first = cli_read_first();
};

// The bytes a read input holds until it is mapped: its scans' arrays and
// the per-scan records beside them (what grows with the log).
uint64_t bytes_held(const vasco::LogInput &in) {
  auto of = [](const auto &v) { return static_cast<uint64_t>(v.capacity()) * sizeof(v[0]); };
  const vasco::ScanBatch &b = in.batch;
  return of(b.x) + of(b.y) + of(b.theta) + of(b.first_angle) + of(b.angle_step) + of(b.beam_offset) + of(b.line) +
         of(b.range) + of(in.stamps) + of(in.load.stamps) + of(in.load.robot_poses);
}

// What each input's read may come to hold, from its file, before it is
// read: the read-ahead counts a read at this from the start, so that reads
// let through together (2 per pool thread) cannot pass the budget before
// any of their sizes is known. At most what the reader lets an input's
// scans take (--max-memory).
std::vector<uint64_t> read_estimates(const Options &opt) {
  std::vector<uint64_t> bytes;
  bytes.reserve(opt.inputs.size());
  for (const std::string &input : opt.inputs)
    bytes.push_back(cli::parsed_bytes_estimate(cli::input_path(input), opt.max_memory_bytes));
  return bytes;
}

// One batch: inputs read on the pool, mapped here in order, written on the pool.
class BatchRun {
 public:
  BatchRun(const Options &opt, const ToolSpec &spec, BatchReport &report, int jobs, const BatchKnobs &knobs)
      : opt_(opt), spec_(spec), report_(report), writes_(2 * static_cast<size_t>(jobs)),
        ahead_(opt.inputs.size(), 2 * static_cast<size_t>(jobs),
               knobs.read_first ? opt.inputs.size() : knobs.ahead_per_thread * static_cast<size_t>(jobs),
               knobs.read_first ? UINT64_MAX : read_ahead_budget(), read_estimates(opt),
               knobs.read_first ? UINT64_MAX : knobs.read_worst),
        read_(opt.inputs.size()), pool_(jobs, knobs.nice) {}

  ~BatchRun() { stop_reads(); }  // queued reads return at once; the pool drains

  void start_reads() {
    std::lock_guard<std::mutex> lock(ahead_mutex_);
    submit_admitted();
  }

  // Until every input's read has ended (VASCO_BATCH_READ_FIRST: each let
  // through, the read-ahead unbounded), or the batch stops.
  void wait_all_read() {
    std::unique_lock<std::mutex> lock(ahead_mutex_);
    all_read_.wait(lock, [this] { return reads_ended_ == read_.size() || stop_; });
  }

  // Maps inputs until none is left, each on `mapper`; several callers (one
  // thread and mapper per GPU) share the inputs, each taking the next.
  void map_all(vasco::Mapper &mapper) {
    const size_t n = read_.size();
    size_t i;
    while (!stop_ && (i = take_next()) < n) {
      std::unique_ptr<RunResult> r;
      const auto t = cli::Clock::now();
      try {
        r = read_[i].get();
      } catch (...) {
        fail(i, std::current_exception());
      }
      if (r) map_one(mapper, i, std::move(r), cli::seconds_since(t));
      release(i);  // its scans are gone (mapped, failed or put off)
    }
  }

  // Whether several mappers share a GPU: then an input that runs out of GPU
  // memory may have lacked only what another mapper holds, and is mapped
  // again at the end, alone (map_deferred). Set before the mappers start.
  void share_gpus(bool shared) { shares_gpu_ = shared; }

  // After every other mapper is gone (its GPU memory given back): the inputs
  // that ran out of memory beside them, read again and mapped on `mapper`;
  // a second failure is reported as any other.
  void map_deferred(vasco::Mapper &mapper) {
    shares_gpu_ = false;
    for (size_t i : deferred_) {
      if (stop_) break;  // report_not_run names them
      std::unique_ptr<RunResult> r;
      try {
        r = read_one(i);
      } catch (...) {
        fail(i, std::current_exception());
        continue;
      }
      map_one(mapper, i, std::move(r), 0.0);
    }
    deferred_.clear();
  }

  // After every map_all has returned.
  void report_not_run() {
    if (!stop_) return;
    for (size_t i = 0; i < read_.size(); ++i) report_.not_run(i);
  }

  // The next input to map; its read was submitted before (read-ahead) or
  // is now, so its future exists before it is waited for. None once the
  // batch stops: the read-ahead lets nothing through then.
  size_t take_next() {
    std::lock_guard<std::mutex> lock(ahead_mutex_);
    if (stop_) return read_.size();  // stop_reads() stops ahead_ under this lock
    const size_t i = next_++;
    if (i < read_.size()) ahead_.taken(i);
    submit_admitted();
    return i;
  }

 private:
  // Input i read (inflated and parsed), timed.
  std::unique_ptr<RunResult> read_one(size_t i) const {
    auto r = std::make_unique<RunResult>();
    const auto t = cli::Clock::now();
    r->input = read_input(opt_, opt_.inputs[i], spec_, nullptr);
    r->parse_s = cli::seconds_since(t);
    return r;
  }

  // Under ahead_mutex_: the reads the read-ahead lets through now.
  void submit_admitted() {
    for (size_t i : ahead_.admit()) submit_read(i);
  }

  void submit_read(size_t i) {
    auto done = std::make_shared<std::promise<std::unique_ptr<RunResult>>>();
    read_[i] = done->get_future();
    pool_.submit([this, i, done] {
      std::unique_ptr<RunResult> r;
      std::exception_ptr error;
      if (!stop_) {
        try {
          r = read_one(i);
        } catch (...) {
          error = std::current_exception();
        }
      }
      {  // counted before a mapper can have it (and release it)
        std::lock_guard<std::mutex> lock(ahead_mutex_);
        ahead_.read(i, r ? bytes_held(r->input) : 0);
        if (++reads_ended_ == read_.size()) all_read_.notify_all();
        submit_admitted();
      }
      if (error) return done->set_exception(error);
      done->set_value(std::move(r));
    });
  }

  void release(size_t i) {
    std::lock_guard<std::mutex> lock(ahead_mutex_);
    ahead_.released(i);
    submit_admitted();
  }

  void stop_reads() {
    stop_ = true;
    std::lock_guard<std::mutex> lock(ahead_mutex_);
    ahead_.stop();
    all_read_.notify_all();
  }

  // waited_s: how long this mapper waited for the input's read.
  void map_one(vasco::Mapper &mapper, size_t i, std::unique_ptr<RunResult> r, double waited_s) {
    const std::string &input = opt_.inputs[i];
    try {
      map_input(mapper, input, *r);
    } catch (const carmen::Error &e) {
      if (shares_gpu_ && e.code() == ErrorCode::OutOfMemory) return defer(i);
      return fail(i, std::current_exception());
    } catch (...) {
      return fail(i, std::current_exception());
    }
    r->input.batch = vasco::ScanBatch();  // the scans are not needed to write
    const auto t = cli::Clock::now();
    writes_.take();
    report_.mapped(i, *r, waited_s + cli::seconds_since(t));
    std::shared_ptr<RunResult> mapped(std::move(r));
    pool_.submit(
        [this, i, mapped] {
          try {
            const auto t = cli::Clock::now();
            write_outputs(opt_, opt_.inputs[i], outputs_of(opt_, opt_.inputs[i]), *mapped);
            report_.written(i, cli::seconds_since(t));
          } catch (...) {
            fail(i, std::current_exception());
          }
          writes_.give();
        },
        true);
  }

  void defer(size_t i) {
    std::lock_guard<std::mutex> lock(deferred_mutex_);
    deferred_.push_back(i);
  }

  void fail(size_t i, const std::exception_ptr &error) {
    report_.failed(i, what_of(error));
    if (opt_.fail_fast) stop_reads();
  }

  const Options &opt_;
  const ToolSpec &spec_;
  BatchReport &report_;
  Slots writes_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> shares_gpu_{false};
  std::mutex deferred_mutex_;
  std::vector<size_t> deferred_;  // out of memory beside another mapper: mapped again at the end
  std::mutex ahead_mutex_;  // ahead_, next_, reads_ended_, read_'s futures as they are made
  std::condition_variable all_read_;
  cli::ReadAhead ahead_;
  size_t next_ = 0;
  size_t reads_ended_ = 0;
  std::vector<std::future<std::unique_ptr<RunResult>>> read_;
  cli::TaskPool pool_;  // after what its tasks use (read_ included): joined first
};

int all_cores() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

// Mappers per GPU when the batch chooses: a mapper's thread spends most of a
// log on the host (the upload's copy, the finish), so several keep one GPU
// busy. batch_bench's scaling table, with the pool reading ahead while the
// backend starts, on one H100: 239 logs/s with two mappers, 270 with three,
// 275 with four (best of one: a row moves 9 % between runs); 186, 194 and
// 203 in a second run (best of three). Three, as each keeps its GPU buffers.
constexpr int kMappersPerGpu = 3;

// The GPUs a batch maps on, a mapper each: --devices' list, or --device's
// GPU alone, when given; else, for a backend that uses GPUs (cuda, auto),
// every visible GPU that is usable, kMappersPerGpu times (none: the one
// backend as before, auto then on the CPU).
std::vector<int> batch_devices(const Options &opt) {
  if (!opt.devices.empty()) return opt.devices;
  const vasco::BackendInfo *b = vasco::find_backend(opt.backend);
  if (opt.device_given || b == nullptr || !b->uses_gpus) return {opt.device};
  std::vector<int> usable;
  for (int d = 0; d < vasco::cuda_device_count(); ++d)
    if (vasco::gpu_usable(d))
      for (int k = 0; k < kMappersPerGpu; ++k) usable.push_back(d);
  if (usable.empty()) return {opt.device};
  return usable;
}

// The mappers' GPUs for the report: "GPUs 0,1", "GPU 0, 2 mappers",
// "GPUs 0,1, 2 mappers each"; a list with a GPU named more often than
// another as given ("GPUs 0,0,1").
std::string gpus_label(const std::vector<int> &devices) {
  std::vector<int> distinct;
  for (int d : devices)
    if (std::find(distinct.begin(), distinct.end(), d) == distinct.end()) distinct.push_back(d);
  const auto each = std::count(devices.begin(), devices.end(), distinct.front());
  bool even = true;
  for (int d : distinct) even &= std::count(devices.begin(), devices.end(), d) == each;
  const std::vector<int> &named = even ? distinct : devices;
  std::string list;
  for (int d : named) list += (list.empty() ? "" : ",") + std::to_string(d);
  std::string label = (named.size() > 1 ? "GPUs " : "GPU ") + list;
  if (even && each > 1) label += ", " + std::to_string(each) + (distinct.size() > 1 ? " mappers each" : " mappers");
  return label;
}

// The GPUs after the first, a thread and a mapper each, sharing the inputs
// with the first's (run.map_all on the calling thread): each log is mapped
// whole by one mapper (start_over between logs), so its bytes are those of a
// one-GPU batch. A GPU whose mapper cannot start is said and left out: the
// others map its share.
// `started` gets each GPU's entry once its mapper has started (a mapper that
// fails later still counts: it mapped).
std::thread map_on_other_devices(BatchRun &run, const Options &opt, std::vector<int> devices,
                                 std::vector<char> *started) {
  started->assign(devices.size(), 0);
  return carmen::start_thread([&run, &opt, devices, started] {
    std::vector<std::thread> workers;
    workers.reserve(devices.size());  // a push_back that throws would drop a running thread
    for (size_t k = 0; k < devices.size(); ++k) {
      workers.push_back(carmen::start_thread([&run, &opt, d = devices[k], flag = &(*started)[k]] {
        try {
          vasco::BackendOptions b = backend_options(opt);
          b.cuda_device = d;
          vasco::Mapper mapper(vasco::MapperParams{}, opt.backend, b);
          *flag = 1;  // its own element: read after the join
          run.map_all(mapper);
        } catch (const std::exception &e) {
          std::fprintf(stderr, "%s: GPU %d %s: %s\n", opt.tool.c_str(), d, *flag ? "stopped mapping" : "left out",
                       carmen::printable(e.what()).c_str());
        }
      }));
    }
    for (std::thread &w : workers) w.join();
  });
}

}  // namespace

int run_batch(const Options &opt, const ToolSpec &spec) {
  const auto t_start = cli::Clock::now();
  const BatchKnobs knobs;  // a bad one is a usage error before anything is made
  carmen::remove_temporaries_on_signals();
  std::vector<BatchEntry> entries = plan_entries(opt);
  std::vector<std::string> inputs = opt.inputs, files;
  if (!opt.param_file.empty()) inputs.push_back(opt.param_file);
  for (const BatchEntry &e : entries)
    for (const std::string &f : files_written(e.outputs)) files.push_back(f);
  if (opt.json) cli::check_stdout_writable("--json");
  const OutDir out_dir(opt.out_dir);
  vasco::pipeline::check_outputs(inputs, files);

  BatchReport report(opt, std::move(entries));
  double read_first_s = 0, start_s = 0, mapped_s = 0;
  {
    const int jobs = opt.jobs > 0 ? opt.jobs : all_cores();
    BatchRun run(opt, spec, report, jobs, knobs);
    run.start_reads();  // while the backend starts
    const auto t_mappers = knobs.read_first ? (run.wait_all_read(), cli::Clock::now()) : t_start;
    read_first_s = std::chrono::duration<double>(t_mappers - t_start).count();
    const std::vector<int> devices = batch_devices(opt);
    // One mapper for every input (per GPU): its backend (a GPU's context
    // and scratch) starts once. auto weighs a workload without end
    // (backend_options: expected_renders 0): the GPU when one is usable, its
    // start-up paid once for the whole batch.
    vasco::BackendOptions first = backend_options(opt);
    first.cuda_device = devices.front();
    vasco::Mapper mapper(vasco::MapperParams{}, opt.backend, first);
    start_s = cli::seconds_since(t_mappers);
    report.set_backend(mapper.backend_name());
    const vasco::BackendInfo *chosen = vasco::find_backend(opt.backend);
    if (chosen != nullptr && chosen->chooses && !mapper.backend_traits().grid_on_device && !opt.quiet)
      std::fprintf(stderr, "%s: --backend auto: no usable GPU: using %s\n", opt.tool.c_str(), mapper.backend_name().c_str());
    const bool several = devices.size() > 1 && mapper.backend_traits().grid_on_device;
    report.set_threads(jobs, 1);  // several: the mappers that started, once they are joined
    if (several) {
      run.share_gpus(true);
      std::vector<char> started;
      std::thread others = map_on_other_devices(run, opt, std::vector<int>(devices.begin() + 1, devices.end()), &started);
      run.map_all(mapper);
      others.join();  // their mappers gone, and their GPU memory with them
      std::vector<int> mapped_on = {devices.front()};
      for (size_t k = 0; k < started.size(); ++k)
        if (started[k]) mapped_on.push_back(devices[k + 1]);
      report.set_threads(jobs, static_cast<int>(mapped_on.size()));
      report.set_backend(mapper.backend_name() + " on " + gpus_label(mapped_on));
      run.map_deferred(mapper);
    } else {
      run.map_all(mapper);
    }
    mapped_s = cli::seconds_since(t_start);
    run.report_not_run();
  }  // every write done
  const double total_s = cli::seconds_since(t_start);
  report.set_phases(read_first_s, start_s, mapped_s - start_s - read_first_s, total_s - mapped_s);
  report.print_end(total_s);
  return report.failures() > 0 ? 1 : 0;
}

}  // namespace log2map
