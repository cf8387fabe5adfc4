// log2map_options.h — the command line of the log → map tools, parsed once
// into Options (log2map_options.cc); log2map_app.cc runs them.
#ifndef VASCO_GPU_TOOLS_LOG2MAP_OPTIONS_H
#define VASCO_GPU_TOOLS_LOG2MAP_OPTIONS_H

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "carmen_compat/image_io.h"
#include "log2map_app.h"
#include "vasco_gpu/option_schema.h"
#include "vasco_gpu/pipeline/log_input.h"
#include "vasco_gpu/pipeline/pose_match.h"

namespace log2map {

struct Options {
  std::string tool = "log2map";
  std::string log;  // the first input (one-log runs); the one being read (batch)
  std::vector<std::string> outputs;
  // Batch mode (--out-dir DIR): every positional is an input, mapped in one
  // process to DIR/STEM.FORMAT for each of `formats`.
  std::string out_dir;
  std::vector<std::string> inputs;
  std::vector<std::string> formats;  // map, map.gz, pgm, png
  bool fail_fast = false;
  int jobs = 0;  // batch threads reading and writing logs (0: all cores)
  int device = 0;
  bool device_given = false;  // --device N: that GPU alone, also in a batch
  std::vector<int> devices;   // --devices LIST (batch): a mapper on each; empty: every usable GPU
  std::vector<int> split_devices;  // --split-devices LIST: one render in bands across them
  std::string param_file;
  std::string robot;
  // The session's defaults (option_schema.h; its table is built on first use).
  std::string backend = vasco::option_row(vasco::session_option_table(), "backend").default_text;
  std::string cuda_mode = vasco::option_row(vasco::session_option_table(), "cuda_mode").default_text;
  int threads = 0;
  uint64_t max_memory_bytes = 0;
  bool lenient = false, json = false, quiet = false;
  std::map<std::string, std::string> overrides;  // --vasco_KEY VALUE
  std::optional<double> map_resolution;          // --resolution M: the written map's cell
  vasco::Pose2 transform;                        // --transform: the first input into the shared frame
  std::vector<vasco::SessionInput> more;         // --add INPUT[@X,Y,THETA | @auto[:HINT]]
  vasco::PoseSource poses;                       // --poses FILE and its options
  std::string laser_mount_text;                  // --laser-mount as given
  std::map<std::string, std::string> extra;      // the tool's own options, as given
  std::vector<std::string> warnings;             // options that change nothing here (said at parse time)
  // --mode, --free-thresh, --occupied-thresh, --negate: the map_server
  // outputs' (.pgm, .png+yaml, .yaml) grey levels and YAML.
  carmen::MapServerOptions map_server;
};

// Parses argv into *opt. Returns -1 to go on, else the exit status to
// return at once: 0 after --help or --version, 2 after a usage error (said
// on stderr).
int parse_options(int argc, const char *const *argv, const ToolSpec &spec, Options *opt);

// "X,Y,THETA" (metres, metres, radians; C locale) as a pose. Throws
// carmen::Error(Usage) naming `option`.
vasco::Pose2 parse_pose_triple(const std::string &text, const std::string &option);

// "--add PATH[@X,Y,THETA]": the path, and the transform when one follows the
// last '@' (a path may hold an '@' of its own when no transform follows).
// "PATH@auto": the transform found by alignment; "PATH@auto:X,Y,THETA",
// "...±R" or "...±R,RTHETA" ("+-" as well as "±"): searched near that
// guess, within R m in x and y and RTHETA rad (defaults 1 m and 0.1 rad).
vasco::SessionInput parse_session(const std::string &text);

}  // namespace log2map

#endif  // VASCO_GPU_TOOLS_LOG2MAP_OPTIONS_H
