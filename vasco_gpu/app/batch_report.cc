#include "batch_report.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "carmen_compat/error.h"
#include "cli_support.h"

namespace log2map {

BatchReport::BatchReport(const Options &opt, std::vector<BatchEntry> entries)
    : opt_(opt), entries_(std::move(entries)), bar_("maps", progress_wanted(opt)) {}

void BatchReport::advance() {
  ++finished_;
  bar_.update(finished_, entries_.size());
}

void BatchReport::mapped(size_t i, const RunResult &r, double waited_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  BatchEntry &e = entries_[i];
  e.scans = r.scans;
  e.parse_s = r.parse_s;
  e.map_s = r.map_total_s + r.finish_s;
  e.wait_s = waited_s;
  e.warnings = r.input.warnings;
}

void BatchReport::written(size_t i, double write_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  entries_[i].state = BatchEntry::State::Done;
  entries_[i].write_s = write_s;
  advance();
}

void BatchReport::failed(size_t i, const std::string &why) {
  std::lock_guard<std::mutex> lock(mutex_);
  entries_[i].state = BatchEntry::State::Failed;
  entries_[i].error = carmen::printable(why);
  bar_.done();
  std::fprintf(stderr, "%s: %s\n", opt_.tool.c_str(), entries_[i].error.c_str());
  advance();
}

void BatchReport::not_run(size_t i) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (entries_[i].state == BatchEntry::State::Waiting) entries_[i].state = BatchEntry::State::NotRun;
}

size_t BatchReport::failures() const {
  std::lock_guard<std::mutex> lock(mutex_);
  size_t n = 0;
  for (const BatchEntry &e : entries_) n += e.state == BatchEntry::State::Failed;
  return n;
}

namespace {

std::string joined(const std::vector<std::string> &items, const char *sep) {
  std::string s;
  for (size_t i = 0; i < items.size(); ++i) s += (i ? sep : "") + items[i];
  return s;
}

}  // namespace

void BatchReport::print_table(double total_s) const {
  const char *tool = opt_.tool.c_str();
  size_t width = 5, done = 0;
  for (const BatchEntry &e : entries_) width = std::max(width, basename_of(e.input).size());
  std::fprintf(stderr, "%s: batch of %zu inputs, backend %s\n", tool, entries_.size(), backend_.c_str());
  std::fprintf(stderr, "  %-*s %8s %8s %8s %8s  %s\n", static_cast<int>(width), "input", "scans", "read s", "map s",
               "write s", "outputs");
  for (const BatchEntry &e : entries_) {
    const std::string name = basename_of(e.input);
    for (const std::string &w : e.warnings) std::fprintf(stderr, "%s: %s: warning: %s\n", tool, name.c_str(), carmen::printable(w).c_str());
    if (e.state == BatchEntry::State::Done) {
      ++done;
      std::fprintf(stderr, "  %-*s %8zu %8.3f %8.3f %8.3f  %s\n", static_cast<int>(width), name.c_str(), e.scans, e.parse_s,
                   e.map_s, e.write_s, joined(e.outputs, ", ").c_str());
    } else {
      const std::string what = e.state == BatchEntry::State::Failed ? "FAILED: " + e.error : "not run (--fail-fast)";
      std::fprintf(stderr, "  %-*s %8s %8s %8s %8s  %s\n", static_cast<int>(width), name.c_str(), "-", "-", "-", "-", what.c_str());
    }
  }
  std::fprintf(stderr, "%s: %zu of %zu inputs mapped in %.3f s: %.1f inputs/s\n", tool, done, entries_.size(), total_s,
               total_s > 0 ? double(done) / total_s : 0.0);
}

void BatchReport::print_json(double total_s) const {
  std::ostringstream j;
  j.precision(9);
  size_t done = 0;
  j << "{\"backend\":" << cli::json_string(backend_) << ",\"inputs\":[";
  for (size_t i = 0; i < entries_.size(); ++i) {
    const BatchEntry &e = entries_[i];
    const char *state = e.state == BatchEntry::State::Done ? "done" : e.state == BatchEntry::State::Failed ? "failed" : "not_run";
    done += e.state == BatchEntry::State::Done;
    j << (i ? "," : "") << "{\"input\":" << cli::json_string(e.input) << ",\"state\":\"" << state << "\"";
    if (e.state == BatchEntry::State::Failed) j << ",\"error\":" << cli::json_string(e.error);
    if (e.state == BatchEntry::State::Done) {
      j << ",\"scans\":" << e.scans << ",\"seconds\":{\"read\":" << e.parse_s << ",\"map\":" << e.map_s
        << ",\"write\":" << e.write_s << ",\"mapper_wait\":" << e.wait_s << "},\"outputs\":[";
      for (size_t k = 0; k < e.outputs.size(); ++k) j << (k ? "," : "") << cli::json_string(e.outputs[k]);
      j << "]";
    }
    j << "}";
  }
  j << "],\"pool_threads\":" << pool_threads_ << ",\"mappers\":" << mappers_ << ",\"phases\":{\"read_first\":" << read_first_s_
    << ",\"start\":" << start_s_
    << ",\"mapping\":" << mapping_s_ << ",\"drain\":" << drain_s_ << "}";
  j << ",\"done\":" << done << ",\"failed\":" << failures() << ",\"seconds\":" << total_s
    << ",\"inputs_per_s\":" << (total_s > 0 ? double(done) / total_s : 0.0) << "}\n";
  std::fputs(j.str().c_str(), stdout);
}

void BatchReport::print_end(double total_s) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    bar_.done();
  }
  if (!opt_.quiet) print_table(total_s);
  if (opt_.json) print_json(total_s);
  std::vector<std::string> bad;
  for (const BatchEntry &e : entries_)
    if (e.state == BatchEntry::State::Failed) bad.push_back(e.input);
  if (!bad.empty())
    std::fprintf(stderr, "%s: %zu of %zu inputs failed: %s\n", opt_.tool.c_str(), bad.size(), entries_.size(),
                 joined(bad, ", ").c_str());
  if (std::fflush(stdout) != 0 || std::ferror(stdout))
    throw carmen::Error(carmen::ErrorCode::Io, std::string("the maps were written, but the statistics could not be "
                                                           "written to standard output: ") + std::strerror(errno));
}

}  // namespace log2map
