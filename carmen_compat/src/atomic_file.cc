// AtomicOutput: temp file in the target's directory + rename.
#include "carmen_compat/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "carmen_compat/error.h"

namespace carmen {
namespace {

std::atomic<unsigned long> g_temp_counter{0};

std::string errno_text(int err) { return std::strerror(err); }

// Splits "a/b/c.map" into "a/" and "c.map" (directory keeps its slash).
void split_path(const std::string &path, std::string *dir, std::string *base) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) {
    dir->clear();
    *base = path;
  } else {
    *dir = path.substr(0, slash + 1);
    *base = path.substr(slash + 1);
  }
}

bool fsync_path(const std::string &path, bool directory) {
  const int fd = ::open(path.c_str(), directory ? (O_RDONLY | O_DIRECTORY) : O_RDONLY);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

}  // namespace

AtomicOutput::AtomicOutput(std::string final_path) : final_path_(std::move(final_path)) {
  std::string dir, base;
  split_path(final_path_, &dir, &base);
  if (base.empty() || base == "." || base == "..") {
    throw FileError(final_path_, "not a file name (cannot write to it)");
  }
  const unsigned long n = g_temp_counter.fetch_add(1);
  temp_path_ =
      dir + "." + base + ".tmp." + std::to_string(static_cast<long>(::getpid())) + "." + std::to_string(n);
}

AtomicOutput::~AtomicOutput() { abandon(); }

void AtomicOutput::abandon() noexcept {
  if (!committed_ && !temp_path_.empty()) {
    std::remove(temp_path_.c_str());  // may not exist: nothing to do then
  }
}

void AtomicOutput::commit(bool durable) {
  if (committed_) throw std::logic_error("AtomicOutput::commit called twice for " + final_path_);
  struct stat st;
  if (::stat(temp_path_.c_str(), &st) != 0) {
    throw FileError(final_path_, "nothing was written (temporary file " + temp_path_ +
                                     " is missing: " + errno_text(errno) + ")");
  }
  if (durable && !fsync_path(temp_path_, false)) {
    const int err = errno;
    abandon();
    throw FileError(final_path_, "cannot sync the data to disk: " + errno_text(err));
  }
  if (std::rename(temp_path_.c_str(), final_path_.c_str()) != 0) {
    const int err = errno;
    abandon();
    throw FileError(final_path_, "cannot move the finished file into place: " + errno_text(err));
  }
  committed_ = true;
  if (durable) {
    std::string dir, base;
    split_path(final_path_, &dir, &base);
    if (!fsync_path(dir.empty() ? std::string(".") : dir, true)) {
      throw FileError(final_path_, "written, but syncing its directory failed: " + errno_text(errno));
    }
  }
}

void write_file_atomically(const std::string &path, std::string_view contents, bool durable) {
  AtomicOutput out(path);
  FILE *f = std::fopen(out.temp_path().c_str(), "wb");
  if (f == nullptr) {
    throw FileError(path, "cannot create " + out.temp_path() + ": " + errno_text(errno));
  }
  const size_t written = contents.empty() ? 0 : std::fwrite(contents.data(), 1, contents.size(), f);
  const int write_errno = errno;
  const bool close_ok = std::fclose(f) == 0;
  if (written != contents.size() || !close_ok) {
    throw FileError(path, "write failed: " + errno_text(written != contents.size() ? write_errno : errno));
  }
  out.commit(durable);
}

}  // namespace carmen
