/* A stand-in for CARMEN's maptool, written for the install test (no CARMEN
 * code): it calls map_io the way maptool's commands do, so the install test
 * can check that an unchanged CARMEN map tool behaves on our libraries as on
 * CARMEN's, on maps with named chunks and on damaged ones too.
 *
 *   maptool_standin info MAP               size, resolution and places, as maptool info prints them
 *   maptool_standin strip IN OUT CHUNK     IN without its chunks of type CHUNK (gridmap, places, ...)
 *   maptool_standin add_place MAP NAME X Y MAP with one more place (x, y in metres)
 *   maptool_standin toppm MAP OUT.ppm      the gridmap as a PPM picture
 *
 * Like maptool, it puts its structs on the stack without initialising them
 * and trusts what the readers leave in them: a reader that fails must still
 * leave them in a state a caller can print, realloc() and free(). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <carmen/carmen_stdio.h>
#include <carmen/map_io.h>

static int chunk_type(const char *name) {
  if (strcmp(name, "gridmap") == 0) return CARMEN_MAP_GRIDMAP_CHUNK;
  if (strcmp(name, "offlimits") == 0) return CARMEN_MAP_OFFLIMITS_CHUNK;
  if (strcmp(name, "places") == 0) return CARMEN_MAP_PLACES_CHUNK;
  if (strcmp(name, "laserscans") == 0) return CARMEN_MAP_LASERSCANS_CHUNK;
  if (strcmp(name, "creator") == 0) return CARMEN_MAP_CREATOR_CHUNK;
  return -1;
}

static int info(const char *path) {
  carmen_map_t map; /* uninitialised, as in maptool */
  carmen_map_placelist_t places;
  if (!carmen_map_file(path)) {
    fprintf(stderr, "%s is not a CARMEN map\n", path);
    return 1;
  }
  carmen_map_read_gridmap_chunk(path, &map);
  printf("size : %d x %d\n", map.config.x_size, map.config.y_size);
  printf("resolution : %.2f\n", map.config.resolution);
  if (carmen_map_chunk_exists(path, CARMEN_MAP_PLACES_CHUNK)) {
    carmen_map_read_places_chunk(path, &places);
    printf("places : %d\n", places.num_places);
    for (int i = 0; i < places.num_places; ++i)
      printf("  %s %.2f %.2f\n", places.places[i].name, places.places[i].x, places.places[i].y);
    free(places.places);
  }
  free(map.complete_map);
  free(map.map);
  free(map.config.map_name);
  return 0;
}

static int strip(const char *in_path, const char *out_path, const char *name) {
  const int type = chunk_type(name);
  if (type < 0) {
    fprintf(stderr, "unknown chunk %s\n", name);
    return 2;
  }
  carmen_FILE *in = carmen_fopen(in_path, "r");
  if (in == NULL) return 1;
  carmen_FILE *out = carmen_fopen(out_path, "w");
  if (out == NULL) return 1;
  const int rc = carmen_map_strip(in, out, type);
  carmen_fclose(in);
  carmen_fclose(out);
  return rc < 0 ? 1 : 0;
}

/* maptool's add_place: the places read (if any), one appended with realloc,
 * the map rewritten without its places and with the new list. */
static int add_place(const char *path, const char *name, double x, double y) {
  carmen_map_placelist_t places;
  places.places = NULL;
  places.num_places = 0;
  if (carmen_map_chunk_exists(path, CARMEN_MAP_PLACES_CHUNK)) carmen_map_read_places_chunk(path, &places);
  places.places = realloc(places.places, sizeof(carmen_place_t) * (size_t)(places.num_places + 1));
  if (places.places == NULL) return 1;
  carmen_place_t *p = &places.places[places.num_places++];
  memset(p, 0, sizeof *p);
  p->type = CARMEN_NAMED_POSITION_TYPE;
  strncpy(p->name, name, sizeof p->name - 1);
  p->x = x;
  p->y = y;

  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  carmen_FILE *in = carmen_fopen(path, "r");
  carmen_FILE *out = carmen_fopen(tmp, "w");
  if (in == NULL || out == NULL) return 1;
  int rc = carmen_map_strip(in, out, CARMEN_MAP_PLACES_CHUNK);
  if (rc >= 0) rc = carmen_map_write_places_chunk(out, places.places, places.num_places);
  carmen_fclose(in);
  carmen_fclose(out);
  free(places.places);
  if (rc < 0) return 1;
  return rename(tmp, path) == 0 ? 0 : 1;
}

static int toppm(const char *path, const char *out) {
  carmen_map_t map;
  if (carmen_map_read_gridmap_chunk(path, &map) < 0) {
    fprintf(stderr, "Error: %s has no gridmap\n", path);
    return 1;
  }
  carmen_map_read_offlimits_chunk_into_map(path, &map);
  const int rc = carmen_map_write_to_ppm(&map, out);
  free(map.complete_map);
  free(map.map);
  free(map.config.map_name);
  return rc < 0 ? 1 : 0;
}

int main(int argc, char **argv) {
  if (argc == 3 && strcmp(argv[1], "info") == 0) return info(argv[2]);
  if (argc == 5 && strcmp(argv[1], "strip") == 0) return strip(argv[2], argv[3], argv[4]);
  if (argc == 6 && strcmp(argv[1], "add_place") == 0)
    return add_place(argv[2], argv[3], atof(argv[4]), atof(argv[5]));
  if (argc == 4 && strcmp(argv[1], "toppm") == 0) return toppm(argv[2], argv[3]);
  fprintf(stderr, "usage: maptool_standin info MAP | strip IN OUT CHUNK | add_place MAP NAME X Y | toppm MAP OUT\n");
  return 2;
}
