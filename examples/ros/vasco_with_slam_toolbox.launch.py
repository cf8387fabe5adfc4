"""vasco_mapper next to slam_toolbox: slam_toolbox localises the robot (it keeps publishing
map -> odom on /tf), vasco_mapper maps every scan at its tf pose and re-renders the whole map on
each Path of optimised poses, publishing it on /map. slam_toolbox's own map is moved to
/slam_toolbox/map so that the two do not share a topic.

    ros2 launch vasco_with_slam_toolbox.launch.py                  # backend:=cuda by default
    ros2 launch vasco_with_slam_toolbox.launch.py backend:=cpu_threads path_topic:=/my_optimizer/path
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    backend = LaunchConfiguration("backend")
    path_topic = LaunchConfiguration("path_topic")
    return LaunchDescription([
        DeclareLaunchArgument("backend", default_value="cuda"),
        DeclareLaunchArgument("path_topic", default_value="trajectory"),
        Node(package="slam_toolbox", executable="async_slam_toolbox_node", name="slam_toolbox",
             parameters=[{"map_frame": "map", "odom_frame": "odom", "base_frame": "base_link",
                          "scan_topic": "/scan", "map_update_interval": 5.0}],
             remappings=[("/map", "/slam_toolbox/map"), ("/map_metadata", "/slam_toolbox/map_metadata")]),
        # vasco_gpu is a Python package, not an ament package: its console script runs the node.
        ExecuteProcess(
            cmd=["vasco_map_node", "--ros-args",
                 "-p", ["backend:=", backend], "-p", "cuda_mode:=float",
                 "-p", "scan_topics:=[scan]", "-p", ["path_topic:=", path_topic],
                 "-p", "map_frame:=map", "-p", "base_frame:=base_link",
                 "-p", "resolution:=0.05", "-p", "vasco_downsample:=1",
                 "-p", "save_map_path:=[maps/vasco.pgm, maps/vasco.map.gz]"],
            output="screen"),
    ])
