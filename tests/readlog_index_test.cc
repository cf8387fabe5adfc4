// CARMEN's readlog C API (carmen/readlog.h): the log index, CARMEN's reading
// loop on damaged logs, and the index's bound.
#include "carmen/readlog.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "readlog_test_support.h"

namespace {

using readlogtest::bad_log;

// CARMEN's progress lines, exactly.
TEST(ReadlogIndex, PrintsCarmensProgress) {
  testing::internal::CaptureStderr();
  carmen_FILE *fp = carmen_fopen(bad_log("good.log").c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  const std::string err = testing::internal::GetCapturedStderr();
  ASSERT_NE(idx, nullptr);
  EXPECT_EQ(err, "\n\rIndexing messages (0%)    \rIndexing messages (100%) - " + std::to_string(idx->num_messages) +
                     " messages found.      \n");
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);

  // A line every 10 MB (CARMEN: every 1000 reads of 10000 bytes).
  char tmpl[] = "/tmp/vasco_readlog_progress_XXXXXX";
  const int fd = mkstemp(tmpl);
  ASSERT_GE(fd, 0);
  close(fd);
  {
    std::ofstream out(tmpl, std::ios::binary);
    const std::string line(99, 'x');
    for (int i = 0; i < 250000; ++i) out << line << '\n';  // 25 MB
  }
  testing::internal::CaptureStderr();
  fp = carmen_fopen(tmpl, "r");
  ASSERT_NE(fp, nullptr);
  idx = carmen_logfile_index_messages(fp);
  const std::string big = testing::internal::GetCapturedStderr();
  ASSERT_NE(idx, nullptr);
  EXPECT_EQ(idx->num_messages, 250000);
  EXPECT_EQ(big, "\n\rIndexing messages (0%)    \rIndexing messages (40%)      \rIndexing messages (80%)      "
                 "\rIndexing messages (100%) - 250000 messages found.      \n");
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
  std::remove(tmpl);
}

TEST(ReadlogIndex, BlankLinesUnterminatedLastLineAndLimits) {
  char tmpl[] = "/tmp/readlog_test_XXXXXX";
  const int fd = mkstemp(tmpl);
  ASSERT_GE(fd, 0);
  close(fd);
  const std::string path = tmpl;
  {
    std::ofstream out(path, std::ios::binary);
    out << "ODOM 1 2 3 0 0 0 5 h 1\n\nFLASER 1 2.0 0 0 0 0 0 0 6 h 2\n\rX\nlast";
  }
  carmen_FILE *fp = carmen_fopen(path.c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  // "ODOM...\n", "\n", "FLASER...\n\rX\n" (no message starts at '\r'), "last"
  ASSERT_EQ(idx->num_messages, 4);
  EXPECT_EQ(idx->offset[0], 0);
  EXPECT_EQ(idx->offset[1], 23);
  EXPECT_EQ(idx->offset[2], 24);
  EXPECT_EQ(idx->offset[3], 58);
  EXPECT_EQ(idx->offset[4], 62);
  EXPECT_EQ(carmen_logfile_percent_read(idx), 0.0f);
  char line[128];
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 3, sizeof line, line), 4);  // random access
  EXPECT_STREQ(line, "last");
  EXPECT_TRUE(carmen_logfile_eof(idx));
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 1, sizeof line, line), 1);
  EXPECT_STREQ(line, "\n");
  EXPECT_EQ(carmen_logfile_read_next_line(idx, fp, sizeof line, line), 34);
  EXPECT_EQ(std::strncmp(line, "FLASER 1 2.0", 12), 0);
  EXPECT_EQ(carmen_logfile_percent_read(idx), 0.75f);
  // Limits: a buffer too small, numbers out of range.
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 0, 23, line), -1);
  EXPECT_NE(std::string(carmen_readlog_last_error()).find("23 bytes"), std::string::npos);
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 0, 24, line), 23);
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 4, sizeof line, line), -1);
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, -1, sizeof line, line), -1);
  EXPECT_EQ(carmen_logfile_read_line(nullptr, fp, 0, sizeof line, line), -1);
  carmen_logfile_free_index(&idx);
  carmen_logfile_free_index(&idx);  // harmless twice
  carmen_fclose(fp);
  std::remove(path.c_str());
  EXPECT_EQ(carmen_logfile_index_messages(nullptr), nullptr);
  EXPECT_TRUE(carmen_logfile_eof(nullptr));
}

// CARMEN's own reading loop (vasco-tiny, clf-read-example) must end: on a
// damaged gzip the index holds what came before the damage, and every
// message can be read in sequence until carmen_logfile_eof().
int read_until_eof(carmen_logfile_index_p idx, carmen_FILE *fp, int buffer, int *failures) {
  std::vector<char> line(static_cast<size_t>(buffer));
  int calls = 0;
  *failures = 0;
  while (!carmen_logfile_eof(idx) && calls <= idx->num_messages) {
    if (carmen_logfile_read_next_line(idx, fp, buffer, line.data()) < 0) ++*failures;
    ++calls;
  }
  return calls;
}

TEST(ReadlogIndex, DamagedGzipIndexesWhatCameBefore) {
  for (const char *f : {"truncated.log.gz", "corrupt.log.gz", "bad_crc.log.gz"}) {
    SCOPED_TRACE(f);
    carmen_FILE *fp = carmen_fopen(bad_log(f).c_str(), "r");
    ASSERT_NE(fp, nullptr);
    carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
    ASSERT_NE(idx, nullptr);
    EXPECT_NE(std::string(carmen_readlog_last_error()).find("gzip"), std::string::npos);
    int failures = 0;
    EXPECT_EQ(read_until_eof(idx, fp, 1 << 16, &failures), idx->num_messages);
    EXPECT_TRUE(carmen_logfile_eof(idx));
    carmen_logfile_free_index(&idx);
    carmen_fclose(fp);
  }
  // A good gzip log indexes every line.
  carmen_FILE *fp = carmen_fopen(bad_log("two_members.log.gz").c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  EXPECT_EQ(idx->num_messages, 11);
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
}

// A message longer than the caller's buffer is skipped with a message (CARMEN
// exits there); the loop goes on to the end instead of spinning.
TEST(ReadlogIndex, AMessageLongerThanTheBufferIsSkippedNotSpunOn) {
  char tmpl[] = "/tmp/vasco_readlog_XXXXXX";
  const int fd = mkstemp(tmpl);
  ASSERT_GE(fd, 0);
  close(fd);
  {
    std::ofstream out(tmpl, std::ios::binary);
    out << "ODOM 1 2 3 0 0 0 5 h 1\n" << "ODOM " << std::string(500, '1') << "\n" << "ODOM 1 2 3 0 0 0 7 h 3\n";
  }
  carmen_FILE *fp = carmen_fopen(tmpl, "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  ASSERT_EQ(idx->num_messages, 3);
  int failures = 0;
  EXPECT_EQ(read_until_eof(idx, fp, 64, &failures), 3);
  EXPECT_EQ(failures, 1);
  // And the line after the long one was read whole.
  char line[64];
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 2, sizeof line, line), 23);
  EXPECT_EQ(std::strncmp(line, "ODOM 1 2 3 0 0 0 7", 18), 0);
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
  std::remove(tmpl);
}

}  // namespace

namespace {

// A gzip log of `n` newlines and nothing else (a 204 KB one held 209 M
// messages for CARMEN's rule: an index of 3.3 GB).
std::string newlines_gz(int n) {
  char tmpl[] = "/tmp/vasco_readlog_nl_XXXXXX";
  const int fd = mkstemp(tmpl);
  close(fd);
  const std::string path = std::string(tmpl) + ".gz";
  std::rename(tmpl, path.c_str());
  gzFile out = gzopen(path.c_str(), "wb");
  const std::string block(1 << 16, '\n');
  for (int done = 0; done < n; done += static_cast<int>(block.size()))
    gzwrite(out, block.data(), static_cast<unsigned>(std::min<int>(n - done, static_cast<int>(block.size()))));
  gzclose(out);
  return path;
}

TEST(ReadlogIndex, TheIndexIsBoundedAndSaysSo) {
  EXPECT_EQ(carmen_logfile_set_max_messages(0), CARMEN_LOGFILE_MAX_MESSAGES);  // 0: only asks
  const int before = carmen_logfile_set_max_messages(100000);
  const std::string over = newlines_gz(1000000), at = newlines_gz(100000);
  carmen_FILE *fp = carmen_fopen(over.c_str(), "r");
  ASSERT_NE(fp, nullptr);
  EXPECT_EQ(carmen_logfile_index_messages(fp), nullptr);
  EXPECT_NE(std::string(carmen_readlog_last_error()).find("more than 100000 messages"), std::string::npos)
      << carmen_readlog_last_error();
  carmen_fclose(fp);
  // Exactly the limit is indexed.
  fp = carmen_fopen(at.c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  EXPECT_EQ(idx->num_messages, 100000);
  EXPECT_EQ(idx->offset[99999], 99999);
  EXPECT_EQ(idx->offset[100000], 100000);
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
  EXPECT_EQ(carmen_logfile_set_max_messages(before), 100000);
  std::remove(over.c_str());
  std::remove(at.c_str());
}

}  // namespace
