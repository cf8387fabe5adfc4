/* map.h — CARMEN 0.7.4's map types (maptools/map.h): the same names, macro
 * values, layouts and include guard (CARMEN_MAP_H), so that a program may
 * include CARMEN's map.h or ours, in either order, and get one definition.
 * carmen_point_t comes from CARMEN's global.h when that is present (see
 * carmen_compat/carmen_shared_types.h). */
#include <carmen_compat/carmen_shared_types.h>

#ifndef CARMEN_MAP_H
#define CARMEN_MAP_H

#ifdef __cplusplus
extern "C" {
#endif

/* Place types. A position stores x y, a pose x y theta, a localization init
 * x y theta x_std y_std theta_std. */
#define CARMEN_NAMED_POSITION_TYPE 0
#define CARMEN_NAMED_POSE_TYPE 1
#define CARMEN_LOCALIZATION_INIT_TYPE 2

/* Off-limits item types: a point uses x1 y1, a line and a rectangle
 * x1 y1 x2 y2 (cells). */
#define CARMEN_OFFLIMITS_POINT_ID 0
#define CARMEN_OFFLIMITS_LINE_ID 1
#define CARMEN_OFFLIMITS_RECT_ID 2

/* Hierarchical-map link types: a door joins two zones with two points per
 * zone, an elevator stacks zones with one point per zone. */
#define CARMEN_HMAP_LINK_DOOR 1
#define CARMEN_HMAP_LINK_ELEVATOR 2

/* map_name: set by the gridmap readers to a malloc()ed copy of the file name
 * (the named readers: of the chunk name), as CARMEN's readers do. The caller
 * owns it and releases it with free(config.map_name). */
typedef struct {
  int x_size;
  int y_size;
  double resolution; /* metres per cell */
  char *map_name;
} carmen_map_config_t, *carmen_map_config_p;

/* map[x][y] == complete_map[x * y_size + y] (x-major). The readers allocate
 * both with malloc(): release with free(map->map), free(map->complete_map)
 * and free(map->config.map_name). */
typedef struct {
  carmen_map_config_t config;
  float *complete_map;
  float **map;
} carmen_map_t, *carmen_map_p;

typedef struct {
  int type;      /* CARMEN_NAMED_POSITION_TYPE ... */
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

typedef struct {
  carmen_map_config_t config;
  float *complete_data;
  float ***dist;
} carmen_exp_dist_t, *carmen_exp_dist_p;

typedef struct {
  int x, y;
  carmen_map_p map;
} carmen_map_point_t, *carmen_map_point_p;

typedef struct {
  carmen_point_t pose;
  carmen_map_p map;
} carmen_world_point_t, *carmen_world_point_p;

typedef struct {
  int type; /* CARMEN_OFFLIMITS_POINT_ID ... */
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

/* A door or an elevator joining map zones. keys[i] indexes
 * carmen_hmap_t.zone_names; points has num_points = degree * (2 for a door,
 * 1 for an elevator) entries, those of keys[i] at points[i * (num_points /
 * degree) ...]. */
typedef struct {
  int type;   /* CARMEN_HMAP_LINK_DOOR or CARMEN_HMAP_LINK_ELEVATOR */
  int degree; /* number of zones joined (2 for a door) */
  int *keys;
  int num_points;
  carmen_point_p points;
} carmen_hmap_link_t, *carmen_hmap_link_p;

/* A hierarchical map. The reader allocates zone_names, each name, links and
 * each link's keys and points with malloc(). */
typedef struct {
  int num_zones;
  char **zone_names;
  int num_links;
  carmen_hmap_link_p links;
} carmen_hmap_t, *carmen_hmap_p;

#ifdef __cplusplus
}
#endif
#endif /* CARMEN_MAP_H */
