/* Stand-in for CARMEN's carmen.h (see ../../README.md). */
#ifndef CARMEN_H
#define CARMEN_H
#define CARMEN_STANDIN_CARMEN 1

#ifdef __cplusplus
extern "C" {
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>
#include <sys/types.h>

#include <carmen/global.h>
#include <carmen/base_messages.h>
#include <carmen/simulator_messages.h>
#include <carmen/laser_messages.h>
#include <carmen/robot_messages.h>
#include <carmen/gps_nmea_messages.h>
#include <carmen/map.h>
#include <carmen/map_io.h>
#include <carmen/readlog.h>

#ifdef __cplusplus
}
#endif
#endif
