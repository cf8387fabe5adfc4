// The streaming CARMEN log reader (carmen_compat/log_reader.h) on bad input:
// strict mode's error for each class names the file and line; lenient mode
// skips and counts the bad lines.
#include "carmen_compat/log_reader.h"
#include "temp_dir.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <string>

#include "log_reader_test_support.h"

namespace {

using namespace logtest;

// ---------------------------------------------------------------------------
// Bad input, strict mode: one test per class; the message names file and line.

TEST(LogReaderBadInput, TruncatedLine) {
  expect_file_error(bad_log("truncated_line.log"), 4, "truncated line");
}
TEST(LogReaderBadInput, BeamCountDisagreesWithFields) {
  expect_file_error(bad_log("count_mismatch.log"), 4, "num_readings 6 disagrees");
  expect_file_error(bad_log("count_mismatch_robotlaser.log"), 4, "num_readings 4 disagrees");
  expect_file_error(bad_log("count_mismatch_robotlaser.log"), 4, "fit 5 beams");
}
TEST(LogReaderBadInput, ExtraFields) {
  expect_file_error(bad_log("extra_fields.log"), 4, "extra fields");
}
TEST(LogReaderBadInput, NonNumericField) {
  expect_file_error(bad_log("not_a_number.log"), 4, "'abc' is not a number");
  expect_file_error(bad_log("not_a_number.log"), 4, "range[2]");
  // A decimal comma (a log written under a non-C locale) is not a number.
  expect_file_error(bad_log("locale_comma.log"), 4, "'0,100000' is not a number");
}
TEST(LogReaderBadInput, NegativeCount) {
  expect_file_error(bad_log("negative_count.log"), 4, "num_readings -5 is negative");
}
TEST(LogReaderBadInput, AbsurdCount) {
  expect_file_error(bad_log("huge_count.log"), 4, "2000000000 exceeds the limit of 100000");
}
TEST(LogReaderBadInput, NanPose) {
  expect_file_error(bad_log("nan_pose.log"), 4, "FLASER x (field 7): 'nan' is not finite");
}
TEST(LogReaderBadInput, InfTimestamp) {
  expect_file_error(bad_log("inf_timestamp.log"), 4, "ipc_timestamp");
  expect_file_error(bad_log("inf_timestamp.log"), 4, "not finite");
}
TEST(LogReaderBadInput, LineTooLong) {
  LogReaderOptions opt;
  opt.max_line_length = 1024;
  expect_file_error(bad_log("long_line.log"), 4, "line longer than 1024 bytes", opt);
  opt.strict = false;
  LogStats s;
  const auto msgs = read_all(bad_log("long_line.log"), opt, &s);
  EXPECT_EQ(s.bad_lines[static_cast<int>(BadLine::TOO_LONG)], 1u);
  EXPECT_EQ(s.first_bad_line[static_cast<int>(BadLine::TOO_LONG)], 4);
  EXPECT_EQ(s.count(MessageType::FLASER), 3u);
  ASSERT_FALSE(msgs.empty());
  EXPECT_EQ(msgs.back().line, 10);
  // With the default cap the same line is fine.
  EXPECT_EQ(read_all(bad_log("long_line.log")).size(), 8u);
}
TEST(LogReaderBadInput, HugeLineWithoutNewlineIsCappedNotBuffered) {
  TempDir tmp;
  const std::string path = tmp.file("no_newline.log");
  write_file(path, "FLASER 5 " + std::string(3 << 20, '7'));
  LogReaderOptions opt;
  opt.max_line_length = 1 << 16;
  expect_file_error(path, 1, "line longer than 65536 bytes", opt);
  opt.strict = false;
  LogStats s;
  EXPECT_TRUE(read_all(path, opt, &s).empty());
  EXPECT_EQ(s.bad_lines[static_cast<int>(BadLine::TOO_LONG)], 1u);
  EXPECT_EQ(s.bytes, (3u << 20) + 9u);
}
// Strict mode: after the error for a line too long to hold, next() goes on
// with the line after it (it used to throw again and again, never advancing).
TEST(LogReaderBadInput, AfterAnOverlongLineStrictReadingGoesOn) {
  TempDir tmp;
  const std::string path = tmp.file("long_then_good.log");
  const std::string good = "ODOM 1.0 2.0 0.5 0 0 0 100.0 host 0.0\n";
  write_file(path, good + "FLASER 5 " + std::string(3 << 20, '7') + "\n" + good);
  LogReaderOptions opt;
  opt.max_line_length = 1 << 16;
  LogReader r(path, opt);
  LogMessage m;
  ASSERT_TRUE(r.next(m));
  EXPECT_EQ(m.line, 1);
  try {
    r.next(m);
    ADD_FAILURE() << "no error for the long line";
  } catch (const FileError &e) {
    EXPECT_EQ(e.line(), 2);
  }
  ASSERT_TRUE(r.next(m));
  EXPECT_EQ(m.line, 3);
  EXPECT_EQ(m.type, MessageType::ODOM);
  EXPECT_FALSE(r.next(m));
}
// Zero bytes after the gzip stream are padding (gzip -t accepts them);
// anything else after them is still an error.
TEST(LogReaderBadInput, GzipWithTrailingZeroPaddingIsRead) {
  TempDir tmp;
  const std::string text = read_file(bad_log("good.log"));
  const std::string plain_gz = tmp.file("plain.log.gz");
  gzFile out = gzopen(plain_gz.c_str(), "wb");
  ASSERT_NE(out, nullptr);
  gzwrite(out, text.data(), static_cast<unsigned>(text.size()));
  gzclose(out);
  const std::string gz = read_file(plain_gz);
  const std::string padded = tmp.file("padded.log.gz"), garbage = tmp.file("garbage.log.gz");
  write_file(padded, gz + std::string(4096, '\0'));
  write_file(garbage, gz + std::string(16, '\0') + "X");
  EXPECT_EQ(read_all(padded).size(), read_all(bad_log("good.log")).size());
  EXPECT_THROW(read_all(garbage), FileError);
}
TEST(LogReaderBadInput, EmptyFile) {
  expect_file_error(bad_log("empty.log"), 0, "empty file");
  expect_file_error(bad_log("empty.log.gz"), 0, "empty log");
}
TEST(LogReaderBadInput, BinaryGarbage) {
  expect_file_error(bad_log("binary_garbage.log"), 1, "binary data");
  expect_file_error(bad_log("binary_garbage.log.gz"), 1, "binary data");
  // A log whose tail was overwritten with NUL bytes: the good lines are read,
  // then the damage is reported at its line.
  LogReader r(bad_log("nul_tail.log"));
  LogMessage m;
  int n = 0;
  try {
    while (r.next(m)) ++n;
    ADD_FAILURE() << "no error for the NUL tail";
  } catch (const FileError &e) {
    EXPECT_EQ(e.line(), 10);
    EXPECT_NE(std::string(e.what()).find("binary data (byte 0x00"), std::string::npos);
  }
  EXPECT_EQ(n, 7);  // PARAM + 3 ODOM + 3 FLASER
  // Lenient mode does not make binary data readable.
  LogReaderOptions lenient;
  lenient.strict = false;
  expect_file_error(bad_log("nul_tail.log"), 10, "binary data", lenient);
}
TEST(LogReaderBadInput, GzipDataUnderAPlainName) {
  TempDir tmp;
  const std::string path = tmp.file("intel.log");
  write_file(path, read_file(bundled_log("intel.gfs.log.gz")));
  expect_file_error(path, 1, "gzip-compressed but its name does not end in .gz");
}
TEST(LogReaderBadInput, PlainTextUnderAGzName) {
  // As zlib's gzread: read as it is.
  TempDir tmp;
  const std::string path = tmp.file("good.log.gz");
  write_file(path, read_file(bad_log("good.log")));
  LogReader r(path);
  EXPECT_FALSE(r.compressed());
  LogMessage m;
  int n = 0;
  while (r.next(m)) ++n;
  EXPECT_EQ(n, 401);
}
TEST(LogReaderBadInput, TruncatedGzip) {
  // Every complete line before the cut is delivered, then the error.
  LogReader r(bad_log("truncated.log.gz"));
  LogMessage m;
  long last = 0;
  try {
    while (r.next(m)) last = m.line;
    ADD_FAILURE() << "truncated gzip read as a short log";
  } catch (const FileError &e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(bad_log("truncated.log.gz") + ":", 0), 0u) << what;
    EXPECT_NE(what.find("truncated gzip stream"), std::string::npos) << what;
    EXPECT_EQ(e.line(), last + 1);
  }
  EXPECT_GT(last, 100);
  LogReaderOptions lenient;
  lenient.strict = false;
  expect_file_error(bad_log("truncated.log.gz"), 264, "truncated gzip stream", lenient);
}
TEST(LogReaderBadInput, CorruptGzip) {
  expect_file_error(bad_log("corrupt.log.gz"), 192, "corrupt gzip stream");
  expect_file_error(bad_log("bad_crc.log.gz"), 404, "incorrect data check");
  expect_file_error(bad_log("trailing_garbage.log.gz"), 404, "not gzip data");
}
TEST(LogReaderBadInput, MissingFileAndDirectory) {
  expect_file_error(bad_log("does_not_exist.log"), 0, "cannot open");
  expect_file_error(std::string(VASCO_TEST_DATA_DIR) + "/logs", 0, "is a directory");
}

// ---------------------------------------------------------------------------
// Lenient mode and data that is not an error.

TEST(LogReaderLenient, CountsEachBadClassWithItsFirstLine) {
  LogReaderOptions opt;
  opt.strict = false;
  opt.max_line_length = 1024;
  LogStats s;
  const auto msgs = read_all(bad_log("mixed_bad.log"), opt, &s);
  auto bad = [&](BadLine k) { return s.bad_lines[static_cast<int>(k)]; };
  auto first = [&](BadLine k) { return s.first_bad_line[static_cast<int>(k)]; };
  EXPECT_EQ(bad(BadLine::TRUNCATED), 1u);
  EXPECT_EQ(first(BadLine::TRUNCATED), 6);
  EXPECT_EQ(bad(BadLine::FIELD_COUNT), 2u);
  EXPECT_EQ(first(BadLine::FIELD_COUNT), 7);
  EXPECT_EQ(bad(BadLine::NOT_A_NUMBER), 1u);
  EXPECT_EQ(first(BadLine::NOT_A_NUMBER), 9);
  EXPECT_EQ(bad(BadLine::BAD_COUNT), 2u);
  EXPECT_EQ(first(BadLine::BAD_COUNT), 10);
  EXPECT_EQ(bad(BadLine::NON_FINITE), 1u);
  EXPECT_EQ(first(BadLine::NON_FINITE), 12);
  EXPECT_EQ(bad(BadLine::TOO_LONG), 1u);
  EXPECT_EQ(first(BadLine::TOO_LONG), 13);
  EXPECT_EQ(s.total_bad_lines(), 8u);
  // PARAM + (ODOM, FLASER) before and after the bad block.
  ASSERT_EQ(msgs.size(), 5u);
  EXPECT_EQ(msgs[3].line, 14);
  EXPECT_EQ(msgs[4].line, 15);
  EXPECT_EQ(msgs[4].laser.timestamp, 2000.5);
  EXPECT_EQ(s.lines, 15u);
  const std::string sum = s.summary();
  EXPECT_NE(sum.find("1 truncated (first at line 6)"), std::string::npos) << sum;
  EXPECT_NE(sum.find("1 too long (first at line 13)"), std::string::npos) << sum;
  // The same file in strict mode stops at the first bad line.
  expect_file_error(bad_log("mixed_bad.log"), 6, "truncated line");
}

TEST(LogReaderLenient, EveryBadFileIsSkippedLineByLine) {
  LogReaderOptions opt;
  opt.strict = false;
  for (const char *f : {"truncated_line.log", "count_mismatch.log", "count_mismatch_robotlaser.log",
                        "not_a_number.log", "locale_comma.log", "negative_count.log",
                        "huge_count.log", "nan_pose.log", "inf_timestamp.log", "extra_fields.log"}) {
    SCOPED_TRACE(f);
    LogStats s;
    const auto msgs = read_all(bad_log(f), opt, &s);
    EXPECT_EQ(s.total_bad_lines(), 1u);
    EXPECT_EQ(msgs.size(), 7u);  // PARAM + 3 ODOM + 3 FLASER
  }
}

}  // namespace
