/* A stand-in for CARMEN's libglobal (its carmen_stdio part), written for the
 * install test: a CARMEN program links its own libglobal beside ours, so its
 * carmen_fopen & co. (strong symbols) must win over our weak ones, statically
 * and with the shared library, without a duplicate-symbol error. This one
 * does all I/O through zlib (which reads plain files too and writes them
 * with "T"), says on stderr that it was used, and returns what CARMEN's
 * returns: carmen_fread gzread's count cast to size_t, so (size_t)-1 on a
 * gzip error, and carmen_fseek gzseek's new offset, not 0. */
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
  f->comp_fp = (gzFile *)gzopen(filename, m); /* CARMEN's field holds the gzFile itself */
  if (f->comp_fp == NULL) {
    free(f);
    return NULL;
  }
  fprintf(stderr, "fake libglobal: carmen_fopen(%s)\n", filename);
  return f;
}

static gzFile gz(carmen_FILE *fp) { return (gzFile)fp->comp_fp; }

int carmen_fclose(carmen_FILE *fp) {
  const int rc = gzclose(gz(fp)) == Z_OK ? 0 : EOF;
  free(fp);
  return rc;
}

int carmen_fgetc(carmen_FILE *fp) { return gzgetc(gz(fp)); }
int carmen_fputc(int c, carmen_FILE *fp) { return gzputc(gz(fp), c); }
char *carmen_fgets(char *s, int size, carmen_FILE *fp) { return gzgets(gz(fp), s, size); }
int carmen_feof(carmen_FILE *fp) { return gzeof(gz(fp)); }
int carmen_fseek(carmen_FILE *fp, off_t offset, int whence) { return (int)gzseek(gz(fp), offset, whence); }
off_t carmen_ftell(carmen_FILE *fp) { return gztell(gz(fp)); }
int carmen_fflush(carmen_FILE *fp) { return gzflush(gz(fp), Z_SYNC_FLUSH) == Z_OK ? 0 : EOF; }

size_t carmen_fread(void *ptr, size_t size, size_t nmemb, carmen_FILE *fp) {
  return (size_t)gzread(gz(fp), ptr, (unsigned)(size * nmemb));
}

size_t carmen_fwrite(const void *ptr, size_t size, size_t nmemb, carmen_FILE *fp) {
  return (size_t)gzwrite(gz(fp), ptr, (unsigned)(size * nmemb));
}

void carmen_fprintf(carmen_FILE *fp, const char *fmt, ...) {
  char buf[4096];
  va_list ap;
  va_start(ap, fmt);
  const int n = vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  if (n >= 0) gzputs(gz(fp), buf);
}
