/* readlog.h — CARMEN 0.7.4's log reading C API (logger/readlog.h), with
 * CARMEN's names and structs.
 *
 * For good input these behave as CARMEN's: arrays are realloc()ed when a count
 * changes, the host string is realloc()ed, and the converters return a pointer
 * just past the host (at " logger_timestamp"). Structs passed to a converter
 * must be zero-initialised or hold pointers from malloc(), as in CARMEN.
 *
 * Unlike CARMEN, bad input is never misread and never kills the process. The
 * text is parsed by the same code as carmen::LogReader (strict mode):
 *   - a converter returns NULL for a truncated line, a count that disagrees
 *     with the fields present, a non-numeric field, a negative count or one
 *     above 100000, a NaN/inf pose or timestamp, or extra fields; the message
 *     struct is then left untouched, and carmen_readlog_last_error() says why.
 *     NaN, inf and negative ranges are accepted, as data.
 *   - carmen_logfile_index_messages() indexes what precedes a read error or
 *     a corrupt / truncated gzip stream, as CARMEN does, and says so.
 *   - carmen_logfile_read_line() returns -1 (instead of dying) for a message
 *     number out of range, a message of max_line_length bytes or more, or a
 *     failed seek or short read; for the last two kinds it also moves on to
 *     the next message (or to the end), so a loop of
 *     carmen_logfile_read_next_line() until carmen_logfile_eof() never spins.
 */
/* The message structs are CARMEN's, from carmen_compat/carmen_shared_types.h
 * (or from CARMEN's own headers when a program uses them: see there); that
 * search comes before our include guard, which is CARMEN's (CARMEN_READLOG_H). */
#include <carmen_compat/carmen_shared_types.h>

#ifndef CARMEN_READLOG_H
#define CARMEN_READLOG_H

#include <sys/types.h>

#include <carmen/carmen_stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Byte offsets of the messages of a log: offset[i] is where message i
 * starts, offset[num_messages] the uncompressed length. As in CARMEN, every
 * byte that follows a '\n' (unless it is '\r') starts a message, so a blank
 * line is a message of one byte and a last line without '\n' is indexed. */
typedef struct {
  int num_messages;
  int current_position;
  off_t *offset;
} carmen_logfile_index_t, *carmen_logfile_index_p;

/* Reads the whole stream, then rewinds it. On a read error or a corrupt or
 * truncated gzip stream it indexes, as CARMEN does, the messages read before
 * the damage (a message cut by it is dropped) and reports the damage on
 * stderr and in carmen_readlog_last_error(). NULL for a NULL file, a file
 * that cannot be rewound, or more messages than the limit (below; the index
 * takes 8 bytes a message), reading stopping there. */
carmen_logfile_index_p carmen_logfile_index_messages(carmen_FILE *infile);
/* Not in CARMEN: the most messages carmen_logfile_index_messages indexes
 * (by default CARMEN_LOGFILE_MAX_MESSAGES, 16777216: an index of 128 MiB; a
 * file of nothing but newlines would otherwise make one of 8 bytes per byte).
 * Sets it for the process when max_messages > 0; returns the limit before. */
#define CARMEN_LOGFILE_MAX_MESSAGES 16777216
int carmen_logfile_set_max_messages(int max_messages);
/* Frees the index and sets *pindex to NULL. */
void carmen_logfile_free_index(carmen_logfile_index_p *pindex);
/* 1 when every message has been read. */
int carmen_logfile_eof(carmen_logfile_index_p index);
/* Fraction of the messages read, 0..1. */
float carmen_logfile_percent_read(carmen_logfile_index_p index);
/* Copies message `message_num` (with its '\n') into `line` and
 * NUL-terminates it; seeks only when not reading sequentially. Returns the
 * number of bytes copied, or -1 (see above). */
int carmen_logfile_read_line(carmen_logfile_index_p index, carmen_FILE *infile, int message_num,
                             int max_line_length, char *line);
/* carmen_logfile_read_line() of the message after the last one read. */
int carmen_logfile_read_next_line(carmen_logfile_index_p index, carmen_FILE *infile,
                                  int max_line_length, char *line);

/* Converters. The message name is skipped when the string starts with it
 * (for RAWLASERn / ROBOTLASERn the number after the name becomes `id`;
 * without the name, id = -1), so both whole log lines and the text after the
 * name are accepted. The string ends at '\n' or NUL. Each returns a pointer
 * just past the host, or NULL for bad input (see above). */
char *carmen_string_to_laser_laser_message(char *string, carmen_laser_laser_message *laser);
/* Old "LASERn num_readings ranges..." lines (and FLASER / RLASER lines, whose
 * poses are then dropped); the config is guessed as for FLASER. */
char *carmen_string_to_laser_laser_message_orig(char *string, carmen_laser_laser_message *laser);
char *carmen_string_to_robot_laser_message(char *string, carmen_robot_laser_message *laser);
/* FLASER / RLASER: laser_pose = the first pose triple, robot_pose = the odom
 * triple; the config is guessed from the beam count; id, tv, rv, the safety
 * distances and turn_axis are left as they were (as CARMEN's converter leaves
 * them); no remissions. */
char *carmen_string_to_robot_laser_message_orig(char *string, carmen_robot_laser_message *laser);
char *carmen_string_to_base_odometry_message(char *string, carmen_base_odometry_message *odometry);
char *carmen_string_to_simulator_truepos_message(char *string,
                                                 carmen_simulator_truepos_message *truepos);

/* Field of view and angle increment CARMEN assumes for an old laser line of
 * num_beams beams (see carmen_compat/log_reader.h for the exact expressions). */
double carmen_laser_guess_fov(int num_beams);
double carmen_laser_guess_angle_increment(int num_beams);

/* Not in CARMEN: why the last converter or index call of this thread failed
 * ("" when it did not). */
const char *carmen_readlog_last_error(void);

#ifdef __cplusplus
}
#endif
#endif /* CARMEN_READLOG_H */
