/* map_io.h — CARMEN 0.7.4's map file API (maptools/map_io.h and the structs
 * of maptools/map.h), with CARMEN's names and signatures.
 *
 * Differences from CARMEN, all on the safe side:
 *  - String arguments are `const char *` (CARMEN: `char *`); C callers are
 *    unaffected.
 *  - Readers parse and check the whole file (on top of the C++ reader in
 *    carmen_compat/map_file.h): a truncated or damaged file, or a grid map
 *    with invalid cell values, makes every reader print a message naming the
 *    file to stderr and return -1, where CARMEN could crash or return garbage.
 *  - Files are always read and written little-endian (CARMEN: host order).
 *  - The comment block ends its Description line with a newline (CARMEN 0.7.4
 *    forgets it) and keeps lines short enough for CARMEN's own reader.
 * Functions return 0 on success and -1 on error unless said otherwise. */
#ifndef CARMEN_MAP_IO_H
#define CARMEN_MAP_IO_H

#include <time.h>

#include "carmen/carmen_stdio.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- File id and chunk codes ------------------------------------------- */
#define CARMEN_MAP_LABEL "CARMENMAPFILE"
#define CARMEN_MAP_VERSION "v020"

#define CARMEN_MAP_CREATOR_OLD_CHUNK 0 /* pre-0.7 creator code (not a CARMEN name) */
#define CARMEN_MAP_GRIDMAP_CHUNK 1
#define CARMEN_MAP_OFFLIMITS_CHUNK 2
#define CARMEN_MAP_HMAP_CHUNK 3
#define CARMEN_MAP_PLACES_CHUNK 4
#define CARMEN_MAP_EXPECTED_CHUNK 8
#define CARMEN_MAP_LASERSCANS_CHUNK 16
#define CARMEN_MAP_CREATOR_CHUNK 32
#define CARMEN_MAP_GLOBAL_OFFSET_CHUNK 64
#define CARMEN_MAP_NAMED_CHUNK_FLAG 0x80

/* ---- Structs (CARMEN's maptools/map.h) ---------------------------------- */
typedef struct {
  int x_size;
  int y_size;
  double resolution; /* metres per cell */
  char *map_name;    /* the readers here set it to NULL */
} carmen_map_config_t, *carmen_map_config_p;

/* map[x][y] == complete_map[x * y_size + y] (x-major). Both arrays come from
 * malloc(): release with free(map->map) and free(map->complete_map). */
typedef struct {
  carmen_map_config_t config;
  float *complete_map;
  float **map;
} carmen_map_t, *carmen_map_p;

/* Place types. A position stores x y, a pose x y theta, a localization init
 * x y theta x_std y_std theta_std. */
#define CARMEN_NAMED_POSITION_TYPE 0
#define CARMEN_NAMED_POSE_TYPE 1
#define CARMEN_LOCALIZATION_INIT_TYPE 2

typedef struct {
  int type;
  int size;      /* not stored in map files; the readers set it to 0 */
  char name[22]; /* 20 characters are stored in the file */
  double x, y, theta;
  double x_std, y_std, theta_std;
} carmen_place_t, *carmen_place_p;

/* places from malloc(): release with free(list.places). */
typedef struct {
  carmen_place_p places;
  int num_places;
} carmen_map_placelist_t, *carmen_map_placelist_p;

typedef enum {
  CARMEN_OFFLIMITS_POINT_ID,
  CARMEN_OFFLIMITS_LINE_ID,
  CARMEN_OFFLIMITS_RECT_ID
} carmen_offlimits_type_t;

/* A point uses x1 y1; a line and a rectangle use x1 y1 x2 y2 (cells). */
typedef struct {
  int type; /* carmen_offlimits_type_t */
  int x1, y1, x2, y2;
} carmen_offlimits_t, *carmen_offlimits_p;

typedef struct {
  carmen_offlimits_p offlimits;
  int list_length;
} carmen_offlimits_list_t, *carmen_offlimits_list_p;

/* range from malloc() (one per scan), the scan array too. */
typedef struct {
  double x, y, theta;
  int num_readings;
  float *range;
} carmen_laser_scan_t, *carmen_laser_scan_p;

typedef struct {
  double x, y, theta;
} carmen_global_offset_t, *carmen_global_offset_p;

/* ---- Writers ------------------------------------------------------------ */
/* Comments, id, creator and grid map, then places, off-limits and laser
 * scans when there are any (num_* > 0). */
int carmen_map_write_all(carmen_FILE *fp, float **prob, int size_x, int size_y, double resolution,
                         const char *comment_origin, const char *comment_description,
                         const char *creator_origin, const char *creator_description, carmen_place_p places,
                         int num_places, carmen_offlimits_p offlimits_list, int offlimits_num_items,
                         carmen_laser_scan_p scan_list, int num_scans);
int carmen_map_write_comment_chunk(carmen_FILE *fp, int size_x, int size_y, double resolution,
                                   const char *origin, const char *description);
int carmen_map_write_id(carmen_FILE *fp);
/* User from $USER, time now, time_t written with sizeof(time_t) bytes. */
int carmen_map_write_creator_chunk(carmen_FILE *fp, const char *origin, const char *description);
int carmen_map_write_gridmap_chunk(carmen_FILE *fp, float **prob, int size_x, int size_y, double resolution);
int carmen_map_write_places_chunk(carmen_FILE *fp, carmen_place_p places, int num_places);
int carmen_map_write_offlimits_chunk(carmen_FILE *fp, carmen_offlimits_p offlimits_list,
                                     int num_offlimits_items);
int carmen_map_write_laserscans_chunk(carmen_FILE *fp, carmen_laser_scan_p scan_list, int num_scans);
int carmen_map_write_global_offset_chunk(carmen_FILE *fp, carmen_global_offset_t *global_offset);

int carmen_map_write_named_gridmap_chunk(carmen_FILE *fp, const char *name, float **prob, int size_x,
                                         int size_y, double resolution);
int carmen_map_write_named_places_chunk(carmen_FILE *fp, const char *name, carmen_place_p places,
                                        int num_places);
int carmen_map_write_named_offlimits_chunk(carmen_FILE *fp, const char *name,
                                           carmen_offlimits_p offlimits_list, int num_offlimits_items);
int carmen_map_write_named_laserscans_chunk(carmen_FILE *fp, const char *name, carmen_laser_scan_p scan_list,
                                            int num_scans);
int carmen_map_write_named_global_offset_chunk(carmen_FILE *fp, const char *name,
                                               carmen_global_offset_t *global_offset);

/* ---- Readers (take a file name; ".gz" names are gunzipped) --------------- */
/* The unnamed readers use the first unnamed chunk of their type; the named
 * ones the first chunk of the type with that name. (CARMEN's unnamed readers
 * stop at the first chunk of the type, named or not, and misread a named
 * one.) carmen_map_read_gridmap_chunk allocates map->complete_map and
 * map->map and sets map->config. */
int carmen_map_read_gridmap_chunk(const char *filename, carmen_map_p map);
int carmen_map_read_gridmap_config(const char *filename, carmen_map_config_p config);
/* Buffers: username >= 11 bytes, origin and description >= 81 bytes; any
 * argument may be NULL. Falls back to an old-style (code 0) creator. */
int carmen_map_read_creator_chunk(const char *filename, time_t *creation_time, char *username, char *origin,
                                  char *description);
int carmen_map_read_places_chunk(const char *filename, carmen_map_placelist_p places);
/* Points first, then lines, then rectangles; *offlimits_list is NULL when
 * the chunk is empty. */
int carmen_map_read_offlimits_chunk(const char *filename, carmen_offlimits_p *offlimits_list,
                                    int *list_length);
int carmen_map_read_laserscans_chunk(const char *filename, carmen_laser_scan_p *scan_list, int *num_scans);
int carmen_map_read_global_offset_chunk(const char *filename, carmen_global_offset_p global_offset);

int carmen_map_read_named_gridmap_chunk(const char *filename, const char *chunk_name, carmen_map_p map);
int carmen_map_read_named_places_chunk(const char *filename, const char *chunk_name,
                                       carmen_map_placelist_p places);
int carmen_map_read_named_offlimits_chunk(const char *filename, const char *chunk_name,
                                          carmen_offlimits_p *offlimits_list, int *list_length);
int carmen_map_read_named_laserscans_chunk(const char *filename, const char *chunk_name,
                                           carmen_laser_scan_p *scan_list, int *num_scans);
int carmen_map_read_named_global_offset_chunk(const char *filename, const char *chunk_name,
                                              carmen_global_offset_p global_offset);

/* ---- Utilities ---------------------------------------------------------- */
/* 1 if the file opens and its comments are followed by CARMENMAPFILEv020,
 * else 0 (prints nothing). */
int carmen_map_file(const char *filename);
/* The size field of the first chunk of this type (named or not), or 0 when
 * there is none or the file cannot be read (then a message is printed). */
int carmen_map_chunk_exists(const char *filename, int specific_chunk);
int carmen_map_named_chunk_exists(const char *filename, int specific_chunk, const char *chunk_name);
/* Rewinds, skips the comments and id, and stops at the first chunk whose type
 * (named flag masked off) is specific_chunk: fp is left just after the type
 * byte, so the int32 size comes next. -1 when there is none. */
int carmen_map_advance_to_chunk(carmen_FILE *fp, int specific_chunk);
/* The same for a named chunk with this name; fp is left just after the type
 * byte too. */
int carmen_map_advance_to_named_chunk(carmen_FILE *fp, int specific_chunk, const char *chunk_name);

#ifdef __cplusplus
}
#endif
#endif /* CARMEN_MAP_IO_H */
