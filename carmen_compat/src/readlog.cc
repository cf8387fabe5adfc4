// CARMEN's readlog index (carmen_logfile_index_messages, read_line, ...):
// message offsets found in one pass over a carmen_FILE, bounded, and every
// carmen_stdio result taken as CARMEN's libglobal may give it. The
// converters are in readlog_messages.cc.
#include "carmen/readlog.h"

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "carmen_stdio_results.h"
#include "readlog_error.h"

namespace {

std::string &last_error() { return carmen::readlog_error_text(); }

void set_error(const std::string &m) { last_error() = m; }

// The largest index carmen_logfile_index_messages builds (readlog.h).
std::atomic<int> g_max_messages{CARMEN_LOGFILE_MAX_MESSAGES};

// Message offsets, kept in a malloc()ed array that grows by half again (it
// becomes the index's array: no copy at the end). One slot more than the
// count, for the length.
struct Offsets {
  off_t *at = nullptr;
  std::size_t count = 0, capacity = 0;
  ~Offsets() { std::free(at); }
  // Room for one more offset after the last.
  bool room() {
    if (count < capacity) return true;
    const std::size_t grown = capacity < 1024 ? 1024 : capacity + capacity / 2;
    void *p = std::realloc(at, sizeof(off_t) * grown);
    if (p == nullptr) return false;
    at = static_cast<off_t *>(p);
    capacity = grown;
    return true;
  }
  bool push(off_t offset) {
    if (!room()) return false;
    at[count++] = offset;
    return true;
  }
};

// carmen_fread as CARMEN's may return it: gzread's -1 becomes (size_t)-1,
// and nothing but 0..n is a count. Returns false for a read error.
bool read_bytes(carmen_FILE *fp, char *buf, std::size_t n, std::size_t *got) {
  const std::size_t r = carmen_fread(buf, 1, n, fp);
  if (r > n) {  // (size_t)-1, or nonsense: an error, nothing usable read
    *got = 0;
    return false;
  }
  *got = r;
  return true;
}

// CARMEN's progress report while indexing (its exact text, on stderr): a
// line of 0% first, one every 1000 reads of 10000 bytes, and the count at
// the end. The fraction is of the file's bytes: for a compressed file, of
// its compressed bytes (the position of its descriptor), as in CARMEN.
struct Progress {
  explicit Progress(carmen_FILE *fp) : fp_(fp) {
    std::fprintf(stderr, "\n\rIndexing messages (0%%)    ");
    struct stat st;
    if (fp->fp != nullptr && fstat(fileno(fp->fp), &st) == 0 && S_ISREG(st.st_mode)) length_ = st.st_size;
  }
  // After each read of kChunk bytes (kChunk / 10000 of CARMEN's reads).
  void read(off_t total) {
    reads_ += kChunk / 10000;
    if (reads_ % 1000 != 0 || length_ <= 0) return;
    off_t at = total;
    if (fp_->compressed) at = fp_->fp != nullptr ? lseek(fileno(fp_->fp), 0, SEEK_CUR) : -1;
    if (at < 0) return;
    std::fprintf(stderr, "\rIndexing messages (%.0f%%)      ",
                 static_cast<float>(at) / static_cast<float>(length_) * 100.0);
  }
  void done(std::size_t messages) {
    std::fprintf(stderr, "\rIndexing messages (100%%) - %d messages found.      \n", static_cast<int>(messages));
  }
  static constexpr std::size_t kChunk = 1000000;  // a multiple of CARMEN's 10000

 private:
  carmen_FILE *fp_;
  off_t length_ = 0;
  long long reads_ = 0;
};

// As CARMEN: index what could be read, and say what is wrong. A last
// message cut by the damage is dropped (it would be half a line).
void note_damage(carmen_FILE *infile, Offsets &offsets, bool after_newline, off_t &total) {
  const std::string what = infile->compressed ? "corrupt or truncated gzip stream" : "read error";
  if (!after_newline && offsets.count > 0) total = offsets.at[--offsets.count];
  set_error(what + " after " + std::to_string(offsets.count) + " messages: the rest of the log is lost");
  std::fprintf(stderr, "carmen_logfile_index_messages: %s\n", last_error().c_str());
  if (infile->compressed) gzclearerr(reinterpret_cast<gzFile>(infile->comp_fp));
  else if (infile->fp != nullptr) std::clearerr(infile->fp);
}

// Finds where every message starts (every byte after a '\n' but '\r', as
// CARMEN), stopping with an error at more than g_max_messages; the length of
// the stream goes in the slot after the last.
bool find_messages(carmen_FILE *infile, Offsets &offsets) {
  const std::size_t limit = static_cast<std::size_t>(g_max_messages.load());
  std::vector<char> chunk(Progress::kChunk);
  Progress progress(infile);
  off_t total = 0;
  bool after_newline = true;  // the first byte starts a message
  bool damaged = false;
  for (;;) {
    std::size_t n = 0;
    if (!read_bytes(infile, chunk.data(), chunk.size(), &n)) {
      damaged = true;
      break;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const char c = chunk[i];
      if (after_newline && c != '\r') {
        if (offsets.count == limit) {
          progress.done(offsets.count);
          set_error("more than " + std::to_string(limit) +
                    " messages: over the index's limit (carmen_logfile_set_max_messages raises it)");
          return false;
        }
        if (!offsets.push(total + static_cast<off_t>(i))) {
          progress.done(offsets.count);
          set_error("out of memory");
          return false;
        }
      }
      after_newline = c == '\n';
    }
    total += static_cast<off_t>(n);
    progress.read(total);
    if (n < chunk.size()) break;
  }
  // A short read is the end of the file or damage: CARMEN's libglobal has no
  // carmen_ferror, ours (always linked) reads the same carmen_FILE.
  if (!damaged) damaged = carmen_ferror(infile) != 0;
  progress.done(offsets.count - (damaged && !after_newline && offsets.count > 0 ? 1 : 0));
  if (damaged) note_damage(infile, offsets, after_newline, total);
  if (!offsets.room()) {  // for the length
    set_error("out of memory");
    return false;
  }
  offsets.at[offsets.count] = total;
  return true;
}

// The index over `offsets`, which hands over its array; NULL when out of memory.
carmen_logfile_index_t *make_index(Offsets &offsets) {
  auto *index = static_cast<carmen_logfile_index_t *>(std::calloc(1, sizeof(carmen_logfile_index_t)));
  if (index == nullptr) {
    set_error("out of memory");
    return nullptr;
  }
  index->num_messages = static_cast<int>(offsets.count);
  index->current_position = 0;
  index->offset = offsets.at;
  offsets.at = nullptr;
  return index;
}

}  // namespace

namespace carmen {

std::string &readlog_error_text() {
  static thread_local std::string text;
  return text;
}

}  // namespace carmen

extern "C" {

const char *carmen_readlog_last_error(void) { return carmen::readlog_error_text().c_str(); }

// ---------------------------------------------------------------------------
// Index.

carmen_logfile_index_p carmen_logfile_index_messages(carmen_FILE *infile) {
  last_error().clear();
  if (infile == nullptr) {
    set_error("NULL file");
    return nullptr;
  }
  if (!carmen::checked_seek(infile, 0, SEEK_SET)) {
    set_error("cannot rewind the log");
    return nullptr;
  }
  Offsets offsets;
  if (!find_messages(infile, offsets)) return nullptr;
  carmen_logfile_index_t *index = make_index(offsets);
  if (index && !carmen::checked_seek(infile, 0, SEEK_SET)) {
    carmen_logfile_free_index(&index);
    set_error("cannot rewind the log");
  }
  return index;
}

int carmen_logfile_set_max_messages(int max_messages) {
  const int before = g_max_messages;
  if (max_messages > 0) g_max_messages = max_messages;
  return before;
}

void carmen_logfile_free_index(carmen_logfile_index_p *pindex) {
  if (pindex == nullptr || *pindex == nullptr) return;
  std::free((*pindex)->offset);
  std::free(*pindex);
  *pindex = nullptr;
}

int carmen_logfile_eof(carmen_logfile_index_p index) {
  if (index == nullptr) return 1;
  return index->current_position >= index->num_messages ? 1 : 0;
}

float carmen_logfile_percent_read(carmen_logfile_index_p index) {
  if (index == nullptr || index->num_messages <= 0) return 1.0f;
  return static_cast<float>(index->current_position) / static_cast<float>(index->num_messages);
}

// Positions the index (and the file) at message `next`; when the file cannot
// get there, at the end, so that carmen_logfile_eof() ends a reading loop.
static void skip_to(carmen_logfile_index_p index, carmen_FILE *infile, int next) {
  if (next < index->num_messages && carmen::checked_seek(infile, index->offset[next], SEEK_SET)) {
    index->current_position = next;
  } else {
    index->current_position = index->num_messages;
  }
}

int carmen_logfile_read_line(carmen_logfile_index_p index, carmen_FILE *infile, int message_num,
                             int max_line_length, char *line) {
  last_error().clear();
  if (index == nullptr || infile == nullptr || line == nullptr || max_line_length <= 0) {
    set_error("NULL or invalid argument");
    return -1;
  }
  if (message_num < 0 || message_num >= index->num_messages) {
    set_error("message number " + std::to_string(message_num) + " out of range (0.." +
              std::to_string(index->num_messages - 1) + ")");
    return -1;
  }
  const off_t start = index->offset[message_num];
  const off_t length = index->offset[message_num + 1] - start;
  if (length >= static_cast<off_t>(max_line_length)) {
    // CARMEN exits here; we skip the message, so that a loop of
    // carmen_logfile_read_next_line until carmen_logfile_eof goes on.
    set_error("message " + std::to_string(message_num) + " has " + std::to_string(length) +
              " bytes, more than the buffer of " + std::to_string(max_line_length) + " allows: skipped");
    std::fprintf(stderr, "carmen_logfile_read_line: %s\n", last_error().c_str());
    skip_to(index, infile, message_num + 1);
    return -1;
  }
  line[0] = '\0';
  if (message_num != index->current_position) {
    if (!carmen::checked_seek(infile, start, SEEK_SET)) {
      // The file may have moved part way (gzseek can fail after skipping
      // some data): current_position no longer says where it is. Seek to
      // the next message (or the end), as after a short read, so that the
      // next read starts where the index says.
      set_error("seek failed");
      skip_to(index, infile, message_num + 1);
      return -1;
    }
    index->current_position = message_num;
  }
  std::size_t n = 0;
  const bool read_ok = read_bytes(infile, line, static_cast<std::size_t>(length), &n);
  line[n] = '\0';
  if (!read_ok || n != static_cast<std::size_t>(length)) {
    line[0] = '\0';
    set_error("short read: the log changed or is damaged");
    skip_to(index, infile, message_num + 1);  // the next call goes on, never spins
    return -1;
  }
  index->current_position = message_num + 1;
  return static_cast<int>(n);
}

int carmen_logfile_read_next_line(carmen_logfile_index_p index, carmen_FILE *infile,
                                  int max_line_length, char *line) {
  if (index == nullptr) {
    set_error("NULL index");
    return -1;
  }
  return carmen_logfile_read_line(index, infile, index->current_position, max_line_length, line);
}

}  // extern "C"

