// A /tmp-style directory for the tests of the sticky-bit rule: world
// writable and sticky (mode 1777), inside a temporary directory opened to
// other users (mkdtemp makes it 0700).
#ifndef VASCO_TESTS_STICKY_DIR_H
#define VASCO_TESTS_STICKY_DIR_H

#include <sys/stat.h>

#include <string>

#include "map_test_support.h"

namespace maptest {

// The sticky directory's path, or "" when it could not be made.
inline std::string make_sticky_directory(const TempDir &dir) {
  const std::string sticky = dir.file("tmp");
  const bool ok = ::chmod(dir.path().c_str(), 0755) == 0 && ::mkdir(sticky.c_str(), 0777) == 0 &&
                  ::chmod(sticky.c_str(), 01777) == 0;
  return ok ? sticky : std::string();
}

}  // namespace maptest

#endif  // VASCO_TESTS_STICKY_DIR_H
