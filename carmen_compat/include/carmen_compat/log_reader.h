// Streaming reader for CARMEN 0.7.4 text logs (.log, .clf, and gzip when the
// name ends in ".gz"), from a file, a FIFO or a pipe, or standard input
// ("-"). The input is read once from start to end, never rewound; from a
// pipe, gzip is recognised by its magic bytes. A leading UTF-8 byte order
// mark is skipped.
//
// One line is one message. The reader dispatches on the exact first token
// (FLASER, RLASER, ROBOTLASER1/2, RAWLASER1..4, ODOM, TRUEPOS, PARAM, SYNC);
// every other line (NEFF, VERTEX2, "#..." comments, blank lines, LASER3, ...)
// is skipped and counted in LogStats.
//
// Unlike CARMEN's readlog.c, which reads fields with sequential strtod() and no
// validation (a missing number shifts every later field, a huge count kills the
// process), this reader checks every line:
//   - strict mode (the default) throws FileError("FILE:LINE: what is wrong")
//     for a truncated line, a beam count that disagrees with the fields
//     present, a non-numeric field, a negative or absurd count (> 100000), or a
//     NaN/inf value anywhere except in ranges and remissions;
//   - lenient mode skips such lines and counts them per BadLine class.
// NaN, inf and negative ranges are data: accepted, stored and counted.
// In both modes a corrupt or truncated gzip stream, an empty file, binary data
// (NUL or other control bytes) and a line longer than the cap (strict mode) are
// a FileError naming the file; in lenient mode an over-long line is skipped.
//
// Numbers are parsed in the C locale with std::from_chars. Ranges and
// remissions are parsed as double and stored as float, as CARMEN does.
#ifndef CARMEN_COMPAT_LOG_READER_H
#define CARMEN_COMPAT_LOG_READER_H

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "carmen_compat/error.h"

namespace carmen {

enum class MessageType {
  FLASER, RLASER,
  ROBOTLASER1, ROBOTLASER2,
  RAWLASER1, RAWLASER2, RAWLASER3, RAWLASER4,
  ODOM, TRUEPOS, PARAM, SYNC
};
constexpr int kNumMessageTypes = 12;

// The name as written in a log ("FLASER", "ROBOTLASER1", ...).
const char *message_type_name(MessageType type);
// Exact match of a first token against the names above.
bool message_type_from_name(const char *name, std::size_t length, MessageType *type);
// FLASER, RLASER, ROBOTLASERn and RAWLASERn.
bool is_laser_message(MessageType type);
// The bit of `type` in LogReaderOptions::budget_types.
constexpr uint32_t message_type_bit(MessageType type) { return uint32_t(1) << static_cast<int>(type); }

// Every laser type and PARAM, each named (not a range of the enum, so that
// the budget's default does not move when a type is added or reordered).
constexpr uint32_t kLaserAndParamBits =
    message_type_bit(MessageType::FLASER) | message_type_bit(MessageType::RLASER) |
    message_type_bit(MessageType::ROBOTLASER1) | message_type_bit(MessageType::ROBOTLASER2) |
    message_type_bit(MessageType::RAWLASER1) | message_type_bit(MessageType::RAWLASER2) |
    message_type_bit(MessageType::RAWLASER3) | message_type_bit(MessageType::RAWLASER4) |
    message_type_bit(MessageType::PARAM);

struct Point { double x = 0, y = 0, theta = 0; };

struct LaserConfig {
  int laser_type = 0;  // 0 SICK_LMS, 1 SICK_PLS, 2 HOKUYO_URG, 3 SIMULATED, 4 SICK_S300, 99 unknown
  double start_angle = 0, fov = 0, angular_resolution = 0, maximum_range = 0, accuracy = 0;
  int remission_mode = 0;  // 0 none, 1 direct, 2 normalized
};

// FLASER / RLASER / ROBOTLASERn / RAWLASERn.
struct LaserMessage {
  int id = -1;            // n of RAWLASERn / ROBOTLASERn; -1 for FLASER / RLASER
  LaserConfig config;     // guessed from the beam count for FLASER / RLASER
  std::vector<float> range;
  std::vector<float> remission;  // empty for FLASER / RLASER
  bool has_pose = false;  // false for RAWLASER
  // FLASER/RLASER: laser_pose = the first triple, robot_pose = the odom triple.
  Point laser_pose, robot_pose;
  // ROBOTLASER only (0 for the others).
  double tv = 0, rv = 0, forward_safety_dist = 0, side_safety_dist = 0, turn_axis = 0;
  double timestamp = 0;  // ipc_timestamp
  std::string host;
  double logger_timestamp = 0;
};

struct OdometryMessage {
  double x = 0, y = 0, theta = 0, tv = 0, rv = 0, acceleration = 0, timestamp = 0;
  std::string host;
  double logger_timestamp = 0;
};

struct TrueposMessage {
  Point truepose, odometrypose;
  double timestamp = 0;
  std::string host;
  double logger_timestamp = 0;
};

// "PARAM module_variable value ...": name and value are the first two tokens
// after PARAM (as CARMEN's param daemon reads them). What follows is not
// checked: old loggers wrote "nohost 0" instead of the three trailing fields.
struct ParamMessage { std::string name, value; };

// "SYNC tagname ...": only the tag is read.
struct SyncMessage { std::string tag; };

// Only the member for `type` is valid. A LogMessage passed to next() again is
// reused: its vectors and strings keep their capacity, so steady-state reading
// allocates nothing.
struct LogMessage {
  MessageType type = MessageType::FLASER;
  long line = 0;  // 1-based line number in the (uncompressed) file
  LaserMessage laser;
  OdometryMessage odom;
  TrueposMessage truepos;
  ParamMessage param;
  SyncMessage sync;
};

// Classes of bad lines (thrown in strict mode, skipped and counted in lenient).
enum class BadLine {
  TRUNCATED,     // too few fields: the line ends before the message does
  FIELD_COUNT,   // a count (beams, remissions) disagrees with the fields present, or extra fields
  NOT_A_NUMBER,  // a numeric field that is not a (whole) number in the C locale
  BAD_COUNT,     // a negative count, or one above kMaxCount
  NON_FINITE,    // NaN or inf in a pose, timestamp, config or velocity field
  TOO_LONG       // a line longer than LogReaderOptions::max_line_length
};
constexpr int kNumBadLineClasses = 6;
const char *bad_line_name(BadLine kind);

// Largest beam / remission count accepted.
constexpr int kMaxCount = 100000;

struct LineError {
  BadLine kind = BadLine::TRUNCATED;
  std::string message;  // without file and line
};

// What the memory budget charges for each message it counts, besides its
// ranges or text: a consumer's per-scan pose and offsets, or a PARAM's two
// strings and line number.
constexpr uint64_t kBudgetBytesPerMessage = 64;

struct LogReaderOptions {
  bool strict = true;
  // Longest line accepted, in bytes (without the '\n'); clamped to 16 B..1 GiB.
  // The read buffer is this plus 256 KiB. A 100000-beam line written with
  // "%.3f" is about 1 MB.
  std::size_t max_line_length = std::size_t(4) << 20;
  // Bytes the caller may keep of what it reads (0: no limit). Each message of
  // a type in budget_types charges kBudgetBytesPerMessage plus 4 bytes a range
  // (laser types) or the bytes of its name and value (PARAM), counted in
  // LogStats::kept_bytes as it is read; the message that passes the budget
  // throws FileError(file, line, ..., ErrorCode::OutOfMemory) naming the
  // budget and budget_option, before a larger log is read any further.
  uint64_t memory_budget = 0;
  // The types the caller keeps (message_type_bit of each); every laser type
  // and PARAM by default.
  uint32_t budget_types = kLaserAndParamBits;
  // How the user raises the budget, as the error names it ("--max-memory").
  std::string budget_option = "LogReaderOptions::memory_budget";
  // A FIFO, pipe or device named by its path is opened without waiting for a
  // writer, then waited on this long (ms) for its first byte before the
  // reader gives up with a FileError; < 0: no limit. Standard input ("-") is
  // not waited on.
  int fifo_wait_ms = 60000;
};

struct LogStats {
  std::array<uint64_t, kNumMessageTypes> messages{};  // per MessageType
  uint64_t lines = 0;          // every line seen, including blank and bad ones
  uint64_t blank_lines = 0;    // empty or white space only
  uint64_t comment_lines = 0;  // first token starts with '#' (including "#PARAM")
  uint64_t unknown_lines = 0;  // other first tokens (NEFF, VERTEX2, LASER3, ...)
  // The first few distinct unknown names with their counts (at most 16 names).
  std::vector<std::pair<std::string, uint64_t>> unknown_names;
  std::array<uint64_t, kNumBadLineClasses> bad_lines{};     // lenient mode only (by BadLine)
  std::array<long, kNumBadLineClasses> first_bad_line{};    // 0 when none
  // Ranges, classified after conversion to float.
  uint64_t nan_ranges = 0;
  uint64_t inf_ranges = 0;       // +inf or -inf
  uint64_t negative_ranges = 0;  // finite and < 0
  uint64_t bytes = 0;  // uncompressed bytes read so far (up to 256 KiB ahead of the last line)
  uint64_t kept_bytes = 0;  // charged against LogReaderOptions::memory_budget so far

  uint64_t count(MessageType type) const { return messages[static_cast<int>(type)]; }
  uint64_t laser_messages() const;  // all laser types together
  uint64_t total_messages() const;
  uint64_t total_bad_lines() const;
  std::string summary() const;  // several lines of text, for people
};

class LogReader {
 public:
  // Opens the log ("-": standard input, named "<stdin>" in errors and by
  // path()). gzip data is inflated when the name ends in ".gz" or the input
  // is not a regular file (a .gz file that is not gzip data is read as plain
  // text, as zlib's gzread does). Throws FileError when the file cannot be
  // opened (ErrorCode::Io), is empty, or its first block is damaged, and when
  // a FIFO stays silent longer than options.fifo_wait_ms.
  explicit LogReader(const std::string &path, LogReaderOptions options = {});
  ~LogReader();
  LogReader(const LogReader &) = delete;
  LogReader &operator=(const LogReader &) = delete;
  LogReader(LogReader &&) noexcept;
  LogReader &operator=(LogReader &&) noexcept;

  // Reads the next message into msg. Returns false at a clean end of the
  // file. Throws FileError (strict mode: for any bad line; both modes: damaged
  // gzip data, binary data, I/O errors). A bad line is consumed before the
  // throw, so next() may be called again to go on after it; damage to the
  // data itself (gzip, binary) throws again.
  //
  // Messages name the file and the line, then what is wrong, e.g.
  //   "fr079.log.gz:1234: FLASER range[12] (field 14): 'abc' is not a number"
  // where fields are numbered from 1 after the message name.
  bool next(LogMessage &msg);

  const LogStats &stats() const;
  const std::string &path() const;
  const LogReaderOptions &options() const;
  // For a progress bar: bytes read from the file so far and its size (0 for
  // a pipe).
  uint64_t compressed_bytes_read() const;
  uint64_t file_size() const;
  bool compressed() const;  // true when the data is being inflated

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Reads a whole log into memory (convenience for small logs and tests).
std::vector<LogMessage> read_log(const std::string &path, LogReaderOptions options = {},
                                 LogStats *stats = nullptr);

// ---------------------------------------------------------------------------
// Config guessing for FLASER / RLASER (CARMEN's carmen_laser_guess_fov and
// carmen_laser_guess_angle_increment). The expressions are evaluated in the
// same order as CARMEN writes them, dividing first:
//   fov:  181, 361 -> M_PI;  180 -> M_PI / 180.0 * 179.0;
//         360 -> M_PI / 180.0 * 179.5;  401 -> M_PI / 180.0 * 100.0;
//         400 -> M_PI / 100.0 * 99.75 (CARMEN's slip: 99.75 "degrees" of a
//         100-unit half turn, about 3.1337 rad);  other n -> M_PI.
//   step: 180, 181 -> M_PI / 180.0;  360, 361 -> M_PI / 360.0;
//         400, 401 -> M_PI / 720.0;  other n -> fov(n) / (double)(n - 1).
// The order matters: M_PI / 180.0 * 179.5 and 179.5 * M_PI / 180.0 differ in
// the last bit (likewise for 400). As in CARMEN, n = 1 gives an infinite step
// and n = 0 a step of -M_PI.
double guess_laser_fov(int num_beams);
double guess_laser_angle_increment(int num_beams);
// laser_type 0 (SICK_LMS), start_angle -M_PI / 2.0, fov and step as above,
// maximum_range 80.0, accuracy 0.01, remission_mode 0.
LaserConfig guess_laser_config(int num_beams);

// ---------------------------------------------------------------------------
// Line-level parsing, shared by LogReader and the readlog.h C API.

enum class LineKind { MESSAGE, BLANK, COMMENT, UNKNOWN, BAD };

// Parses one line [begin, end) (without the '\n'; a trailing '\r' and spaces
// or tabs between fields are accepted). MESSAGE fills msg.type and the member
// for it (msg.line is left alone); BAD fills *err. For UNKNOWN, *name_end (if
// given) receives the end of the first token.
LineKind parse_log_line(const char *begin, const char *end, LogMessage &msg, LineError *err,
                        const char **name_end = nullptr);

// Parses the fields of a message of a known type, [begin, end) starting after
// the message name. For laser types msg.laser.id is set from the type (-1 for
// FLASER/RLASER). On success, *after_host (if given) receives the position
// just past the host token (what CARMEN's converters return).
bool parse_message_fields(MessageType type, const char *begin, const char *end, LogMessage &msg,
                          LineError *err, const char **after_host = nullptr);

// Old "LASERn num_readings r[0..n-1] ipc_timestamp host logger_timestamp"
// fields (the name already skipped), with the config guessed as for FLASER.
bool parse_old_laser_fields(const char *begin, const char *end, LaserMessage &laser,
                            LineError *err, const char **after_host = nullptr);

}  // namespace carmen

#endif  // CARMEN_COMPAT_LOG_READER_H
