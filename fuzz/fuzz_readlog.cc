// CARMEN's readlog.h converters on one NUL-terminated line.
#include <cstdlib>
#include <cstring>
#include <vector>

#include "carmen/readlog.h"
#include "fuzz_support.h"

namespace {

void free_laser(carmen_laser_laser_message *m) {
  std::free(m->range);
  std::free(m->remission);
  std::free(m->host);
}
void free_robot(carmen_robot_laser_message *m) {
  std::free(m->range);
  std::free(m->tooclose);
  std::free(m->remission);
  std::free(m->host);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  std::vector<char> line(data, data + size);
  line.push_back('\0');
  std::vector<char> work;
  auto fresh = [&] {
    work = line;
    return work.data();
  };
  carmen_laser_laser_message laser;
  std::memset(&laser, 0, sizeof laser);
  carmen_string_to_laser_laser_message(fresh(), &laser);
  carmen_string_to_laser_laser_message_orig(fresh(), &laser);
  free_laser(&laser);
  carmen_robot_laser_message robot;
  std::memset(&robot, 0, sizeof robot);
  carmen_string_to_robot_laser_message(fresh(), &robot);
  carmen_string_to_robot_laser_message_orig(fresh(), &robot);
  free_robot(&robot);
  carmen_base_odometry_message odom;
  std::memset(&odom, 0, sizeof odom);
  carmen_string_to_base_odometry_message(fresh(), &odom);
  std::free(odom.host);
  carmen_simulator_truepos_message truepos;
  std::memset(&truepos, 0, sizeof truepos);
  carmen_string_to_simulator_truepos_message(fresh(), &truepos);
  std::free(truepos.host);
  return 0;
}
