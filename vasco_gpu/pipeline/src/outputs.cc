// The pipeline's outputs (outputs.h).
#include "vasco_gpu/pipeline/outputs.h"

#include <algorithm>
#include <map>
#include <tuple>
#include <utility>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"

namespace vasco {
namespace pipeline {

using carmen::Error;
using carmen::ErrorCode;

std::string output_stem(const std::string &input) {
  std::string name = input;
  while (name.size() > 1 && name.back() == '/') name.pop_back();  // a ROS 2 bag's directory
  const size_t slash = name.rfind('/');
  if (slash != std::string::npos) name.erase(0, slash + 1);
  if (name.size() > 3 && name.compare(name.size() - 3, 3, ".gz") == 0) name.resize(name.size() - 3);
  const size_t dot = name.rfind('.');
  if (dot != std::string::npos && dot > 0) name.resize(dot);
  return name;
}

std::vector<std::string> check_map_formats(const std::vector<std::string> &names, const std::string &what) {
  if (names.empty()) throw Error(ErrorCode::Usage, what + ": at least one of " + carmen::known_map_format_names());
  std::vector<std::pair<std::string, std::string>> files;  // (a file of STEM, its format)
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string &f = names[i];
    if (carmen::find_map_format_by_name(f) == nullptr)
      throw Error(ErrorCode::Usage, what + ": '" + carmen::printable(f) + "' is none of " + carmen::known_map_format_names());
    if (std::find(names.begin(), names.begin() + static_cast<long>(i), f) != names.begin() + static_cast<long>(i))
      throw Error(ErrorCode::Usage, what + ": " + f + " is named twice");
    const std::vector<std::string> mine = carmen::map_output_files("STEM." + f);
    for (const std::string &file : mine)
      for (const auto &[other_file, other] : files)
        if (file == other_file) throw Error(ErrorCode::Usage, what + ": " + other + " and " + f + " both write " + file);
    for (const std::string &file : mine) files.emplace_back(file, f);
  }
  return names;
}

std::vector<PlannedInput> plan_outputs(const std::vector<std::string> &inputs, const std::string &out_dir,
                                       const std::vector<std::string> &formats, const std::string &who) {
  const std::string dir = out_dir.empty() || out_dir.back() == '/' ? out_dir : out_dir + "/";
  std::vector<PlannedInput> plan;
  std::map<std::string, std::string> by_stem;
  for (const std::string &input : inputs) {
    const std::string stem = output_stem(input);
    if (stem.empty() || stem == "/")
      throw Error(ErrorCode::Usage, who + "'" + carmen::printable(input) + "': no file name to name its outputs after");
    const auto [at, fresh] = by_stem.emplace(stem, input);
    if (!fresh)
      throw Error(ErrorCode::Usage, who + at->second + " and " + input + " would both write " + dir + stem +
                                        ".*: give inputs of different names (or map them in two runs)");
    PlannedInput p;
    p.input = input;
    for (const std::string &f : formats) p.outputs.push_back(dir + stem + "." + f);
    plan.push_back(std::move(p));
  }
  return plan;
}

std::vector<std::string> output_files(const std::vector<std::string> &outputs) {
  std::vector<std::string> files;
  for (const std::string &out : outputs) {
    const std::vector<std::string> of_one = carmen::map_output_files(out);
    files.insert(files.end(), of_one.begin(), of_one.end());
  }
  return files;
}

namespace {

// Paths by target (carmen::TargetKey): each path is looked at once and found
// in a map, so a batch of thousands of outputs is checked in one pass, not
// pair by pair.
class TargetIndex {
 public:
  // The index given with an earlier path of the same target, or -1.
  long find(const carmen::TargetKey &k) const {
    if (k.has_file) {
      const auto f = files_.find({k.file_dev, k.file_ino});
      if (f != files_.end()) return static_cast<long>(f->second);
    }
    if (k.has_place) {
      const auto p = places_.find(std::make_tuple(k.dir_dev, k.dir_ino, k.name));
      if (p != places_.end()) return static_cast<long>(p->second);
    }
    return -1;
  }
  void add(const carmen::TargetKey &k, size_t index) {
    if (k.has_file) files_.emplace(std::make_pair(k.file_dev, k.file_ino), index);
    if (k.has_place) places_.emplace(std::make_tuple(k.dir_dev, k.dir_ino, k.name), index);
  }

 private:
  std::map<std::pair<unsigned long long, unsigned long long>, size_t> files_;
  std::map<std::tuple<unsigned long long, unsigned long long, std::string>, size_t> places_;
};

}  // namespace

void check_outputs(const std::vector<std::string> &inputs, const std::vector<std::string> &output_files,
                   bool replaceable) {
  TargetIndex read, written;
  for (size_t i = 0; i < inputs.size(); ++i)
    if (!inputs[i].empty()) read.add(carmen::target_key(inputs[i]), i);
  for (size_t i = 0; i < output_files.size(); ++i) {
    const std::string &out = output_files[i];
    const carmen::TargetKey key = carmen::target_key(out);
    const long in = read.find(key);
    if (in >= 0)
      throw Error(ErrorCode::Usage, out + ": is the input " + inputs[static_cast<size_t>(in)] +
                                        ": an output must not overwrite what is read");
    const long earlier = written.find(key);
    if (earlier >= 0)
      throw Error(ErrorCode::Usage, out + ": the same file as the output " +
                                        output_files[static_cast<size_t>(earlier)] + ": give each output once");
    written.add(key, i);
  }
  if (!replaceable) return;
  for (const std::string &out : output_files) carmen::check_replaceable(out);
}

void write_map_outputs(const std::vector<std::string> &outputs, const carmen::MapToWrite &map) {
  carmen::OutputTransaction tx;
  for (const std::string &out : outputs) carmen::write_map(tx, out, map);
  tx.commit();
}

}  // namespace pipeline
}  // namespace vasco
