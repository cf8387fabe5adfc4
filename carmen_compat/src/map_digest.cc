#include "carmen_compat/map_digest.h"

#include <openssl/evp.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace carmen {
namespace {

// The payload is little-endian, and cells are hashed straight from memory: a
// big-endian host is refused rather than given a wrong digest.
bool host_is_little_endian() {
  const uint32_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

struct MdCtxDeleter {
  void operator()(EVP_MD_CTX *c) const { EVP_MD_CTX_free(c); }
};

}  // namespace

std::string gridmap_payload_sha256(int size_x, int size_y, double resolution,
                                   const std::vector<float> &cells) {
  if (size_x < 0 || size_y < 0 ||
      cells.size() != static_cast<size_t>(size_x) * static_cast<size_t>(size_y))
    throw std::invalid_argument("gridmap_payload_sha256: cells do not match the grid size");
  if (!host_is_little_endian())
    throw std::runtime_error("gridmap_payload_sha256: big-endian hosts are not supported");
  unsigned char header[12];
  const int32_t sx = size_x, sy = size_y;
  const float res = static_cast<float>(resolution);
  std::memcpy(header, &sx, 4);
  std::memcpy(header + 4, &sy, 4);
  std::memcpy(header + 8, &res, 4);

  std::unique_ptr<EVP_MD_CTX, MdCtxDeleter> ctx(EVP_MD_CTX_new());
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int md_len = 0;
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1 ||
      EVP_DigestUpdate(ctx.get(), header, sizeof header) != 1 ||
      EVP_DigestUpdate(ctx.get(), cells.data(), cells.size() * sizeof(float)) != 1 ||
      EVP_DigestFinal_ex(ctx.get(), md, &md_len) != 1)
    throw std::runtime_error("gridmap_payload_sha256: OpenSSL's SHA-256 failed");
  static const char hex[] = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < md_len; ++i) {
    out += hex[md[i] >> 4];
    out += hex[md[i] & 15];
  }
  return out;
}

}  // namespace carmen
