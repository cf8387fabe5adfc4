// CARMEN's guesses of a laser's field of view and angle step from its beam
// count (FLASER / RLASER lines carry no config). See log_reader.h.
#include "carmen_compat/log_reader.h"

namespace carmen {

namespace {

// M_PI as CARMEN's headers define it (glibc's value).
constexpr double kPi = 3.14159265358979323846;

}  // namespace

double guess_laser_fov(int n) {
  if (n == 181) return kPi;
  if (n == 180) return kPi / 180.0 * 179.0;
  if (n == 361) return kPi;
  if (n == 360) return kPi / 180.0 * 179.5;
  if (n == 401) return kPi / 180.0 * 100.0;
  if (n == 400) return kPi / 100.0 * 99.75;
  return kPi;
}

double guess_laser_angle_increment(int n) {
  if (n == 181 || n == 180) return kPi / 180.0;
  if (n == 361 || n == 360) return kPi / 360.0;
  if (n == 401 || n == 400) return kPi / 720.0;
  return guess_laser_fov(n) / static_cast<double>(n - 1);
}

LaserConfig guess_laser_config(int n) {
  LaserConfig c;
  c.laser_type = 0;
  c.start_angle = -kPi / 2.0;
  c.fov = guess_laser_fov(n);
  c.angular_resolution = guess_laser_angle_increment(n);
  c.maximum_range = 80.0;
  c.accuracy = 0.01;
  c.remission_mode = 0;
  return c;
}

}  // namespace carmen
