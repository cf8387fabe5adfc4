// The map_server pair: a YAML and the image it names (PGM or PNG), as
// mapconvert, mapdiff and read_map read them. The input is the YAML's text,
// a NUL byte, then the image's bytes; the first byte's low bit picks the
// image's name (map.pgm or map.png), which a seed's YAML names. Every reader
// must return a map or throw carmen::Error: never crash, hang or allocate
// beyond the map budget.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "carmen_compat/error.h"
#include "carmen_compat/image_io.h"

namespace {

// A directory of this process holding the pair, emptied on scope exit.
class PairDir {
 public:
  PairDir(const std::string &yaml, const std::string &image, const char *image_name) {
    const char *tmp = std::getenv("TMPDIR");
    dir_ = std::string(tmp ? tmp : "/tmp") + "/vasco_fuzz_map_server_" + std::to_string(::getpid());
    ::mkdir(dir_.c_str(), 0700);
    yaml_ = dir_ + "/map.yaml";
    image_ = dir_ + "/" + image_name;
    write(yaml_, yaml);
    write(image_, image);
  }
  ~PairDir() {
    std::remove(yaml_.c_str());
    std::remove(image_.c_str());
    ::rmdir(dir_.c_str());
  }
  const std::string &yaml() const { return yaml_; }
  const std::string &image() const { return image_; }

 private:
  static void write(const std::string &path, const std::string &bytes) {
    std::FILE *f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) std::abort();
    if (!bytes.empty()) std::fwrite(bytes.data(), 1, bytes.size(), f);
    std::fclose(f);
  }
  std::string dir_, yaml_, image_;
};

template <class F>
void expect_map_or_error(F &&read) {
  try {
    read();
  } catch (const carmen::Error &) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size == 0) return 0;
  const bool png = (data[0] & 1) != 0;
  const std::string rest(reinterpret_cast<const char *>(data) + 1, size - 1);
  const size_t nul = rest.find('\0');
  const std::string yaml = rest.substr(0, nul);
  const std::string image = nul == std::string::npos ? std::string() : rest.substr(nul + 1);
  const PairDir pair(yaml, image, png ? "map.png" : "map.pgm");
  expect_map_or_error([&] { carmen::read_map_server_yaml(pair.yaml()); });
  expect_map_or_error([&] { carmen::read_image_with_yaml(pair.image(), pair.yaml()); });
  if (png) expect_map_or_error([&] { carmen::read_png(pair.image()); });
  return 0;
}
