"""The node's Fast DDS profile for maps in one piece (vasco_gpu.ros.transport): when it is taken,
and that Fast DDS can take it. No ROS needed; the node tests run with it (their ready line)."""

from __future__ import annotations

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
])
def test_the_profile_is_taken_only_on_shared_memory_alone_without_a_profile(env, taken):
    before = dict(env)
    assert use_map_sized_shm(env) is taken
    assert map_sized_shm_in_use(env) is taken
    if taken:
        assert env == {**before, "FASTDDS_DEFAULT_PROFILES_FILE": str(MAP_SIZED_SHM_PROFILE)}
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
