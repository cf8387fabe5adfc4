/* A stand-in for CARMEN's logtool, written for the install test (no CARMEN
 * code): it indexes a log as logtool does and prints how many messages the
 * index holds and how many of them are laser scans. Linked beside a
 * CARMEN-like libglobal, whose carmen_fread returns (size_t)-1 on a gzip
 * error, it must end with a message, not a crash, on a corrupt log.
 *
 *   logtool_standin LOG */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <carmen/carmen_stdio.h>
#include <carmen/readlog.h>

#define LINE_MAX_BYTES 100000

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: logtool_standin LOG\n");
    return 2;
  }
  carmen_FILE *fp = carmen_fopen(argv[1], "r");
  if (fp == NULL) {
    fprintf(stderr, "Error: could not open file %s for reading.\n", argv[1]);
    return 1;
  }
  carmen_logfile_index_p index = carmen_logfile_index_messages(fp);
  if (index == NULL) {
    fprintf(stderr, "Error: could not index %s\n", argv[1]);
    carmen_fclose(fp);
    return 1;
  }
  char *line = malloc(LINE_MAX_BYTES);
  int lasers = 0;
  for (int i = 0; i < index->num_messages; ++i) {
    if (carmen_logfile_read_line(index, fp, i, LINE_MAX_BYTES, line) < 0) continue;
    if (strncmp(line, "FLASER ", 7) == 0 || strncmp(line, "ROBOTLASER1 ", 12) == 0) ++lasers;
  }
  printf("messages %d lasers %d\n", index->num_messages, lasers);
  free(line);
  carmen_logfile_free_index(&index);
  carmen_fclose(fp);
  return 0;
}
