// CARMEN map files (plain and gzipped names) and their chunk listing.
#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  for (const char *suffix : {".map", ".map.gz"}) {
    fuzz::InputFile in(data, size, suffix);
    carmen::MapReadOptions opt;
    opt.max_kept_bytes = 64 << 20;  // the budget, small enough for the fuzzer's memory limit
    try {
      carmen::read_map_file(in.path(), opt);
    } catch (const carmen::Error &) {
    }
    try {
      carmen::list_map_chunks(in.path());
    } catch (const carmen::Error &) {
    }
    carmen::is_map_file(in.path());
  }
  return 0;
}
