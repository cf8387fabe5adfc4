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
 *   - a converter refuses a truncated line, a count that disagrees with the
 *     fields present, a non-numeric field, a negative count or one above
 *     100000 (so no count makes an unbounded allocation), a NaN/inf pose or
 *     timestamp, or extra fields. It then says why on stderr (naming the
 *     converter and the field) and in carmen_readlog_last_error(), and leaves
 *     the message a valid empty one that CARMEN's callers can use unchanged:
 *     every array freed and NULL with its count 0, every other number 0, and
 *     `host` a malloc()ed "" (the caller frees it, as after a good line).
 *     It returns a pointer to the end of the line (its '\n' or NUL), so a
 *     caller that reads the logger timestamp there, as CARMEN's playback
 *     does, reads 0 instead of crashing. So a converter returns NULL only
 *     for a NULL argument; test carmen_readlog_last_error()[0] for success.
 *     NaN, inf and negative ranges are accepted, as data.
 *     Where memory runs out, the message is emptied likewise; where not even
 *     its "" host can be allocated, the process exits with "Out of memory"
 *     on stderr, as CARMEN's converters do on any failed allocation.
 *   - carmen_logfile_index_messages() prints CARMEN's progress on stderr
 *     ("\n\rIndexing messages (0%)", a "\rIndexing messages (N%)" every
 *     10 MB read, then "\rIndexing messages (100%) - N messages found.");
 *     it indexes what precedes a read error or a corrupt / truncated gzip
 *     stream, as CARMEN does, and says so.
 *   - every carmen_stdio call's result is checked as CARMEN's libglobal may
 *     return it when a program links that library (whose functions then
 *     replace ours: carmen_stdio.h): a carmen_fread of (size_t)-1 (zlib's
 *     error) or more than was asked is a read error; a carmen_fseek that
 *     returns the new offset (gzseek's) instead of 0 is a success, checked
 *     with carmen_ftell.
 *   - carmen_logfile_read_line() returns -1 (instead of dying) for a message
 *     number out of range, a message of max_line_length bytes or more, or a
 *     failed seek or short read (`line` is then ""); for the last two kinds
 *     it also moves on to the next message (or to the end), so a loop of
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
 * name (what CARMEN's playback passes) are accepted. The string ends at '\n'
 * or NUL. After the message's fields come "ipc_timestamp host
 * logger_timestamp", as the logger writes them. Each returns a pointer just
 * past the host (at " logger_timestamp"); for bad input, see above. */
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

/* The other messages CARMEN's logger writes, with their line formats (the
 * fields before the trailer). Arrays are realloc()ed to the counts read, as
 * in CARMEN; a count of 0 leaves the array NULL.
 *   ARM flags num_joints angles.. num_currents currents.. num_vels vels.. gripper_closed */
char *carmen_string_to_arm_state_message(char *string, carmen_arm_state_message *arm);
/*   SONAR cone_angle num_sonars ranges.. (x y theta of each sonar).. */
char *carmen_string_to_base_sonar_message(char *string, carmen_base_sonar_message *sonar);
/*   BUMPER num_bumpers states.. (x y of each bumper)..  (a state is an
 *   integer 0..255) */
char *carmen_string_to_base_bumper_message(char *string, carmen_base_bumper_message *bumper);
/*   BASEVELOCITY tv rv */
char *carmen_string_to_base_velocity_message(char *string, carmen_base_velocity_message *msg);
/*   NMEAGGA nr utc latitude_dm lat_orient longitude_dm long_orient gps_quality
 *           num_satellites hdop sea_level altitude geo_sea_level geo_sep data_age
 * latitude / longitude are the DDMM.MMMM values in degrees (DD + MM.MMMM/60,
 * unsigned: the orientation letters are kept apart, as in CARMEN); an
 * orientation is one character. */
char *carmen_string_to_gps_gpgga_message(char *string, carmen_gps_gpgga_message *gps_msg);
/*   NMEARMC nr validity utc latitude_dm lat_orient longitude_dm long_orient
 *           speed true_course variation var_dir date */
char *carmen_string_to_gps_gprmc_message(char *string, carmen_gps_gprmc_message *gps_msg);
/*   IMU accX accY accZ q0 q1 q2 q3 magX magY magZ gyroX gyroY gyroZ */
char *carmen_string_to_imu_message(char *string, carmen_imu_message *msg);
/*   POSITIONLASER id x y z phi theta psi */
char *carmen_string_to_pantilt_laserpos_message(char *string, carmen_pantilt_laserpos_message *laserpos);
/*   SCANMARK type laserid */
char *carmen_string_to_pantilt_scanmark_message(char *string, carmen_pantilt_scanmark_message *scanmark);
/*   FOLLOWTRAJECTORY x y theta tv rv length (x y theta tv rv of each point)..
 * (CARMEN's converter skips a leading "ROBOTVELOCITY" instead: both names
 * are skipped here.) */
char *carmen_string_to_robot_follow_trajectory_message(char *string,
                                                       carmen_robot_follow_trajectory_message *msg);
/*   VECTORMOVE distance theta */
char *carmen_string_to_robot_vector_move_message(char *string, carmen_robot_vector_move_message *msg);
/*   ROBOTVELOCITY tv rv  (the name CARMEN's converter skips is "VELOCITY":
 * both are skipped here) */
char *carmen_string_to_robot_velocity_message(char *string, carmen_robot_velocity_message *msg);

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
