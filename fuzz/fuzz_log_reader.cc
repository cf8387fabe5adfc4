// The log reader on arbitrary bytes, plain and as a .gz name (strict and
// lenient): errors are carmen::FileError, never a crash, a hang or a leak.
#include "carmen_compat/error.h"
#include "carmen_compat/log_reader.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  for (const char *suffix : {".log", ".log.gz"}) {
    fuzz::InputFile in(data, size, suffix);
    for (bool strict : {true, false}) {
      carmen::LogReaderOptions opt;
      opt.strict = strict;
      opt.max_line_length = 1 << 12;
      try {
        carmen::LogStats stats;
        carmen::read_log(in.path(), opt, &stats);
      } catch (const carmen::Error &) {
      }
    }
  }
  return 0;
}
