// A nav_msgs/Path read from its serialized bytes (XCDR1, little-endian), for
// the live node (vasco_gpu.ros.path_cdr): one pass in C++ instead of a
// NumPy record view and its checks, a step a live node pays several times
// over. The layout: a 4-byte encapsulation header, then {int32 sec, uint32
// nanosec, string frame_id} of the Path's header, uint32 pose count, and
// per PoseStamped {int32 sec, uint32 nanosec, string frame_id, 7 float64},
// each primitive aligned to its size from the end of the encapsulation
// header, a string as uint32 length (NUL included) and its bytes.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

#include "arrays.h"
#include "bindings.h"

namespace vasco_py {

using namespace nb::literals;

namespace {

// Reads at CDR alignment; every read checked against the end. ok turns
// false on the first read past it.
class CdrReader {
 public:
  CdrReader(const uint8_t *data, size_t size) : body_(data + 4), size_(size - 4) {}

  uint32_t u32() { return read<uint32_t>(); }
  int32_t i32() { return read<int32_t>(); }
  // The offset of n float64s, moved past them (0, ok false, past the end); f64_at reads one
  // there (an 8-byte load: one memcpy of 56 bytes compiled to rep movs, slower than the rest
  // of a pose's reading)
  size_t doubles(size_t n) { return aligned<8>(8 * n); }
  double f64_at(size_t at) const {
    double v;
    std::memcpy(&v, body_ + at, sizeof v);
    return v;
  }
  // A string's bytes without its NUL; empty view (ok false) for a bad one.
  std::string_view string() {
    const uint32_t n = u32();
    if (!ok || n == 0 || n > size_ - pos_ || body_[pos_ + n - 1] != 0) {
      ok = false;
      return {};
    }
    std::string_view s(reinterpret_cast<const char *>(body_ + pos_), n - 1);
    pos_ += n;
    return s;
  }
  size_t left() const { return size_ - pos_; }

  bool ok = true;

 private:
  template <typename T>
  T read() {
    T v{};
    const size_t at = aligned<sizeof(T)>(sizeof(T));
    if (ok) std::memcpy(&v, body_ + at, sizeof(T));  // little-endian host (x86-64, aarch64)
    return v;
  }
  // The offset of `bytes` at Align (a power of 2, known when compiled: no division a read),
  // moved past them; ok false (offset 0) past the end.
  template <size_t Align>
  size_t aligned(size_t bytes) {
    static_assert((Align & (Align - 1)) == 0, "CDR aligns to powers of 2");
    const size_t at = (pos_ + Align - 1) & ~(Align - 1);
    if (!ok || at > size_ || bytes > size_ - at) {
      ok = false;
      return 0;
    }
    pos_ = at + bytes;
    return at;
  }

  const uint8_t *body_;
  size_t size_, pos_ = 0;
};

nb::str utf8(std::string_view s) {
  PyObject *o = PyUnicode_DecodeUTF8(s.data(), Py_ssize_t(s.size()), "replace");
  if (!o) throw nb::python_error();
  return nb::steal<nb::str>(o);
}

int64_t stamp_ns(int32_t sec, uint32_t nanosec) { return int64_t(sec) * 1000000000 + nanosec; }

// None where the bytes are not a little-endian CDR Path whose poses share one
// frame_id (the caller takes rclpy's deserialisation then).
nb::object path_from_cdr(nb::bytes raw) {
  const auto *data = reinterpret_cast<const uint8_t *>(raw.c_str());
  const size_t size = raw.size();
  if (size < 4 || data[0] != 0x00 || data[1] != 0x01) return nb::none();
  CdrReader r(data, size);
  const int32_t sec = r.i32();
  const uint32_t nanosec = r.u32();
  const std::string_view frame = r.string();
  const uint32_t k = r.u32();
  // a pose takes at least 72 bytes: a count past what the bytes can hold is no Path
  if (!r.ok || k > r.left() / 72) return nb::none();
  std::vector<int64_t> stamps(k);
  std::vector<double> positions(3 * size_t(k)), orientations(4 * size_t(k));
  std::string_view pose_frame;
  {
    nb::gil_scoped_release release;
    for (uint32_t i = 0; i < k && r.ok; ++i) {
      const int32_t ps = r.i32();
      const uint32_t pn = r.u32();
      const std::string_view f = r.string();
      if (i == 0) pose_frame = f;
      if (f != pose_frame) r.ok = false;
      const size_t at = r.doubles(7);  // position x y z, orientation x y z w
      if (!r.ok) break;
      stamps[i] = stamp_ns(ps, pn);
      double *p = &positions[3 * size_t(i)], *q = &orientations[4 * size_t(i)];
      for (size_t j = 0; j < 3; ++j) p[j] = r.f64_at(at + 8 * j);
      for (size_t j = 0; j < 4; ++j) q[j] = r.f64_at(at + 24 + 8 * j);
    }
  }
  if (!r.ok) return nb::none();
  return nb::make_tuple(utf8(frame), stamp_ns(sec, nanosec), utf8(pose_frame), owned(std::move(stamps), {k}),
                        owned(std::move(positions), {k, 3}), owned(std::move(orientations), {k, 4}));
}

}  // namespace

void bind_path_cdr(nb::module_ &m) {
  m.def("_path_from_cdr", &path_from_cdr, "raw"_a,
        "A serialized nav_msgs/Path (little-endian CDR) as (frame_id, stamp_ns, the poses' one\n"
        "frame_id, stamps (k,) int64 ns, positions (k, 3), orientations (k, 4) x y z w); None for\n"
        "bytes of another layout (big-endian, poses in several frames, truncated), which\n"
        "vasco_gpu.ros.path_cdr hands to rclpy's deserialisation.");
}

}  // namespace vasco_py
