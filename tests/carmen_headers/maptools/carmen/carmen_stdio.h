/* Stand-in for CARMEN's carmen_stdio.h (see ../../README.md): CARMEN's guard,
 * comp_fp as gzFile *, carmen_fprintf returning void, off_t offsets: the
 * same declarations as ours. */
#ifndef DGC_MY_STDIO_H
#define DGC_MY_STDIO_H
#define CARMEN_STANDIN_STDIO 1

#ifdef __cplusplus
extern "C" {
#endif

#include <carmen/carmen.h>
#include <zlib.h>

typedef struct {
  int compressed;
  FILE *fp;
  gzFile *comp_fp;
} carmen_FILE;

carmen_FILE *carmen_fopen(const char *filename, const char *mode);
int carmen_fgetc(carmen_FILE *fp);
int carmen_feof(carmen_FILE *fp);
int carmen_fseek(carmen_FILE *fp, off_t offset, int whence);
off_t carmen_ftell(carmen_FILE *fp);
int carmen_fclose(carmen_FILE *fp);
size_t carmen_fread(void *ptr, size_t size, size_t nmemb, carmen_FILE *fp);
size_t carmen_fwrite(const void *ptr, size_t size, size_t nmemb, carmen_FILE *fp);
char *carmen_fgets(char *s, int size, carmen_FILE *fp);
int carmen_fputc(int c, carmen_FILE *fp);
void carmen_fprintf(carmen_FILE *fp, const char *fmt, ...);
int carmen_fflush(carmen_FILE *fp);

#ifdef __cplusplus
}
#endif
#endif
