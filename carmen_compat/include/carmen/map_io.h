/* map_io.h — CARMEN 0.7.4's map file API (maptools/map_io.h; the structs are
 * in carmen/map.h), with CARMEN's names, signatures and macro values.
 *
 * Differences from CARMEN, all on the safe side:
 *  - String arguments are `const char *` (CARMEN: `char *`); C callers are
 *    unaffected.
 *  - Readers find their chunk as CARMEN does (the first of its type, named
 *    or not, scanning from the start; chunks after it are not read) and check
 *    what they read (on top of the C++ reader in carmen_compat/map_file.h): a
 *    damaged chunk (the one asked for or one before it: a size the file does
 *    not hold, a payload that does not parse) makes the reader print a
 *    message naming the file and the chunk's byte offset to stderr and return
 *    -1, where CARMEN could crash or return garbage. Every reader clears its
 *    outputs first, so a failure leaves them zero / NULL, never as they were.
 *    Grid cells that are not -1, [0, 1] or [2, 3] (damage) are returned as
 *    stored, as CARMEN's are, with a warning on stderr.
 *  - Files are always read and written little-endian (CARMEN: host order).
 *  - The comment block is CARMEN's, byte for byte, except that newlines
 *    inside a description become spaces and each line is cut to fit CARMEN's
 *    own reader (fgets with 100 bytes).
 *  - Where CARMEN's behaviour is undefined or a crash (an unknown HMAP link
 *    type, PPM bytes out of range, a NULL chunk name),
 *    the function below says what it does instead.
 * Functions return 0 on success and -1 on error unless said otherwise. */
/* The search for CARMEN's own headers comes before our include guard (see
 * carmen_compat/carmen_shared_types.h). CARMEN_MAP_IO_H is CARMEN's guard:
 * whichever map_io.h a program includes first is the one it gets. */
#include <carmen_compat/carmen_shared_types.h>

#ifndef CARMEN_MAP_IO_H
#define CARMEN_MAP_IO_H

#include <time.h>

#include <carmen/carmen_stdio.h>
#include <carmen/map.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- File id and chunk codes ------------------------------------------- */
#define CARMEN_MAP_LABEL "CARMENMAPFILE"
#define CARMEN_MAP_VERSION "v020"

#define CARMEN_MAP_NO_CHUNK 0
#define CARMEN_MAP_CREATOR_OLD_CHUNK 0 /* pre-0.7 creator code (not a CARMEN name) */
#define CARMEN_MAP_GRIDMAP_CHUNK 1
#define CARMEN_MAP_OFFLIMITS_CHUNK 2
#define CARMEN_MAP_HMAP_CHUNK 3
#define CARMEN_MAP_PLACES_CHUNK 4
#define CARMEN_MAP_EXPECTED_CHUNK 8
#define CARMEN_MAP_LASERSCANS_CHUNK 16
#define CARMEN_MAP_CREATOR_CHUNK 32
#define CARMEN_MAP_GLOBAL_OFFSET_CHUNK 64
#define CARMEN_MAP_NAMED_CHUNK_FLAG (1 << 7)
#define CARMEN_MAP_CHUNK_IS_NAMED(type) ((type) & CARMEN_MAP_NAMED_CHUNK_FLAG)

/* ---- Writers ------------------------------------------------------------ */
/* Comments, id, creator and grid map, then places, off-limits and laser
 * scans when there are any (num_* > 0). */
int carmen_map_write_all(carmen_FILE *fp, float **prob, int size_x, int size_y, double resolution,
                         const char *comment_origin, const char *comment_description,
                         const char *creator_origin, const char *creator_description, carmen_place_p places,
                         int num_places, carmen_offlimits_p offlimits_list, int offlimits_num_items,
                         carmen_laser_scan_p scan_list, int num_scans);
/* CARMEN's block: a rule of 53 '#', "#", "# Carnegie Mellon Robot Toolkit
 * (CARMEN) map file", "#", "# Map author    : " getlogin() (or "UNKNOWN"),
 * "# Creation date : " asctime(localtime(now)), "# Map size      : X x Y",
 * "# Resolution    : %.1f", "# Origin        : ", "# Description   : "
 * without a newline (so the file reads "...: description#"), "#", the rule.
 * A NULL origin or description is written "(null)", as glibc prints CARMEN's
 * NULL. */
int carmen_map_write_comment_chunk(carmen_FILE *fp, int size_x, int size_y, double resolution,
                                   const char *origin, const char *description);
int carmen_map_write_id(carmen_FILE *fp);
/* User getlogin() (or "UNKNOWN" when the process has no login name, as
 * CARMEN's), time now, time_t written with sizeof(time_t) bytes. */
int carmen_map_write_creator_chunk(carmen_FILE *fp, const char *origin, const char *description);
int carmen_map_write_named_creator_chunk(carmen_FILE *fp, const char *name, const char *origin,
                                         const char *description);
int carmen_map_write_gridmap_chunk(carmen_FILE *fp, float **prob, int size_x, int size_y, double resolution);
int carmen_map_write_places_chunk(carmen_FILE *fp, carmen_place_p places, int num_places);
int carmen_map_write_offlimits_chunk(carmen_FILE *fp, carmen_offlimits_p offlimits_list,
                                     int num_offlimits_items);
int carmen_map_write_laserscans_chunk(carmen_FILE *fp, carmen_laser_scan_p scan_list, int num_scans);
int carmen_map_write_global_offset_chunk(carmen_FILE *fp, carmen_global_offset_t *global_offset);

/* A hierarchical map (HMAP, never named in CARMEN). Every link must be a
 * door or an elevator, its keys valid zone indices, and zone names shorter
 * than 128 characters (CARMEN's reader stops there). */
int carmen_map_write_hmap_chunk(carmen_FILE *fp, carmen_hmap_p hmap);

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
/* The unnamed readers use the first chunk of their type, named or not (a
 * named chunk's name is skipped), as CARMEN's do; the named ones the first
 * named chunk of the type with that name (chunk_name NULL: -1).
 * On any failure the outputs are zero / NULL: map->config.x_size, y_size and
 * resolution 0, map_name, complete_map and map NULL; a place list NULL with
 * num_places 0; *offlimits_list / *scan_list NULL with a count of 0; an
 * offset 0, 0, 0; a creator time 0 and empty strings; an hmap all zero.
 * A missing chunk is reported on stderr except by the unnamed places,
 * off-limits and global offset readers, which return -1 silently, as
 * CARMEN's do (so that, say, writing a PPM of a map without off-limits
 * prints nothing).
 * carmen_map_read_gridmap_chunk allocates map->complete_map and map->map and
 * sets map->config. The gridmap readers set config.map_name to a malloc()ed
 * copy of the file name (the named ones: of chunk_name), as CARMEN's do; the
 * caller owns it and free()s it. */
int carmen_map_read_gridmap_chunk(const char *filename, carmen_map_p map);
/* Reads only the gridmap's size and resolution (checked against the chunk's
 * size): damaged cells do not matter here, as in CARMEN. */
int carmen_map_read_gridmap_config(const char *filename, carmen_map_config_p config);
/* Buffers: username >= 11 bytes, origin and description >= 81 bytes; any
 * argument may be NULL. Falls back to an old-style (code 0) creator. */
int carmen_map_read_creator_chunk(const char *filename, time_t *creation_time, char *username, char *origin,
                                  char *description);
int carmen_map_read_named_creator_chunk(const char *filename, const char *chunk_name, time_t *creation_time,
                                        char *username, char *origin, char *description);
int carmen_map_read_places_chunk(const char *filename, carmen_map_placelist_p places);
/* Points first, then lines, then rectangles; *offlimits_list is NULL when
 * the chunk is empty. */
int carmen_map_read_offlimits_chunk(const char *filename, carmen_offlimits_p *offlimits_list,
                                    int *list_length);
/* Reads the off-limits chunk and marks its cells in map (already read, same
 * size) by adding 2.0, as CARMEN does: points, lines (CARMEN's Bresenham,
 * both ends) and rectangles (x1..x2 by y1..y2, inclusive); cells outside the
 * map are left out. -1 as in CARMEN when there is no off-limits chunk, when
 * it is empty, or when map has no cells. */
int carmen_map_read_offlimits_chunk_into_map(const char *filename, carmen_map_p map);
int carmen_map_read_laserscans_chunk(const char *filename, carmen_laser_scan_p *scan_list, int *num_scans);
/* Fills *hmap from the first HMAP chunk, named or not; every array comes
 * from malloc(): free each zone name, zone_names, each link's keys and
 * points, and links. On error *hmap is all zero (NULL arrays, no zones). */
int carmen_map_read_hmap_chunk(const char *filename, carmen_hmap_p hmap);
int carmen_map_read_global_offset_chunk(const char *filename, carmen_global_offset_p global_offset);

int carmen_map_read_named_gridmap_chunk(const char *filename, const char *chunk_name, carmen_map_p map);
int carmen_map_read_named_gridmap_config(const char *filename, const char *chunk_name,
                                         carmen_map_config_p config);
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
 * there is none or the file cannot be read up to it (then a message is
 * printed). */
int carmen_map_chunk_exists(const char *filename, int specific_chunk);
int carmen_map_named_chunk_exists(const char *filename, int specific_chunk, const char *chunk_name);
/* Rewinds, skips the comments and id, and stops at the first chunk whose type
 * (named flag masked off) is specific_chunk: fp is left at its type byte, as
 * CARMEN leaves it (its readers carmen_fgetc() the type next). -1 when there
 * is none. */
int carmen_map_advance_to_chunk(carmen_FILE *fp, int specific_chunk);
/* The same for a named chunk with this name; fp is left at its type byte
 * too. */
int carmen_map_advance_to_named_chunk(carmen_FILE *fp, int specific_chunk, const char *chunk_name);

/* Copies the comment lines and the map id from fp_in (from where it is: a
 * freshly opened map) to fp_out. -1 when the id does not follow the
 * comments. Lines of any length are copied whole. */
int carmen_map_copy_comments(carmen_FILE *fp_in, carmen_FILE *fp_out);
/* Copies a map from fp_in to fp_out without the unnamed chunks of the
 * num_chunks types given (ints, 0..127) after num_chunks. Named chunks are
 * always copied, as in CARMEN (its table is indexed by the raw type byte,
 * so type | 0x80 is never in it): maptool's strip keeps a map's named
 * gridmaps and hmap zones. -1 for a type out of range or a truncated
 * chunk. */
int carmen_map_vstrip(carmen_FILE *fp_in, carmen_FILE *fp_out, int num_chunks, ...);
/* carmen_map_vstrip() of one chunk type. */
int carmen_map_strip(carmen_FILE *fp_in, carmen_FILE *fp_out, int chunk);
/* Appends to out_file (an existing map; it may be in_file) a copy of the
 * first chunk of chunk_type in in_file, named chunk_name. -1 when in_file has
 * no such chunk, when that chunk is already named, or when out_file already
 * has a chunk of that type with that name. */
int carmen_map_name_chunk(const char *in_file, const char *out_file, int chunk_type, const char *chunk_name);
/* Writes map as a binary PPM (P6, x_size by y_size, the top row is the
 * largest y): unknown (-1) blue, a probability p grey 255 - 255 * p, an
 * off-limits cell (2 + p) red-tinted (255, 255 - 255 * p, same); bytes are
 * truncated as CARMEN's conversion to char does. Values that are none of
 * these (damage) are clamped to 0..255 where CARMEN's are undefined. */
int carmen_map_write_to_ppm(carmen_map_p map, const char *output_filename);

/* ---- CARMEN's map-server calls, without IPC ------------------------------ */
/* CARMEN declares these in map_io.h and implements them in its map server
 * (map_interface), which publishes the map over IPC. vasco_gpu has no IPC, so
 * a CARMEN program that calls them links and runs, and is told plainly that
 * nothing is served:
 *  - carmen_map_set_filename stores a copy of the name (NULL: none) that a
 *    publish would use; it publishes nothing.
 *  - carmen_map_publish_update does nothing (there is no one to publish to)
 *    and prints nothing.
 *  - carmen_map_initialize_ipc prints "carmen_map_initialize_ipc: no IPC in
 *    vasco_gpu: <file> cannot be served to other processes" and returns -1,
 *    so that a map server (CARMEN's param_daemon with a map, map_server)
 *    stops with its own error message instead of waiting for requests that
 *    never reach it. Link CARMEN's map_interface library to serve maps. */
int carmen_map_initialize_ipc(void);
void carmen_map_set_filename(const char *new_filename);
void carmen_map_publish_update(void);

#ifdef __cplusplus
}
#endif
#endif /* CARMEN_MAP_IO_H */
