// outputs.h — the outputs of the log → map pipeline, for every front end
// (log2map, bag2map, Python's map_logs and write paths, the ROS node's
// save_map): which formats a batch may write, what each input's outputs are
// called, that no output overwrites an input or another output, and the one
// transaction that writes a map to all of them.
//
// The formats are the map-format table's (carmen_compat/map_format.h): a
// format is named by its extension without the dot ("map.gz", "pgm").
#ifndef VASCO_GPU_PIPELINE_OUTPUTS_H
#define VASCO_GPU_PIPELINE_OUTPUTS_H

#include <string>
#include <vector>

#include "carmen_compat/map_format.h"

namespace vasco {
namespace pipeline {

// The name of an input's outputs: its file (or directory) name less ".gz"
// and then one extension ("fr079.gfs.log.gz" -> "fr079.gfs", "run.mcap" ->
// "run", "bag_dir/" -> "bag_dir").
std::string output_stem(const std::string &input);

// `names` as a batch's formats: each a name of the map-format table, none
// twice, at least one, and no two writing one file (pgm and yaml both write
// STEM.yaml). Throws carmen::Error(Usage) beginning with `what` ("--formats
// 'x,y'", "map_logs: formats").
std::vector<std::string> check_map_formats(const std::vector<std::string> &names, const std::string &what);

// One input of a batch and the outputs it writes: DIR/STEM.FORMAT.
struct PlannedInput {
  std::string input;
  std::vector<std::string> outputs;
};

// Every input's outputs in `out_dir`; two inputs of one stem (they would
// write the same files) and an input without a name are refused,
// carmen::Error(Usage) beginning with `who` ("map_logs: ", "").
std::vector<PlannedInput> plan_outputs(const std::vector<std::string> &inputs, const std::string &out_dir,
                                       const std::vector<std::string> &formats, const std::string &who = "");

// Every file writing `outputs` creates (a .pgm's .yaml too), in order.
std::vector<std::string> output_files(const std::vector<std::string> &outputs);

// Refuses, carmen::Error(Usage), an output file that is one of `inputs`
// (however spelled: a link, "./x") or the same file as another output, and,
// with `replaceable`, carmen::FileError for one a rename could not replace
// (check_replaceable; a batch of Python's map_logs leaves that to each
// input's transaction, which reports it as that input's failure).
void check_outputs(const std::vector<std::string> &inputs, const std::vector<std::string> &output_files,
                   bool replaceable = true);

// Writes `map` to every one of `outputs`, each in the format of its name, as
// one transaction (carmen::OutputTransaction): all are written to temporaries
// first and renamed only when every one is written, so a failure touches no
// output and leaves no temporary.
void write_map_outputs(const std::vector<std::string> &outputs, const carmen::MapToWrite &map);

}  // namespace pipeline
}  // namespace vasco

#endif  // VASCO_GPU_PIPELINE_OUTPUTS_H
