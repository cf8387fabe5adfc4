/* The layouts of CARMEN 0.7.4's structs that our headers share, checked at
 * compile time against offsets worked out by hand from CARMEN's declarations
 * for an LP64 target (int 4, pointer/long/double 8, enum 4; each member at
 * the next multiple of its alignment). Whichever header defined a type, the
 * program sees this layout. */
#ifndef VASCO_TESTS_LAYOUT_CHECK_H
#define VASCO_TESTS_LAYOUT_CHECK_H

#include <stddef.h>

#if defined(__LP64__)
#define LAYOUT(type, member, offset) _Static_assert(offsetof(type, member) == (offset), #type "." #member)
#define SIZE(type, size) _Static_assert(sizeof(type) == (size), "sizeof " #type)

SIZE(carmen_point_t, 24);
LAYOUT(carmen_point_t, theta, 16);

SIZE(carmen_laser_laser_config_t, 56);
LAYOUT(carmen_laser_laser_config_t, start_angle, 8);
LAYOUT(carmen_laser_laser_config_t, accuracy, 40);
LAYOUT(carmen_laser_laser_config_t, remission_mode, 48);

SIZE(carmen_laser_laser_message, 112);
LAYOUT(carmen_laser_laser_message, config, 8);
LAYOUT(carmen_laser_laser_message, num_readings, 64);
LAYOUT(carmen_laser_laser_message, range, 72);
LAYOUT(carmen_laser_laser_message, num_remissions, 80);
LAYOUT(carmen_laser_laser_message, remission, 88);
LAYOUT(carmen_laser_laser_message, timestamp, 96);
LAYOUT(carmen_laser_laser_message, host, 104);

SIZE(carmen_robot_laser_message, 208);
LAYOUT(carmen_robot_laser_message, num_readings, 64);
LAYOUT(carmen_robot_laser_message, range, 72);
LAYOUT(carmen_robot_laser_message, tooclose, 80);
LAYOUT(carmen_robot_laser_message, num_remissions, 88);
LAYOUT(carmen_robot_laser_message, remission, 96);
LAYOUT(carmen_robot_laser_message, laser_pose, 104);
LAYOUT(carmen_robot_laser_message, robot_pose, 128);
LAYOUT(carmen_robot_laser_message, tv, 152);
LAYOUT(carmen_robot_laser_message, forward_safety_dist, 168);
LAYOUT(carmen_robot_laser_message, turn_axis, 184);
LAYOUT(carmen_robot_laser_message, timestamp, 192);
LAYOUT(carmen_robot_laser_message, host, 200);

SIZE(carmen_base_odometry_message, 64);
LAYOUT(carmen_base_odometry_message, acceleration, 40);
LAYOUT(carmen_base_odometry_message, timestamp, 48);
LAYOUT(carmen_base_odometry_message, host, 56);

SIZE(carmen_simulator_truepos_message, 64);
LAYOUT(carmen_simulator_truepos_message, odometrypose, 24);
LAYOUT(carmen_simulator_truepos_message, timestamp, 48);
LAYOUT(carmen_simulator_truepos_message, host, 56);

SIZE(carmen_position_t, 16);
SIZE(carmen_traj_point_t, 40);
LAYOUT(carmen_traj_point_t, r_vel, 32);
SIZE(carmen_base_velocity_message, 32);
LAYOUT(carmen_base_velocity_message, host, 24);
SIZE(carmen_base_sonar_message, 48);
LAYOUT(carmen_base_sonar_message, cone_angle, 8);
LAYOUT(carmen_base_sonar_message, range, 16);
LAYOUT(carmen_base_sonar_message, sonar_offsets, 24);
LAYOUT(carmen_base_sonar_message, host, 40);
SIZE(carmen_base_bumper_message, 40);
LAYOUT(carmen_base_bumper_message, state, 8);
LAYOUT(carmen_base_bumper_message, bumper_offsets, 16);
LAYOUT(carmen_base_bumper_message, host, 32);
SIZE(carmen_robot_velocity_message, 32);
SIZE(carmen_robot_vector_move_message, 32);
LAYOUT(carmen_robot_vector_move_message, theta, 8);
SIZE(carmen_robot_follow_trajectory_message, 72);
LAYOUT(carmen_robot_follow_trajectory_message, trajectory, 8);
LAYOUT(carmen_robot_follow_trajectory_message, robot_position, 16);
LAYOUT(carmen_robot_follow_trajectory_message, timestamp, 56);
LAYOUT(carmen_robot_follow_trajectory_message, host, 64);
SIZE(carmen_arm_state_message, 72);
LAYOUT(carmen_arm_state_message, num_joints, 4);
LAYOUT(carmen_arm_state_message, joint_angles, 8);
LAYOUT(carmen_arm_state_message, num_currents, 16);
LAYOUT(carmen_arm_state_message, joint_currents, 24);
LAYOUT(carmen_arm_state_message, num_vels, 32);
LAYOUT(carmen_arm_state_message, joint_angular_vels, 40);
LAYOUT(carmen_arm_state_message, gripper_closed, 48);
LAYOUT(carmen_arm_state_message, host, 64);
SIZE(carmen_gps_gpgga_message, 136);
LAYOUT(carmen_gps_gpgga_message, latitude_dm, 24);
LAYOUT(carmen_gps_gpgga_message, lat_orient, 32);
LAYOUT(carmen_gps_gpgga_message, longitude, 40);
LAYOUT(carmen_gps_gpgga_message, long_orient, 56);
LAYOUT(carmen_gps_gpgga_message, gps_quality, 60);
LAYOUT(carmen_gps_gpgga_message, num_satellites, 64);
LAYOUT(carmen_gps_gpgga_message, hdop, 72);
LAYOUT(carmen_gps_gpgga_message, data_age, 112);
LAYOUT(carmen_gps_gpgga_message, timestamp, 120);
LAYOUT(carmen_gps_gpgga_message, host, 128);
SIZE(carmen_gps_gprmc_message, 112);
LAYOUT(carmen_gps_gprmc_message, validity, 4);
LAYOUT(carmen_gps_gprmc_message, lat_orient, 32);
LAYOUT(carmen_gps_gprmc_message, speed, 64);
LAYOUT(carmen_gps_gprmc_message, var_dir, 88);
LAYOUT(carmen_gps_gprmc_message, date, 92);
LAYOUT(carmen_gps_gprmc_message, host, 104);
SIZE(carmen_imu_message, 120);
LAYOUT(carmen_imu_message, gyroZ, 96);
LAYOUT(carmen_imu_message, host, 112);
SIZE(carmen_pantilt_scanmark_message, 24);
LAYOUT(carmen_pantilt_scanmark_message, laserid, 4);
LAYOUT(carmen_pantilt_scanmark_message, host, 16);
SIZE(carmen_pantilt_laserpos_message, 72);
LAYOUT(carmen_pantilt_laserpos_message, x, 8);
LAYOUT(carmen_pantilt_laserpos_message, psi, 48);
LAYOUT(carmen_pantilt_laserpos_message, host, 64);

SIZE(carmen_map_config_t, 24);
LAYOUT(carmen_map_config_t, resolution, 8);
LAYOUT(carmen_map_config_t, map_name, 16);
SIZE(carmen_map_t, 40);
LAYOUT(carmen_map_t, complete_map, 24);
LAYOUT(carmen_map_t, map, 32);
SIZE(carmen_place_t, 80);
LAYOUT(carmen_place_t, size, 4);
LAYOUT(carmen_place_t, name, 8);
LAYOUT(carmen_place_t, x, 32);
LAYOUT(carmen_place_t, theta_std, 72);
SIZE(carmen_map_placelist_t, 16);
LAYOUT(carmen_map_placelist_t, num_places, 8);
SIZE(carmen_exp_dist_t, 40);
LAYOUT(carmen_exp_dist_t, dist, 32);
SIZE(carmen_map_point_t, 16);
LAYOUT(carmen_map_point_t, map, 8);
SIZE(carmen_world_point_t, 32);
LAYOUT(carmen_world_point_t, map, 24);
SIZE(carmen_offlimits_t, 20);
LAYOUT(carmen_offlimits_t, y2, 16);
SIZE(carmen_offlimits_list_t, 16);
LAYOUT(carmen_offlimits_list_t, list_length, 8);
SIZE(carmen_laser_scan_t, 40);
LAYOUT(carmen_laser_scan_t, num_readings, 24);
LAYOUT(carmen_laser_scan_t, range, 32);
SIZE(carmen_global_offset_t, 24);
SIZE(carmen_hmap_link_t, 32);
LAYOUT(carmen_hmap_link_t, keys, 8);
LAYOUT(carmen_hmap_link_t, num_points, 16);
LAYOUT(carmen_hmap_link_t, points, 24);
SIZE(carmen_hmap_t, 32);
LAYOUT(carmen_hmap_t, zone_names, 8);
LAYOUT(carmen_hmap_t, num_links, 16);
LAYOUT(carmen_hmap_t, links, 24);

SIZE(carmen_FILE, 24);
LAYOUT(carmen_FILE, fp, 8);
LAYOUT(carmen_FILE, comp_fp, 16);
SIZE(carmen_logfile_index_t, 16);
LAYOUT(carmen_logfile_index_t, offset, 8);

SIZE(evidence_grid, 136);
LAYOUT(evidence_grid, size_x, 8);
LAYOUT(evidence_grid, theta_offset, 16);
LAYOUT(evidence_grid, max_prob, 48);
LAYOUT(evidence_grid, wall_thickness, 72);
LAYOUT(evidence_grid, prob, 80);
LAYOUT(evidence_grid, distance_table_size, 88);
LAYOUT(evidence_grid, distance_table, 96);
LAYOUT(evidence_grid, first, 104);
LAYOUT(evidence_grid, start_theta, 128);
#endif

#endif
