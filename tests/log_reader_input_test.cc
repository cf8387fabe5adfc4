// Tests of where the log reader's text comes from (carmen_compat/log_reader.h):
// standard input ("-"), pipes and FIFOs, which cannot be rewound; gzip data
// recognised by its magic bytes there; a UTF-8 byte order mark.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/log_reader.h"
#include "temp_dir.h"

namespace {

using carmen::ErrorCode;
using carmen::FileError;
using carmen::LogMessage;
using carmen::LogReader;
using carmen::LogReaderOptions;
using carmen::MessageType;

const std::string kLog =
    "PARAM robot_width 0.5 nohost 0\n"
    "FLASER 3 1.5 2.25 3.0 0.1 0.2 0.3 0.4 0.5 0.6 1.0 host 2.0\n"
    "ODOM 1 2 0.5 0 0 0 3.0 host 4.0\n";

// gzip of `text`, made with zlib (gzip's own wrapper: windowBits 15 + 16).
std::string gzip_of(const std::string &text) {
  z_stream zs{};
  deflateInit2(&zs, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);
  std::string out(deflateBound(&zs, text.size()), '\0');
  zs.next_in = reinterpret_cast<Bytef *>(const_cast<char *>(text.data()));
  zs.avail_in = static_cast<uInt>(text.size());
  zs.next_out = reinterpret_cast<Bytef *>(&out[0]);
  zs.avail_out = static_cast<uInt>(out.size());
  deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

// The types of the messages read, in order.
std::vector<MessageType> types_of(LogReader &reader) {
  std::vector<MessageType> out;
  LogMessage m;
  while (reader.next(m)) out.push_back(m.type);
  return out;
}

const std::vector<MessageType> kTypes = {MessageType::PARAM, MessageType::FLASER, MessageType::ODOM};

// Makes a pipe's read end the process's standard input while it lives; a
// thread writes `data` into it and closes it.
class PipedStdin {
 public:
  explicit PipedStdin(std::string data) {
    int fds[2];
    EXPECT_EQ(pipe(fds), 0);
    saved_ = dup(STDIN_FILENO);
    dup2(fds[0], STDIN_FILENO);
    close(fds[0]);
    writer_ = std::thread([fd = fds[1], data = std::move(data)] {
      for (std::size_t done = 0; done < data.size();) {
        const ssize_t n = write(fd, data.data() + done, data.size() - done);
        if (n <= 0) break;
        done += static_cast<std::size_t>(n);
      }
      close(fd);
    });
  }
  ~PipedStdin() {
    writer_.join();
    dup2(saved_, STDIN_FILENO);
    close(saved_);
  }

 private:
  int saved_ = -1;
  std::thread writer_;
};

TEST(LogReaderInput, DashReadsStandardInput) {
  PipedStdin in(kLog + kLog);
  LogReader reader("-");
  EXPECT_EQ(reader.path(), "<stdin>");
  std::vector<MessageType> twice = kTypes;
  twice.insert(twice.end(), kTypes.begin(), kTypes.end());
  EXPECT_EQ(types_of(reader), twice);
  EXPECT_EQ(reader.file_size(), 0u);
}

TEST(LogReaderInput, DevStdinPipeIsReadWithoutRewinding) {
  PipedStdin in(kLog);
  LogReader reader("/dev/stdin");  // was "cannot rewind the file"
  EXPECT_EQ(types_of(reader), kTypes);
}

TEST(LogReaderInput, PipedGzipIsRecognisedByItsMagic) {
  PipedStdin in(gzip_of(kLog));
  LogReader reader("-");
  EXPECT_TRUE(reader.compressed());
  EXPECT_EQ(types_of(reader), kTypes);
}

TEST(LogReaderInput, PipedLongLogArrivesWhole) {
  std::string big;
  for (int i = 0; i < 20000; ++i) big += kLog;  // about 2 MB: many pipe buffers
  PipedStdin in(big);
  LogReader reader("-");
  EXPECT_EQ(types_of(reader).size(), 3u * 20000);
}

TEST(LogReaderInput, FifoWithoutWriterFailsInsteadOfBlocking) {
  TempDir dir;
  const std::string fifo = dir.file("silent.fifo");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  LogReaderOptions opt;
  opt.fifo_wait_ms = 200;
  const auto start = std::chrono::steady_clock::now();
  try {
    LogReader reader(fifo, opt);
    ADD_FAILURE() << "no error for a FIFO nobody writes to";
  } catch (const FileError &e) {
    EXPECT_EQ(e.file(), fifo);
    EXPECT_EQ(e.code(), ErrorCode::Io);
    EXPECT_NE(std::string(e.what()).find("nothing writes to this FIFO"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(LogReaderInput, FifoWhoseWriterComesLaterIsRead) {
  TempDir dir;
  const std::string fifo = dir.file("late.fifo");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const int fd = open(fifo.c_str(), O_WRONLY);
    if (fd < 0) return;
    const ssize_t n = write(fd, kLog.data(), kLog.size());
    EXPECT_EQ(n, static_cast<ssize_t>(kLog.size()));
    close(fd);
  });
  LogReader reader(fifo);
  EXPECT_EQ(types_of(reader), kTypes);
  writer.join();
}

TEST(LogReaderInput, ByteOrderMarkIsSkipped) {
  TempDir dir;
  const std::string path = dir.file("bom.log");
  std::FILE *f = std::fopen(path.c_str(), "wb");
  ASSERT_TRUE(f);
  std::fputs(("\xEF\xBB\xBF" + kLog).c_str(), f);
  std::fclose(f);
  LogReader reader(path);
  EXPECT_EQ(types_of(reader), kTypes);  // the PARAM line was dropped as an unknown one
  EXPECT_EQ(reader.stats().unknown_lines, 0u);
}

TEST(LogReaderInput, ByteOrderMarkIsSkippedInGzipFromAPipe) {
  PipedStdin in(gzip_of("\xEF\xBB\xBF" + kLog));
  LogReader reader("-");
  EXPECT_EQ(types_of(reader), kTypes);
}

TEST(LogReaderInput, ByteOrderMarkOnlyAtTheStart) {
  TempDir dir;
  const std::string path = dir.file("bom2.log");
  std::FILE *f = std::fopen(path.c_str(), "wb");
  ASSERT_TRUE(f);
  std::fputs((kLog + "\xEF\xBB\xBFPARAM a b\n").c_str(), f);
  std::fclose(f);
  LogReader reader(path);
  EXPECT_EQ(types_of(reader), kTypes);
  EXPECT_EQ(reader.stats().unknown_lines, 1u);
}

}  // namespace
