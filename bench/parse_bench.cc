// Parse-speed harness for the CARMEN log reader (not a test).
//
// Parses the bundled fr079 log several times, gzip-compressed as shipped and,
// after inflating it to a temporary file, as plain text, and prints one row per
// file: uncompressed MB, median seconds of a full parse, MB/s of log text.
// The gz row inflates on a second thread while the first parses, so it is
// bounded by the slower of the two: the plain row (parsing) or the "inflate
// only" row of the codec the reader uses (ISA-L's igzip where the build found
// it; zlib's row is printed beside it for comparison).
//
//   parse_bench [--runs N] [log ...]
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "carmen_compat/log_reader.h"
#include "gzip_stream.h"  // carmen_compat's own inflater, for the "inflate only" rows

namespace {

struct Row {
  std::string file;
  double mb = 0;
  double median_s = 0;
  uint64_t messages = 0;
};

std::string base_name(const std::string &p) {
  const auto s = p.find_last_of('/');
  return s == std::string::npos ? p : p.substr(s + 1);
}

// Inflates `gz` into `out`; false on failure.
bool inflate_to(const std::string &gz, const std::string &out) {
  gzFile in = gzopen(gz.c_str(), "rb");
  if (!in) return false;
  std::FILE *o = std::fopen(out.c_str(), "wb");
  if (!o) {
    gzclose(in);
    return false;
  }
  std::vector<char> buf(1 << 20);
  int n;
  bool ok = true;
  while ((n = gzread(in, buf.data(), static_cast<unsigned>(buf.size()))) > 0)
    ok = ok && std::fwrite(buf.data(), 1, static_cast<size_t>(n), o) == static_cast<size_t>(n);
  int err = Z_OK;
  gzerror(in, &err);
  ok = ok && n == 0 && (err == Z_OK || err == Z_STREAM_END);
  gzclose(in);
  ok = std::fclose(o) == 0 && ok;
  return ok;
}

Row measure(const std::string &path, int runs) {
  Row row;
  row.file = base_name(path);
  std::vector<double> times;
  carmen::LogMessage msg;  // reused across runs, as a client would
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    carmen::LogReader reader(path);
    uint64_t n = 0;
    while (reader.next(msg)) ++n;
    const auto t1 = std::chrono::steady_clock::now();
    times.push_back(std::chrono::duration<double>(t1 - t0).count());
    row.mb = static_cast<double>(reader.stats().bytes) / 1e6;
    row.messages = n;
  }
  std::sort(times.begin(), times.end());
  row.median_s = times[times.size() / 2];
  return row;
}

// Inflating alone, as the reader's background thread does (its GzipInflater,
// 256 KiB at a time, on this thread): what the gz row cannot beat.
Row measure_inflate(const std::string &path, int runs, carmen::gzip::Codec codec) {
  Row row;
  row.file =
      std::string("(inflate only, ") + carmen::gzip::codec_name(codec) + ") " + base_name(path);
  std::vector<double> times;
  std::vector<char> buf(256 << 10);
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    std::FILE *in = std::fopen(path.c_str(), "rb");
    if (!in) break;
    carmen::gzip::GzipInflater inflater(in, codec);
    uint64_t total = 0;
    bool eof = false;
    std::string error;
    while (!eof && error.empty()) total += inflater.read(buf.data(), buf.size(), &eof, &error);
    std::fclose(in);
    if (!error.empty()) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), error.c_str());
      break;
    }
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    row.mb = static_cast<double>(total) / 1e6;
  }
  if (times.empty()) return row;
  std::sort(times.begin(), times.end());
  row.median_s = times[times.size() / 2];
  return row;
}

void print_row(const Row &r) {
  std::printf("%-48s %8.2f %10llu %10.4f %8.1f\n", r.file.c_str(), r.mb,
              static_cast<unsigned long long>(r.messages), r.median_s,
              r.median_s > 0 ? r.mb / r.median_s : 0.0);
}

}  // namespace

int main(int argc, char **argv) {
  int runs = 7;
  std::vector<std::string> logs;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "--help") == 0) {
      std::printf("usage: %s [--runs N] [log ...]\n", argv[0]);
      return 0;
    } else {
      logs.push_back(argv[i]);
    }
  }
  std::vector<std::string> temps;
  if (logs.empty()) {
    const std::string gz = std::string(VASCO_SOURCE_DIR) + "/logs/fr079-complete.gfs.log.gz";
    char tmpl[] = "/tmp/parse_bench_XXXXXX";
    const char *dir = mkdtemp(tmpl);
    if (!dir) {
      std::perror("mkdtemp");
      return 1;
    }
    const std::string plain = std::string(dir) + "/fr079-complete.gfs.log";
    if (!inflate_to(gz, plain)) {
      std::fprintf(stderr, "cannot inflate %s\n", gz.c_str());
      return 1;
    }
    temps.push_back(plain);
    temps.push_back(dir);
    logs = {gz, plain};
  }

  std::printf("%-48s %8s %10s %10s %8s\n", "file", "MB", "messages", "median s", "MB/s");
  int rc = 0;
  for (const std::string &log : logs) {
    try {
      measure(log, 1);  // warm the page cache
      print_row(measure(log, runs));
    } catch (const std::exception &e) {
      std::fprintf(stderr, "%s\n", e.what());
      rc = 1;
    }
  }
  for (const std::string &log : logs) {
    const size_t n = log.size();
    if (n <= 3 || log.compare(n - 3, 3, ".gz") != 0) continue;
    print_row(measure_inflate(log, runs, carmen::gzip::default_codec()));
    if (carmen::gzip::default_codec() != carmen::gzip::Codec::ZLIB)
      print_row(measure_inflate(log, runs, carmen::gzip::Codec::ZLIB));
  }
  std::printf("(median of %d runs; plain: one thread, gz: inflate (%s) and parse on two; MB = 10^6 bytes of uncompressed log text)\n",
              runs, carmen::gzip::codec_name(carmen::gzip::default_codec()));
  if (!temps.empty()) {
    std::remove(temps[0].c_str());
    rmdir(temps[1].c_str());
  }
  return rc;
}
