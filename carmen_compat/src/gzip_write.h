// Writing a .gz file (internal to carmen_compat): one gzip member that gzip,
// zlib and CARMEN's own reader (zlib's gzread) take alike.
//
// ISA-L's igzip at its level 1 where the build has ISA-L, zlib's default
// level otherwise: a map's floats hardly compress either way (fr079's map,
// 409 KB: 115 KB at zlib's level 6, about 120 KB at igzip's level 1), and
// zlib's level 6 took 6.4 ms of a batch's 7.9 ms write per fr079 log on the
// 2-core machine, a pool thread's time that bounds a batch's throughput.
// Either codec writes the same map bytes, only their compression differs.
#ifndef CARMEN_COMPAT_SRC_GZIP_WRITE_H
#define CARMEN_COMPAT_SRC_GZIP_WRITE_H

#include <cstddef>
#include <memory>
#include <string>

#include "gzip_stream.h"

namespace carmen {
namespace gzip {

// Compresses what it is given into a descriptor it owns. Errors throw
// carmen::FileError naming `name` (the file the user asked for, not the
// temporary being written).
class GzipWriter {
 public:
  GzipWriter(int fd, std::string name, Codec codec = default_codec());
  ~GzipWriter();  // closes the descriptor; a writer not closed wrote no whole file
  GzipWriter(const GzipWriter &) = delete;
  GzipWriter &operator=(const GzipWriter &) = delete;

  void write(const char *data, std::size_t n);
  // The member's end (trailer) written and the descriptor closed.
  void close();

  class Encoder;  // the codec's side (gzip_write.cc)

 private:
  void write_out(const unsigned char *p, std::size_t n);

  int fd_;
  std::string name_;
  std::unique_ptr<Encoder> enc_;
  std::unique_ptr<unsigned char[]> out_;
};

}  // namespace gzip
}  // namespace carmen

#endif  // CARMEN_COMPAT_SRC_GZIP_WRITE_H
