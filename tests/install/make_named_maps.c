/* Writes the maps the install test gives to the CARMEN program stand-ins,
 * through the installed map_io writers:
 *
 *   DIR/named_only.map  comments, id, creator, a NAMED 100 x 120 gridmap and
 *                       NAMED places (3): CARMEN's unnamed readers find them
 *                       (they look for the first chunk of a type, named or not)
 *   DIR/rich.map        an unnamed 40 x 30 gridmap, then a named 110 x 110 one
 *                       ("second") and named places
 *   DIR/zones.map       an hmap file: an unnamed 20 x 20 overview gridmap and
 *                       two named zone gridmaps (60 x 50, 70 x 40)
 *
 * and prints, for each file, the bytes that stripping the unnamed gridmap
 * must remove: the chunk header (type byte, size int32) plus its size field
 * (10-byte description + 12-byte header + 4 bytes a cell), computed here
 * from the format, not by stripping.
 *
 *   make_named_maps DIR */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <carmen/carmen_stdio.h>
#include <carmen/map_io.h>

static float **grid(int sx, int sy, float value) {
  float *cells = malloc(sizeof(float) * (size_t)sx * (size_t)sy);
  float **rows = malloc(sizeof(float *) * (size_t)sx);
  for (int x = 0; x < sx; ++x) {
    rows[x] = cells + (size_t)x * (size_t)sy;
    for (int y = 0; y < sy; ++y) rows[x][y] = (x + y) % 3 == 0 ? -1.0f : value;
  }
  return rows;
}

static void free_grid(float **rows) {
  free(rows[0]);
  free(rows);
}

static carmen_FILE *start(const char *dir, const char *name, int sx, int sy) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  carmen_FILE *fp = carmen_fopen(path, "w");
  if (fp == NULL) {
    fprintf(stderr, "make_named_maps: cannot write %s\n", path);
    exit(1);
  }
  carmen_map_write_comment_chunk(fp, sx, sy, 0.05, "make_named_maps", "a test map");
  carmen_map_write_id(fp);
  carmen_map_write_creator_chunk(fp, "make_named_maps", "install test");
  return fp;
}

static void write_named_grid(carmen_FILE *fp, const char *name, int sx, int sy, float value) {
  float **g = grid(sx, sy, value);
  if (carmen_map_write_named_gridmap_chunk(fp, name, g, sx, sy, 0.05) < 0) exit(1);
  free_grid(g);
}

static void write_grid(carmen_FILE *fp, int sx, int sy, float value) {
  float **g = grid(sx, sy, value);
  if (carmen_map_write_gridmap_chunk(fp, g, sx, sy, 0.05) < 0) exit(1);
  free_grid(g);
}

static void write_named_places(carmen_FILE *fp, const char *name) {
  carmen_place_t places[3];
  memset(places, 0, sizeof places);
  const char *names[3] = {"door", "desk", "lift"};
  for (int i = 0; i < 3; ++i) {
    places[i].type = CARMEN_NAMED_POSITION_TYPE;
    strcpy(places[i].name, names[i]);
    places[i].x = 1.0 + i;
    places[i].y = 2.0 + i;
  }
  if (carmen_map_write_named_places_chunk(fp, name, places, 3) < 0) exit(1);
}

static long unnamed_gridmap_bytes(int sx, int sy) { return 1 + 4 + 10 + 12 + 4L * sx * sy; }

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: make_named_maps DIR\n");
    return 2;
  }
  carmen_FILE *fp = start(argv[1], "named_only.map", 100, 120);
  write_named_grid(fp, "floor1", 100, 120, 0.25f);
  write_named_places(fp, "floor1");
  carmen_fclose(fp);

  fp = start(argv[1], "rich.map", 40, 30);
  write_grid(fp, 40, 30, 0.75f);
  write_named_grid(fp, "second", 110, 110, 0.5f);
  write_named_places(fp, "second");
  carmen_fclose(fp);
  printf("rich.map %ld\n", unnamed_gridmap_bytes(40, 30));

  fp = start(argv[1], "zones.map", 20, 20);
  write_grid(fp, 20, 20, 0.1f);
  write_named_grid(fp, "zone_a", 60, 50, 0.2f);
  write_named_grid(fp, "zone_b", 70, 40, 0.3f);
  carmen_fclose(fp);
  printf("zones.map %ld\n", unnamed_gridmap_bytes(20, 20));
  return 0;
}
