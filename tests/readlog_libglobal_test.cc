// readlog under CARMEN's own carmen_stdio (libglobal linked ahead of us):
// this file defines the carmen_f* functions strongly, so they replace our
// weak ones in this executable, and they return what CARMEN 0.7.4's do:
// carmen_fread passes gzread's int through (-1 on a gzip error becomes
// (size_t)-1), carmen_fseek returns gzseek's new offset on a compressed
// stream, carmen_ftell gztell's. readlog must survive every one of them.
// (Written from those return conventions; no CARMEN code.)
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "carmen/carmen_stdio.h"
#include "carmen/readlog.h"

namespace {

int g_calls = 0;                 // proves these replaced ours
long long g_fail_after = -1;     // a plain read past this many bytes fails with (size_t)-1
long long g_plain_read = 0;
bool g_seek_fails_once = false;  // the next seek gets 3 bytes short of its offset, then fails

gzFile gz(carmen_FILE *fp) { return reinterpret_cast<gzFile>(fp->comp_fp); }

bool ends_with_gz(const char *name) {
  const std::size_t n = std::strlen(name);
  return n >= 3 && std::strcmp(name + n - 3, ".gz") == 0;
}

}  // namespace

extern "C" {

carmen_FILE *carmen_fopen(const char *filename, const char *mode) {
  ++g_calls;
  auto *f = static_cast<carmen_FILE *>(std::calloc(1, sizeof(carmen_FILE)));
  f->compressed = ends_with_gz(filename);
  f->fp = std::fopen(filename, mode);
  if (f->fp == nullptr) {
    std::free(f);
    return nullptr;
  }
  if (f->compressed) f->comp_fp = reinterpret_cast<gzFile *>(gzdopen(dup(fileno(f->fp)), mode));
  g_plain_read = 0;
  return f;
}

int carmen_fclose(carmen_FILE *fp) {
  int rc = fp->compressed ? gzclose(gz(fp)) : 0;
  std::fclose(fp->fp);
  std::free(fp);
  return rc;
}

size_t carmen_fread(void *ptr, size_t size, size_t nmemb, carmen_FILE *fp) {
  ++g_calls;
  if (fp->compressed) {
    const int n = gzread(gz(fp), ptr, static_cast<unsigned>(size * nmemb));
    return static_cast<size_t>(n / static_cast<int>(size));  // -1 stays -1: (size_t)-1
  }
  if (g_fail_after >= 0 && g_plain_read + static_cast<long long>(size * nmemb) > g_fail_after)
    return static_cast<size_t>(-1);
  const size_t n = std::fread(ptr, size, nmemb, fp->fp);
  g_plain_read += static_cast<long long>(n * size);
  return n;
}

size_t carmen_fwrite(const void *ptr, size_t size, size_t nmemb, carmen_FILE *fp) {
  if (fp->compressed) return static_cast<size_t>(gzwrite(gz(fp), ptr, static_cast<unsigned>(size * nmemb))) / size;
  return std::fwrite(ptr, size, nmemb, fp->fp);
}

int carmen_fseek(carmen_FILE *fp, off_t offset, int whence) {
  ++g_calls;
  if (g_seek_fails_once) {  // as gzseek when the data goes bad part way: moved, and -1
    g_seek_fails_once = false;
    const off_t part = offset > 3 ? offset - 3 : 0;
    if (fp->compressed) {
      gzseek(gz(fp), part, whence);
    } else {
      fseeko(fp->fp, part, whence);
    }
    return -1;
  }
  if (fp->compressed) return static_cast<int>(gzseek(gz(fp), offset, whence));  // the new offset
  g_plain_read = offset;
  return fseeko(fp->fp, offset, whence);
}

off_t carmen_ftell(carmen_FILE *fp) { return fp->compressed ? gztell(gz(fp)) : ftello(fp->fp); }
int carmen_fgetc(carmen_FILE *fp) { return fp->compressed ? gzgetc(gz(fp)) : std::fgetc(fp->fp); }
int carmen_fputc(int c, carmen_FILE *fp) { return fp->compressed ? gzputc(gz(fp), c) : std::fputc(c, fp->fp); }
char *carmen_fgets(char *s, int size, carmen_FILE *fp) {
  return fp->compressed ? gzgets(gz(fp), s, size) : std::fgets(s, size, fp->fp);
}
int carmen_feof(carmen_FILE *fp) { return fp->compressed ? gzeof(gz(fp)) : std::feof(fp->fp); }
int carmen_fflush(carmen_FILE *fp) { return fp->compressed ? 0 : std::fflush(fp->fp); }
void carmen_fprintf(carmen_FILE *fp, const char *fmt, ...) {
  char buf[4096];
  va_list ap;
  va_start(ap, fmt);
  const int n = std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  if (n > 0) carmen_fwrite(buf, 1, static_cast<size_t>(n) < sizeof buf ? n : sizeof buf - 1, fp);
}

}  // extern "C"

namespace {

std::string log_path(const char *name) { return std::string(VASCO_TEST_DATA_DIR) + "/logs/" + name; }

// The lines of a gzip file as zlib reads them (each with its '\n').
std::vector<std::string> gz_lines(const std::string &path) {
  gzFile z = gzopen(path.c_str(), "rb");
  std::vector<std::string> out;
  char buf[1 << 16];
  while (gzgets(z, buf, sizeof buf) != nullptr) out.emplace_back(buf);
  gzclose(z);
  return out;
}

int read_until_eof(carmen_logfile_index_p idx, carmen_FILE *fp, int *failures) {
  std::vector<char> line(1 << 16);
  int calls = 0;
  *failures = 0;
  while (!carmen_logfile_eof(idx) && calls <= idx->num_messages) {
    if (carmen_logfile_read_next_line(idx, fp, static_cast<int>(line.size()), line.data()) < 0) ++*failures;
    ++calls;
  }
  return calls;
}

TEST(ReadlogUnderCarmensStdio, ACorruptGzipLogIsAnErrorNotACrash) {
  g_calls = 0;
  for (const char *f : {"corrupt.log.gz", "truncated.log.gz", "bad_crc.log.gz"}) {
    SCOPED_TRACE(f);
    carmen_FILE *fp = carmen_fopen(log_path(f).c_str(), "r");
    ASSERT_NE(fp, nullptr);
    carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
    ASSERT_NE(idx, nullptr) << carmen_readlog_last_error();
    EXPECT_NE(std::string(carmen_readlog_last_error()).find("gzip"), std::string::npos)
        << carmen_readlog_last_error();
    ASSERT_GE(idx->num_messages, 0);
    int failures = 0;
    EXPECT_EQ(read_until_eof(idx, fp, &failures), idx->num_messages);
    carmen_logfile_free_index(&idx);
    carmen_fclose(fp);
  }
  EXPECT_GT(g_calls, 0);  // CARMEN's stand-ins were the ones called
}

TEST(ReadlogUnderCarmensStdio, SeeksThatReturnTheOffsetAreSuccesses) {
  const std::string path = log_path("two_members.log.gz");
  const std::vector<std::string> lines = gz_lines(path);
  carmen_FILE *fp = carmen_fopen(path.c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  EXPECT_STREQ(carmen_readlog_last_error(), "");
  ASSERT_EQ(idx->num_messages, static_cast<int>(lines.size()));
  char line[1 << 16];
  // Random access: each seek's result is gzseek's offset, not 0.
  for (int i : {5, 2, 9, 0, static_cast<int>(lines.size()) - 1}) {
    SCOPED_TRACE(i);
    ASSERT_EQ(carmen_logfile_read_line(idx, fp, i, sizeof line, line), static_cast<int>(lines[i].size()))
        << carmen_readlog_last_error();
    EXPECT_EQ(std::string(line), lines[i]);
  }
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
}

// A seek that fails after moving the file leaves it somewhere the index
// does not know: the next read must not read from there.
TEST(ReadlogUnderCarmensStdio, AFailedSeekIsNotFollowedByAReadFromTheWrongPlace) {
  const std::string path = log_path("two_members.log.gz");
  const std::vector<std::string> lines = gz_lines(path);
  ASSERT_GT(lines.size(), 8u);
  carmen_FILE *fp = carmen_fopen(path.c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  ASSERT_EQ(idx->num_messages, static_cast<int>(lines.size()));
  char line[1 << 16];
  ASSERT_EQ(carmen_logfile_read_line(idx, fp, 0, sizeof line, line), static_cast<int>(lines[0].size()));
  g_seek_fails_once = true;
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 5, sizeof line, line), -1);
  EXPECT_FALSE(g_seek_fails_once);
  EXPECT_NE(std::string(carmen_readlog_last_error()).find("seek"), std::string::npos)
      << carmen_readlog_last_error();
  // Message 5 was not delivered; the next one is read from its own offset.
  ASSERT_EQ(carmen_logfile_read_next_line(idx, fp, sizeof line, line), static_cast<int>(lines[6].size()))
      << carmen_readlog_last_error();
  EXPECT_EQ(std::string(line), lines[6]);
  ASSERT_EQ(carmen_logfile_read_line(idx, fp, 2, sizeof line, line), static_cast<int>(lines[2].size()));
  EXPECT_EQ(std::string(line), lines[2]);
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
}

TEST(ReadlogUnderCarmensStdio, AReadOfMinusOneIsAReadError) {
  char tmpl[] = "/tmp/vasco_readlog_libglobal_XXXXXX";
  const int fd = mkstemp(tmpl);
  ASSERT_GE(fd, 0);
  close(fd);
  {
    std::ofstream out(tmpl, std::ios::binary);
    for (int i = 0; i < 100; ++i) out << "ODOM 1 2 3 0 0 0 " << i << " h 1\n";
  }
  // Indexing: the very first read fails.
  g_fail_after = 10;
  carmen_FILE *fp = carmen_fopen(tmpl, "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  EXPECT_EQ(idx->num_messages, 0);
  EXPECT_NE(std::string(carmen_readlog_last_error()).find("read error"), std::string::npos)
      << carmen_readlog_last_error();
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);

  // Reading a line: the index is good, then reads past byte 500 fail.
  g_fail_after = -1;
  fp = carmen_fopen(tmpl, "r");
  idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  ASSERT_EQ(idx->num_messages, 100);
  g_fail_after = 500;
  char line[256];
  int failures = 0;
  EXPECT_EQ(read_until_eof(idx, fp, &failures), 100);
  EXPECT_GT(failures, 0);
  EXPECT_LT(failures, 100);
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 99, sizeof line, line), -1);
  EXPECT_STREQ(line, "");
  g_fail_after = -1;
  EXPECT_GT(carmen_logfile_read_line(idx, fp, 99, sizeof line, line), 0);
  EXPECT_EQ(std::strncmp(line, "ODOM 1 2 3 0 0 0 99 h 1", 23), 0);
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
  std::remove(tmpl);
}

}  // namespace
