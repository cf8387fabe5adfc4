/* A stand-in for CARMEN's libglobal (its carmen_stdio part), written for the
 * install test: a CARMEN program links its own libglobal beside ours, so its
 * carmen_fopen & co. (strong symbols) must win over our weak ones, statically
 * and with the shared library, without a duplicate-symbol error. This one
 * does all I/O through zlib (which reads plain files too and writes them
 * with "T") and says on stderr that it was used. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include <carmen/carmen_stdio.h>

static int ends_with_gz(const char *name) {
  const size_t n = strlen(name);
  return n >= 3 && strcmp(name + n - 3, ".gz") == 0;
}

carmen_FILE *carmen_fopen(const char *filename, const char *mode) {
  char m[8];
  snprintf(m, sizeof m, "%c%s", mode[0], (mode[0] != 'r' && !ends_with_gz(filename)) ? "bT" : "b");
  carmen_FILE *f = calloc(1, sizeof *f);
  if (f == NULL) return NULL;
  f->compressed = 1;
  f->comp_fp = gzopen(filename, m);
  if (f->comp_fp == NULL) {
    free(f);
    return NULL;
  }
  fprintf(stderr, "fake libglobal: carmen_fopen(%s)\n", filename);
  return f;
}

int carmen_fclose(carmen_FILE *fp) {
  const int rc = gzclose(fp->comp_fp) == Z_OK ? 0 : EOF;
  free(fp);
  return rc;
}

int carmen_fgetc(carmen_FILE *fp) { return gzgetc(fp->comp_fp); }
int carmen_fputc(int c, carmen_FILE *fp) { return gzputc(fp->comp_fp, c); }
char *carmen_fgets(char *s, int size, carmen_FILE *fp) { return gzgets(fp->comp_fp, s, size); }
int carmen_feof(carmen_FILE *fp) { return gzeof(fp->comp_fp); }
int carmen_fseek(carmen_FILE *fp, long offset, int whence) {
  return gzseek(fp->comp_fp, offset, whence) < 0 ? -1 : 0;
}
long carmen_ftell(carmen_FILE *fp) { return gztell(fp->comp_fp); }
int carmen_fflush(carmen_FILE *fp) { return gzflush(fp->comp_fp, Z_SYNC_FLUSH) == Z_OK ? 0 : EOF; }

size_t carmen_fread(void *ptr, size_t size, size_t nmemb, carmen_FILE *fp) {
  const int n = gzread(fp->comp_fp, ptr, (unsigned)(size * nmemb));
  return n <= 0 ? 0 : (size_t)n / size;
}

size_t carmen_fwrite(const void *ptr, size_t size, size_t nmemb, carmen_FILE *fp) {
  const int n = gzwrite(fp->comp_fp, ptr, (unsigned)(size * nmemb));
  return n <= 0 ? 0 : (size_t)n / size;
}

int carmen_fprintf(carmen_FILE *fp, const char *fmt, ...) {
  char buf[4096];
  va_list ap;
  va_start(ap, fmt);
  const int n = vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  return n < 0 ? n : gzputs(fp->comp_fp, buf);
}
