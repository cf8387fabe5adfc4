// carmen_stdio: CARMEN's FILE wrapper, gzip when the name ends in ".gz".
#include "carmen/carmen_stdio.h"

#include <cerrno>
#include <cstdarg>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <unistd.h>

#include "carmen_compat/file_names.h"

namespace {

// By name, case and all, as CARMEN's carmen_fopen decides.
bool ends_with_gz(const char *name) { return carmen::ends_with(name, ".gz"); }

// comp_fp has CARMEN's type (gzFile *) but holds the gzFile, as CARMEN's
// carmen_fopen leaves it: a carmen_FILE opened by CARMEN's libglobal and
// read by our readers (or the reverse) means the same.
gzFile gz(carmen_FILE *fp) { return reinterpret_cast<gzFile>(fp->comp_fp); }

}  // namespace

// CARMEN keeps these functions in its libglobal, which a CARMEN program links
// anyway. Ours are weak definitions: where the program also links CARMEN's
// libglobal, its (strong) definitions win, statically or at run time, with
// no duplicate-symbol error, and every caller, our readers and writers
// included, uses them (same carmen_FILE layout, same semantics). Without
// libglobal, ours serve. carmen_ferror is ours alone, so it stays strong.
#if defined(__GNUC__)
#define CARMEN_STDIO_WEAK __attribute__((weak))
#else
#define CARMEN_STDIO_WEAK
#endif

extern "C" {

CARMEN_STDIO_WEAK carmen_FILE *carmen_fopen(const char *filename, const char *mode) {
  if (filename == nullptr || mode == nullptr) {
    errno = EINVAL;
    return nullptr;
  }
  auto *f = static_cast<carmen_FILE *>(std::calloc(1, sizeof(carmen_FILE)));
  if (f == nullptr) return nullptr;
  f->compressed = ends_with_gz(filename) ? 1 : 0;
  // As CARMEN: fp is the file itself in both cases (for a compressed one,
  // its compressed bytes, which the index's progress measures); zlib reads a
  // duplicate of its descriptor, closed by gzclose.
  f->fp = std::fopen(filename, mode);
  if (f->fp == nullptr) {
    std::free(f);
    return nullptr;
  }
  if (f->compressed) {
    // zlib wants "rb"/"wb"; make sure the mode says binary.
    std::string m(mode);
    if (m.find('b') == std::string::npos) m += 'b';
    const int fd = dup(fileno(f->fp));
    gzFile z = fd < 0 ? nullptr : gzdopen(fd, m.c_str());
    if (z == nullptr) {
      const int saved = errno != 0 ? errno : EIO;
      if (fd >= 0) close(fd);
      std::fclose(f->fp);
      std::free(f);
      errno = saved;
      return nullptr;
    }
    gzbuffer(z, 1 << 17);
    f->comp_fp = reinterpret_cast<gzFile *>(z);
  }
  return f;
}

CARMEN_STDIO_WEAK int carmen_fclose(carmen_FILE *fp) {
  if (fp == nullptr) return EOF;
  int rc = 0;
  if (fp->compressed) {
    rc = gzclose(gz(fp)) == Z_OK ? 0 : EOF;
    if (fp->fp != nullptr && std::fclose(fp->fp) != 0) rc = EOF;
  } else {
    rc = std::fclose(fp->fp);
  }
  std::free(fp);
  return rc;
}

CARMEN_STDIO_WEAK int carmen_fgetc(carmen_FILE *fp) {
  return fp->compressed ? gzgetc(gz(fp)) : std::fgetc(fp->fp);
}

CARMEN_STDIO_WEAK int carmen_fputc(int c, carmen_FILE *fp) {
  return fp->compressed ? gzputc(gz(fp), c) : std::fputc(c, fp->fp);
}

CARMEN_STDIO_WEAK char *carmen_fgets(char *s, int size, carmen_FILE *fp) {
  return fp->compressed ? gzgets(gz(fp), s, size) : std::fgets(s, size, fp->fp);
}

CARMEN_STDIO_WEAK size_t carmen_fread(void *ptr, size_t size, size_t nmemb, carmen_FILE *fp) {
  if (!fp->compressed) return std::fread(ptr, size, nmemb, fp->fp);
  if (size == 0 || nmemb == 0) return 0;
  return gzfread(ptr, size, nmemb, gz(fp));
}

CARMEN_STDIO_WEAK size_t carmen_fwrite(const void *ptr, size_t size, size_t nmemb, carmen_FILE *fp) {
  if (!fp->compressed) return std::fwrite(ptr, size, nmemb, fp->fp);
  if (size == 0 || nmemb == 0) return 0;
  return gzfwrite(ptr, size, nmemb, gz(fp));
}

CARMEN_STDIO_WEAK void carmen_fprintf(carmen_FILE *fp, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  va_list ap2;
  va_copy(ap2, ap);
  const int n = std::vsnprintf(nullptr, 0, fmt, ap);
  va_end(ap);
  if (n < 0) {
    va_end(ap2);
    return;
  }
  std::vector<char> buf(static_cast<size_t>(n) + 1);
  std::vsnprintf(buf.data(), buf.size(), fmt, ap2);
  va_end(ap2);
  carmen_fwrite(buf.data(), 1, static_cast<size_t>(n), fp);  // a failure shows in carmen_ferror
}

CARMEN_STDIO_WEAK int carmen_feof(carmen_FILE *fp) {
  return fp->compressed ? gzeof(gz(fp)) : std::feof(fp->fp);
}

int carmen_ferror(carmen_FILE *fp) {
  if (!fp->compressed) return std::ferror(fp->fp);
  int err = Z_OK;
  gzerror(gz(fp), &err);
  return err != Z_OK && err != Z_STREAM_END ? 1 : 0;
}

CARMEN_STDIO_WEAK int carmen_fseek(carmen_FILE *fp, off_t offset, int whence) {
  if (!fp->compressed) return fseeko(fp->fp, offset, whence);
  if (whence == SEEK_END) {
    errno = EINVAL;
    return -1;
  }
  return gzseek(gz(fp), static_cast<z_off_t>(offset), whence) < 0 ? -1 : 0;
}

CARMEN_STDIO_WEAK off_t carmen_ftell(carmen_FILE *fp) {
  return fp->compressed ? static_cast<off_t>(gztell(gz(fp))) : ftello(fp->fp);
}

CARMEN_STDIO_WEAK int carmen_fflush(carmen_FILE *fp) {
  return fp->compressed ? (gzflush(gz(fp), Z_SYNC_FLUSH) == Z_OK ? 0 : EOF)
                        : std::fflush(fp->fp);
}

}  // extern "C"
