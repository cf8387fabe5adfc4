// carmen.ini parsing and the mapper's parameters from it.
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/ini_file.h"
#include "fuzz_support.h"
#include "vasco_gpu/params.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const std::string text(reinterpret_cast<const char *>(data), size);
  for (const char *robot : {"", "p2d8+"}) {
    try {
      const carmen::ParamFile pf = carmen::ParamFile::parse(text, "fuzz.ini", robot);
      std::vector<std::string> warnings;
      vasco::MapperParams::from_params(pf, &warnings);
    } catch (const carmen::Error &) {  // a ParamError or a FileError: refused input
    } catch (const std::invalid_argument &) {
    }
  }
  return 0;
}
