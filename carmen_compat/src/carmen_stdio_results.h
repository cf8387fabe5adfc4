// carmen_stdio_results.h — carmen_stdio calls whose results are taken as
// CARMEN's libglobal may give them: a program may link it ahead of our weak
// carmen_stdio, and its carmen_fseek returns gzseek's new offset for a .gz
// file (not 0) and fseek's 0 for a plain one. Shared by readlog and map_io.
#ifndef CARMEN_COMPAT_CARMEN_STDIO_RESULTS_H
#define CARMEN_COMPAT_CARMEN_STDIO_RESULTS_H

#include <cstdio>
#include <limits>

#include "carmen/carmen_stdio.h"

namespace carmen {

// carmen_fseek by `whence`; true when it did not report failure (-1) and the
// file is where it was asked to go, as carmen_ftell says (SEEK_END: no
// position to compare with).
inline bool checked_seek(carmen_FILE *fp, off_t offset, int whence) {
  off_t target = offset;
  if (whence == SEEK_CUR) {
    const off_t here = carmen_ftell(fp);
    if (here < 0 || offset > std::numeric_limits<off_t>::max() - here) return false;
    target = here + offset;
  }
  if (carmen_fseek(fp, offset, whence) == -1) return false;
  return whence == SEEK_END || carmen_ftell(fp) == target;
}

}  // namespace carmen

#endif  // CARMEN_COMPAT_CARMEN_STDIO_RESULTS_H
