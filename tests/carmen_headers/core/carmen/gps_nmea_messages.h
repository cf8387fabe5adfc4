/* Stand-in for CARMEN's gps_nmea_messages.h (see ../../README.md). */
#ifndef GPS_NMEA_MESSAGES_H
#define GPS_NMEA_MESSAGES_H
#define CARMEN_STANDIN_GPS_NMEA_MESSAGES 1

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  int nr;
  double utc;
  double latitude;
  double latitude_dm;
  char lat_orient;
  double longitude;
  double longitude_dm;
  char long_orient;
  int gps_quality;
  int num_satellites;
  double hdop;
  double sea_level;
  double altitude;
  double geo_sea_level;
  double geo_sep;
  int data_age;
  double timestamp;
  char *host;
} carmen_gps_gpgga_message;

typedef struct {
  int nr;
  int validity;
  double utc;
  double latitude;
  double latitude_dm;
  char lat_orient;
  double longitude;
  double longitude_dm;
  char long_orient;
  double speed;
  double true_course;
  double variation;
  char var_dir;
  int date;
  double timestamp;
  char *host;
} carmen_gps_gprmc_message;

#ifdef __cplusplus
}
#endif
#endif
