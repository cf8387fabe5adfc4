/* carmen_stdio.h — CARMEN 0.7.4's stdio wrapper with transparent gzip.
 *
 * A name ending in ".gz" is read and written through zlib; anything else is a
 * plain FILE. The content is never sniffed (as in CARMEN). The functions keep
 * CARMEN's names and signatures so existing code links unchanged. */
/* DGC_MY_STDIO_H is CARMEN's guard for its carmen_stdio.h: whichever of the
 * two a program includes first is the one it gets (carmen_FILE is a typedef
 * of an anonymous struct, which C cannot define twice). The two agree in
 * every declaration: layout, member types and signatures. */
#ifndef DGC_MY_STDIO_H
#define DGC_MY_STDIO_H

#include <stdio.h>
#include <sys/types.h>
#include <zlib.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  int compressed;  /* 1 when the stream goes through zlib */
  FILE *fp;        /* plain stream (compressed == 0) */
  /* zlib stream (compressed == 1). The type is CARMEN's; what it holds is
   * the gzFile itself (as CARMEN stores gzdopen's result), so pass
   * (gzFile)fp->comp_fp to zlib. */
  gzFile *comp_fp;
} carmen_FILE;

/* Opens `filename` with an fopen() mode ("r", "w", "rb", "wb", "a"...).
 * Returns NULL and sets errno on failure. */
carmen_FILE *carmen_fopen(const char *filename, const char *mode);
/* Closes and frees the stream; returns 0 on success, EOF on error (for a
 * written gzip stream an error means the file is incomplete). */
int carmen_fclose(carmen_FILE *fp);
int carmen_fgetc(carmen_FILE *fp);
int carmen_fputc(int c, carmen_FILE *fp);
char *carmen_fgets(char *s, int size, carmen_FILE *fp);
size_t carmen_fread(void *ptr, size_t size, size_t nmemb, carmen_FILE *fp);
size_t carmen_fwrite(const void *ptr, size_t size, size_t nmemb, carmen_FILE *fp);
/* As CARMEN's, returns nothing: carmen_ferror() tells whether it failed. */
void carmen_fprintf(carmen_FILE *fp, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
int carmen_feof(carmen_FILE *fp);
/* Non-zero when the stream hit a read/write error (or, compressed, a corrupt
 * or truncated gzip stream). Not in CARMEN; offered so callers can tell a
 * clean end of file from damage. */
int carmen_ferror(carmen_FILE *fp);
/* Seeks; returns 0, or -1 on failure. On a compressed stream only
 * SEEK_SET/SEEK_CUR are supported and a backward seek rewinds and
 * decompresses again (slow, as in CARMEN). (CARMEN's returns gzseek's new
 * offset on a compressed stream: a caller that may get CARMEN's should
 * treat only a negative result as failure.) */
int carmen_fseek(carmen_FILE *fp, off_t offset, int whence);
/* The position (uncompressed, for a compressed stream), or -1. */
off_t carmen_ftell(carmen_FILE *fp);
int carmen_fflush(carmen_FILE *fp);

#ifdef __cplusplus
}
#endif
#endif /* DGC_MY_STDIO_H */
