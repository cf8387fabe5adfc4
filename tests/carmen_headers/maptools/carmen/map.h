/* Stand-in for CARMEN's maptools/map.h (see ../../README.md). Like CARMEN's,
 * it needs global.h (carmen_point_t) first. */
#ifndef CARMEN_MAP_H
#define CARMEN_MAP_H
#define CARMEN_STANDIN_MAP 1

#ifdef __cplusplus
extern "C" {
#endif

#define CARMEN_NAMED_POSITION_TYPE 0
#define CARMEN_NAMED_POSE_TYPE 1
#define CARMEN_LOCALIZATION_INIT_TYPE 2

#define CARMEN_OFFLIMITS_POINT_ID 0
#define CARMEN_OFFLIMITS_LINE_ID 1
#define CARMEN_OFFLIMITS_RECT_ID 2

#define CARMEN_HMAP_LINK_DOOR 1
#define CARMEN_HMAP_LINK_ELEVATOR 2

typedef struct {
  int x_size;
  int y_size;
  double resolution;
  char *map_name;
} carmen_map_config_t, *carmen_map_config_p;

typedef struct {
  carmen_map_config_t config;
  float *complete_map;
  float **map;
} carmen_map_t, *carmen_map_p;

typedef struct {
  int type, size;
  char name[22];
  double x, y, theta;
  double x_std, y_std, theta_std;
} carmen_place_t, *carmen_place_p;

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
  int type;
  int x1, y1, x2, y2;
} carmen_offlimits_t, *carmen_offlimits_p;

typedef struct {
  carmen_offlimits_p offlimits;
  int list_length;
} carmen_offlimits_list_t, *carmen_offlimits_list_p;

typedef struct {
  double x, y, theta;
  int num_readings;
  float *range;
} carmen_laser_scan_t, *carmen_laser_scan_p;

typedef struct {
  double x, y, theta;
} carmen_global_offset_t, *carmen_global_offset_p;

typedef struct {
  int type;
  int degree;
  int *keys;
  int num_points;
  carmen_point_p points;
} carmen_hmap_link_t, *carmen_hmap_link_p;

typedef struct {
  int num_zones;
  char **zone_names;
  int num_links;
  carmen_hmap_link_p links;
} carmen_hmap_t, *carmen_hmap_p;

#ifdef __cplusplus
}
#endif
#endif
