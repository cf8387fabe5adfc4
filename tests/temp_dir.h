// A temporary directory for a test's files, removed (with the files named
// through it) at the end of the test.
#ifndef VASCO_TESTS_TEMP_DIR_H
#define VASCO_TESTS_TEMP_DIR_H

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/vasco_test_XXXXXX";
    if (const char *d = mkdtemp(tmpl)) path_ = d;
  }
  ~TempDir() {
    for (const auto &f : files_) std::remove(f.c_str());
    if (!path_.empty()) rmdir(path_.c_str());
  }
  TempDir(const TempDir &) = delete;
  TempDir &operator=(const TempDir &) = delete;
  // The path of `name` in the directory, removed with it.
  std::string file(const std::string &name) {
    files_.push_back(path_ + "/" + name);
    return files_.back();
  }

 private:
  std::string path_;
  std::vector<std::string> files_;
};

#endif  // VASCO_TESTS_TEMP_DIR_H
