// The streaming log reader: buffered text from a LogSource (a file, a FIFO
// or standard input, inflated when gzip), split into lines, each parsed by
// the message table (log_messages.h) and counted in LogStats.
#include "carmen_compat/log_reader.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string_view>

#include "log_number.h"
#include "log_source.h"

namespace carmen {

namespace {

// Whether every range is a finite number >= 0 (-0 included), as nearly all
// are: a test on the bits, which vectorizes where comparing floats one by
// one took a tenth of a parse.
bool all_plain_ranges(const std::vector<float> &r) {
  uint32_t odd = 0;
  for (float v : r) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    odd |= static_cast<uint32_t>(bits >= 0x7F800000u) & static_cast<uint32_t>(bits != 0x80000000u);
  }
  return odd == 0;
}

// Control bytes other than \t \n \v \f \r, and DEL, mark binary data.
inline bool is_binary_byte(unsigned char c) { return c < 9 || (c >= 14 && c < 32) || c == 127; }

const unsigned char *find_binary(const unsigned char *p, const unsigned char *e) {
  while (e - p >= 64) {
    // Byte-wide lanes throughout, so that the loop vectorizes 16 bytes at a
    // time (with unsigned lanes it ran 4 at a time, a tenth of a parse).
    unsigned char acc = 0;
    for (int i = 0; i < 64; ++i) {
      const unsigned char c = p[i];
      acc |= static_cast<unsigned char>(c < 9) |
             static_cast<unsigned char>(static_cast<unsigned char>(c - 14) < 18) |
             static_cast<unsigned char>(c == 127);
    }
    if (acc) break;
    p += 64;
  }
  for (; p < e; ++p)
    if (is_binary_byte(*p)) return p;
  return nullptr;
}

constexpr std::size_t kReadChunk = std::size_t(256) << 10;  // text per refill (stays in L2)
constexpr uint64_t kNoBinary = UINT64_MAX;
constexpr std::size_t kMaxLineCap = std::size_t(1) << 30;  // largest max_line_length honoured

// "104857600 bytes (100 MiB)".
// "1120896 bytes (1.07 MiB)": whole MiB as such, else rounded up to 0.01 MiB,
// so that a need just over a whole budget never reads as the budget itself.
std::string bytes_text(uint64_t n) {
  std::string s = std::to_string(n) + " bytes";
  if (n < (uint64_t(1) << 20)) return s;
  if (n % (uint64_t(1) << 20) == 0) return s + " (" + std::to_string(n >> 20) + " MiB)";
  const uint64_t mib = uint64_t(1) << 20;
  const uint64_t hundredths = n / mib * 100 + ((n % mib) * 100 + mib - 1) / mib;  // no wrap for any n
  char frac[8];
  std::snprintf(frac, sizeof frac, "%02d", static_cast<int>(hundredths % 100));
  return s + " (" + std::to_string(hundredths / 100) + "." + frac + " MiB)";
}

// The bytes a caller keeps of a message it keeps (see LogReaderOptions::memory_budget).
uint64_t kept_bytes(const LogMessage &msg) {
  if (is_laser_message(msg.type)) return kBudgetBytesPerMessage + sizeof(float) * msg.laser.range.size();
  if (msg.type == MessageType::PARAM)
    return kBudgetBytesPerMessage + msg.param.name.size() + msg.param.value.size();
  return 0;
}

}  // namespace

struct LogReader::Impl {
  LogReaderOptions opt;
  LogStats stats;
  std::unique_ptr<LogSource> source;

  // Text buffer: [pos, lim) not yet consumed; buf[0] is stream offset base.
  // Not zero-filled: most of its max_line_length part (4 MiB by default) is
  // never touched, and so never paged in.
  std::unique_ptr<char[]> buf;
  std::size_t buf_size = 0;
  std::size_t pos = 0, lim = 0, scan = 0;
  uint64_t base = 0;
  bool at_start = true;  // no text read yet: a UTF-8 byte order mark may come
  uint64_t binary_at = kNoBinary;
  unsigned char binary_byte = 0;
  bool skipping = false;  // lenient: discarding the rest of an over-long line

  long line_no = 0;
  LineError err;

  const std::string &path() const { return source->name(); }
  [[noreturn]] void fail(long line, const std::string &m, ErrorCode code = ErrorCode::BadInput) const {
    throw FileError(path(), line, m, code);
  }

  void open(const std::string &file) {
    source = std::make_unique<LogSource>(file, opt.fifo_wait_ms, kReadChunk);
    opt.max_line_length = std::min(std::max(opt.max_line_length, std::size_t(16)), kMaxLineCap);
    buf_size = opt.max_line_length + kReadChunk + 1;
    buf.reset(new char[buf_size]);
    fill();
    if (lim == 0) {
      if (!source->error().empty()) fail(0, source->error());
      fail(0, source->gz() ? "empty log: the gzip stream holds no data" : "empty file");
    }
  }

  // Appends more text to the buffer (compacting it first).
  void fill() {
    if (pos > 0) {
      std::memmove(buf.get(), buf.get() + pos, lim - pos);
      base += pos;
      lim -= pos;
      scan -= pos;
      pos = 0;
    }
    const std::size_t room = std::min(buf_size - 1 - lim, kReadChunk);
    char *dst = buf.get() + lim;
    const std::size_t n = source->read(dst, room);
    if (binary_at == kNoBinary && n > 0) {
      const auto *u = reinterpret_cast<const unsigned char *>(dst);
      if (const unsigned char *b = find_binary(u, u + n)) {
        binary_at = base + lim + static_cast<uint64_t>(b - u);
        binary_byte = *b;
      }
    }
    lim += n;
    stats.bytes += n;
    if (at_start && n > 0) skip_byte_order_mark();
  }

  // Editors on Windows start UTF-8 text with EF BB BF; it is not part of the
  // first line (whose name it would hide).
  void skip_byte_order_mark() {
    at_start = false;
    if (lim >= 3 && std::memcmp(buf.get(), "\xEF\xBB\xBF", 3) == 0) pos = scan = 3;
  }

  [[noreturn]] void binary_error(long line) const {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02x", binary_byte);
    std::string m = std::string("binary data (byte ") + hex + " at offset " +
                    std::to_string(binary_at) + "): not a CARMEN text log";
    if (!source->gz() && source->gzip_magic())
      m += " (the file is gzip-compressed but its name does not end in .gz)";
    fail(line, m);
  }

  // Next line into [b, e) (without '\n'). False at the end of the data.
  bool next_line(const char *&b, const char *&e) {
    for (;;) {
      char *const data = buf.get();
      const void *nl = scan < lim ? std::memchr(data + scan, '\n', lim - scan) : nullptr;
      if (nl) {
        const std::size_t at = static_cast<std::size_t>(static_cast<const char *>(nl) - data);
        if (binary_at != kNoBinary && binary_at < base + at) binary_error(line_no + 1);
        if (skipping) {  // the end of an over-long line: drop it
          skipping = false;
          pos = scan = at + 1;
          continue;
        }
        ++line_no;
        if (at - pos > opt.max_line_length) {
          pos = scan = at + 1;
          too_long();
          continue;
        }
        b = data + pos;
        e = data + at;
        pos = scan = at + 1;
        return true;
      }
      scan = lim;
      if (binary_at != kNoBinary && binary_at < base + lim) binary_error(line_no + 1);
      if (skipping) pos = scan = lim;  // discard what we have of the long line
      if (!skipping && lim - pos > opt.max_line_length) {
        // Skip it before reporting it: in strict mode too_long() throws, and a
        // later next() must go on after this line, not report it again.
        ++line_no;
        skipping = true;
        pos = scan = lim;
        too_long();
      }
      if (!source->error().empty()) fail(line_no + (skipping ? 0 : 1), source->error());
      if (source->eof()) {
        if (pos < lim && !skipping) {  // a last line without '\n'
          ++line_no;
          b = data + pos;
          e = data + lim;
          pos = scan = lim;
          return true;
        }
        return false;
      }
      fill();
    }
  }

  void too_long() {
    const std::string m = "line longer than " + std::to_string(opt.max_line_length) +
                          " bytes (binary data or a damaged log?)";
    if (opt.strict) fail(line_no, m);
    count_bad(BadLine::TOO_LONG);
  }

  void count_bad(BadLine k) {
    const int i = static_cast<int>(k);
    ++stats.bad_lines[i];
    ++stats.lines;
    if (stats.first_bad_line[i] == 0) stats.first_bad_line[i] = line_no;
  }

  void note_unknown(const char *b, const char *e) {
    ++stats.unknown_lines;
    std::string_view name(b, static_cast<std::size_t>(e - b));
    if (name.size() > 64) name = name.substr(0, 64);
    for (auto &u : stats.unknown_names) {
      if (u.first == name) {
        ++u.second;
        return;
      }
    }
    if (stats.unknown_names.size() < 16) stats.unknown_names.emplace_back(std::string(name), 1);
  }

  void count_ranges(const std::vector<float> &r) {
    if (all_plain_ranges(r)) return;
    for (float v : r) {
      if (__builtin_expect(!(v >= 0.0f) || v > FLT_MAX, 0)) {
        if (std::isnan(v)) ++stats.nan_ranges;
        else if (std::isinf(v)) ++stats.inf_ranges;
        else ++stats.negative_ranges;
      }
    }
  }

  // Counts what the caller keeps of msg against the budget; throws once it is passed.
  void charge(const LogMessage &msg) {
    if (!(opt.budget_types & message_type_bit(msg.type))) return;
    stats.kept_bytes += kept_bytes(msg);
    if (opt.memory_budget == 0 || stats.kept_bytes <= opt.memory_budget) return;
    fail(line_no,
         "the log's ranges and PARAM lines up to here need " + bytes_text(stats.kept_bytes) +
             ", more than the memory budget of " + bytes_text(opt.memory_budget) + "; raise it with " +
             opt.budget_option,
         ErrorCode::OutOfMemory);
  }

  bool next(LogMessage &msg) {
    const char *b, *e;
    while (next_line(b, e)) {
      const char *name_end = nullptr;
      const LineKind k = parse_log_line(b, e, msg, &err, &name_end);
      switch (k) {
        case LineKind::MESSAGE:
          ++stats.lines;
          ++stats.messages[static_cast<int>(msg.type)];
          msg.line = line_no;
          if (is_laser_message(msg.type)) count_ranges(msg.laser.range);
          charge(msg);
          return true;
        case LineKind::BLANK:
          ++stats.lines;
          ++stats.blank_lines;
          break;
        case LineKind::COMMENT:
          ++stats.lines;
          ++stats.comment_lines;
          break;
        case LineKind::UNKNOWN: {
          ++stats.lines;
          const char *p = b;
          while (p < name_end && lex::is_sep(*p)) ++p;
          note_unknown(p, name_end);
          break;
        }
        case LineKind::BAD:
          if (opt.strict) fail(line_no, err.message);
          count_bad(err.kind);
          break;
      }
    }
    return false;
  }
};

LogReader::LogReader(const std::string &path, LogReaderOptions options) : impl_(new Impl) {
  impl_->opt = std::move(options);
  impl_->open(path);
}

LogReader::~LogReader() = default;
LogReader::LogReader(LogReader &&) noexcept = default;
LogReader &LogReader::operator=(LogReader &&) noexcept = default;

bool LogReader::next(LogMessage &msg) { return impl_->next(msg); }
const LogStats &LogReader::stats() const { return impl_->stats; }
const std::string &LogReader::path() const { return impl_->path(); }
const LogReaderOptions &LogReader::options() const { return impl_->opt; }
uint64_t LogReader::compressed_bytes_read() const { return impl_->source->compressed_read(); }
uint64_t LogReader::file_size() const { return impl_->source->size(); }
bool LogReader::compressed() const { return impl_->source->gz(); }

std::vector<LogMessage> read_log(const std::string &path, LogReaderOptions options,
                                 LogStats *stats) {
  LogReader reader(path, std::move(options));
  std::vector<LogMessage> out;
  LogMessage m;
  while (reader.next(m)) out.push_back(m);
  if (stats) *stats = reader.stats();
  return out;
}

}  // namespace carmen
