"""The node's Fast DDS profile for maps in one piece (vasco_gpu.ros.transport): when it is taken,
and that Fast DDS can take it. No ROS needed, except for the last test, which publishes large
latched messages under it; the node tests run with it (their ready line)."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from vasco_gpu.ros.transport import MAP_SIZED_SHM_PROFILE, map_sized_shm_in_use, use_map_sized_shm


@pytest.mark.parametrize("env,taken", [
    ({"FASTDDS_BUILTIN_TRANSPORTS": "SHM"}, True),
    ({"FASTDDS_BUILTIN_TRANSPORTS": "shm", "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp"}, True),
    ({}, False),  # Fast DDS's default, UDP and shared memory: the robot's nodes may be on several hosts
    ({"FASTDDS_BUILTIN_TRANSPORTS": "UDPv4"}, False),
    ({"FASTDDS_BUILTIN_TRANSPORTS": "LARGE_DATA"}, False),
    ({"FASTDDS_BUILTIN_TRANSPORTS": "SHM", "FASTDDS_DEFAULT_PROFILES_FILE": "/robot/dds.xml"}, False),
    ({"FASTDDS_BUILTIN_TRANSPORTS": "SHM", "FASTRTPS_DEFAULT_PROFILES_FILE": "/robot/dds.xml"}, False),
    ({"FASTDDS_BUILTIN_TRANSPORTS": "SHM", "RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}, False),
    ({"FASTDDS_BUILTIN_TRANSPORTS": "SHM", "RMW_FASTRTPS_USE_QOS_FROM_XML": "0"}, True),  # the user's 0 kept
])
def test_the_profile_is_taken_only_on_shared_memory_alone_without_a_profile(env, taken):
    before = dict(env)
    assert use_map_sized_shm(env) is taken
    assert map_sized_shm_in_use(env) is taken
    if taken:  # Fast DDS 3 reads the first variable, Fast DDS 2 (Jazzy) the second
        assert env == {"RMW_FASTRTPS_USE_QOS_FROM_XML": "1", **before,
                       "FASTDDS_DEFAULT_PROFILES_FILE": str(MAP_SIZED_SHM_PROFILE),
                       "FASTRTPS_DEFAULT_PROFILES_FILE": str(MAP_SIZED_SHM_PROFILE)}
    else:
        assert env == before  # the user's configuration untouched


def test_the_profile_is_shared_memory_alone_with_room_for_its_messages():
    ns = {"d": "http://www.eprosima.com"}
    root = ET.parse(MAP_SIZED_SHM_PROFILE).getroot()
    descriptors = root.findall("d:profiles/d:transport_descriptors/d:transport_descriptor", ns)
    assert [d.find("d:type", ns).text for d in descriptors] == ["SHM"]  # no UDP, no TCP
    segment = int(descriptors[0].find("d:segment_size", ns).text)
    largest = int(descriptors[0].find("d:maxMessageSize", ns).text)
    assert 65_500 < largest <= segment  # Fast DDS refuses a message size above the segment
    participant = root.find("d:profiles/d:participant", ns)
    assert participant.get("is_default_profile") == "true"
    assert participant.find("d:rtps/d:useBuiltinTransports", ns).text == "false"
    used = [t.text for t in participant.findall("d:rtps/d:userTransports/d:transport_id", ns)]
    assert used == [descriptors[0].find("d:transport_id", ns).text]


def test_the_profiles_endpoints_free_what_the_history_lets_go_and_keep_rmws_other_settings():
    ns = {"d": "http://www.eprosima.com"}
    profiles = ET.parse(MAP_SIZED_SHM_PROFILE).getroot().find("d:profiles", ns)
    writer, reader = profiles.find("d:data_writer", ns), profiles.find("d:data_reader", ns)
    assert writer.get("is_default_profile") == reader.get("is_default_profile") == "true"
    assert writer.find("d:historyMemoryPolicy", ns).text == "DYNAMIC"
    # with RMW_FASTRTPS_USE_QOS_FROM_XML=1 rmw takes both from here, Fast DDS's defaults where
    # they are missing (PREALLOCATED, SYNCHRONOUS): rmw's own choices written out
    assert writer.find("d:qos/d:publishMode/d:kind", ns).text == "ASYNCHRONOUS"
    assert reader.find("d:historyMemoryPolicy", ns).text == "PREALLOCATED_WITH_REALLOC"


# A latched writer (the node's /map QoS) publishes a message of 64 MiB three times; prints the
# resident MiB before the first and after each (the message's own array counted in all).
LATCHED_TWICE = """
import sys, time
from array import array
from vasco_gpu.ros.transport import use_map_sized_shm, map_sized_shm_in_use
if sys.argv[1] == "profile":
    assert use_map_sized_shm() and map_sized_shm_in_use()
import rclpy
from nav_msgs.msg import OccupancyGrid
from vasco_gpu.ros.publication import LATCHED
def rss():
    return next(int(l.split()[1]) for l in open("/proc/self/status") if l.startswith("VmRSS")) >> 10
rclpy.init()
node = rclpy.create_node("latched_twice")
pub = node.create_publisher(OccupancyGrid, "map", LATCHED)
msg = OccupancyGrid(check_fields=True)
msg.info.width, msg.info.height = 64 << 20, 1
msg.data = array("b", b"\x01") * (64 << 20)
seen = [rss()]
for _ in range(3):
    pub.publish(msg)
    time.sleep(0.3)
    seen.append(rss())
print(*seen)
node.destroy_node()
rclpy.shutdown()
"""


def _latched_growth(mode: str) -> list[int]:
    from ros_support import ROS_ENV, import_or_skip

    import_or_skip("rclpy")
    env = {k: v for k, v in os.environ.items() if k not in ("FASTDDS_DEFAULT_PROFILES_FILE",
                                                             "FASTRTPS_DEFAULT_PROFILES_FILE",
                                                             "RMW_FASTRTPS_USE_QOS_FROM_XML")}
    out = subprocess.run([sys.executable, "-c", LATCHED_TWICE, mode], capture_output=True, text=True, timeout=120,
                         env={**env, **ROS_ENV})
    assert out.returncode == 0, out.stderr
    seen = [int(v) for v in out.stdout.split()]
    return [v - seen[0] for v in seen[1:]]


def test_a_latched_writer_under_the_profile_holds_one_serialised_map():
    # rmw's own setting keeps the replaced map's buffer too: two 64 MiB copies after the second
    # publication (the route by which the bytes were found at a large site, and the reason the
    # test can fail); under the profile one copy, whichever Fast DDS reads it
    plain, profiled = _latched_growth("plain"), _latched_growth("profile")
    assert plain[2] >= 2 * 64 - 8, plain
    assert 64 - 8 <= profiled[0] and profiled[2] <= 64 + 16, profiled
