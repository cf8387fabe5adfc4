// Atomic file output: write to a temporary file beside the target, then
// rename it over the target. A writer that fails or throws part-way leaves
// the target untouched (an old file stays as it was, a new one never appears).
#ifndef CARMEN_COMPAT_ATOMIC_FILE_H
#define CARMEN_COMPAT_ATOMIC_FILE_H

#include <string>
#include <string_view>

namespace carmen {

// Usage:
//   AtomicOutput out(path);
//   FILE *f = fopen(out.temp_path().c_str(), "wb");  ... write, fclose, check ...
//   out.commit();            // rename(temp, path); throws carmen::FileError
// If commit() is never reached (an exception, an early return), the
// destructor removes the temporary file.
//
// The temporary file lies in the target's directory (rename() is atomic only
// within one file system) and is named ".NAME.tmp.PID.N": hidden, unique per
// process (N counts up) and never ending in the target's extension, so
// extension-based tools ignore it. Open it yourself with the format you want
// (for gzip, open it with gzopen: carmen_fopen would judge by the temp name).
class AtomicOutput {
 public:
  // Throws carmen::FileError(final_path, ...) when the path has no file name
  // (empty, or ending in '/').
  explicit AtomicOutput(std::string final_path);
  ~AtomicOutput();  // removes the temporary file unless committed
  AtomicOutput(const AtomicOutput &) = delete;
  AtomicOutput &operator=(const AtomicOutput &) = delete;

  const std::string &final_path() const noexcept { return final_path_; }
  const std::string &temp_path() const noexcept { return temp_path_; }

  // Renames the temporary file over the final path. The file must be
  // complete and closed. With durable = true the data and the directory entry
  // are fsync'ed too (slower; for files that must survive a power cut).
  // Throws carmen::FileError naming the final path when the temporary file is
  // missing or the rename fails (the temporary file is then removed).
  // Calling it twice is an error (std::logic_error).
  void commit(bool durable = false);
  bool committed() const noexcept { return committed_; }

  // Removes the temporary file now and gives up (what the destructor does).
  void abandon() noexcept;

 private:
  std::string final_path_;
  std::string temp_path_;
  bool committed_ = false;
};

// Writes `contents` to `path` atomically (binary). Throws carmen::FileError.
void write_file_atomically(const std::string &path, std::string_view contents, bool durable = false);

}  // namespace carmen

#endif  // CARMEN_COMPAT_ATOMIC_FILE_H
