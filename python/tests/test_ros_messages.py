"""The message packages the repository generates (ros/): tf2_msgs/TFMessage and
map_msgs/OccupancyGridUpdate import through the node's loaders, survive a CDR round trip, and
carry upstream's type hashes (REP 2011's RIHS01, which ROS 2 compares across nodes). The
expected hashes and the reading of rclpy's bytes come from rosbags, an independent
implementation, given upstream's definitions; the same test in a Jazzy and a Kilted
environment thus checks that both builds give the same hash."""

from __future__ import annotations

import os
import sys

import pytest

import ros_support  # noqa: F401  (the ROS environment)

ros_support.import_or_skip("rclpy")

import rclpy  # noqa: E402
from geometry_msgs.msg import TransformStamped  # noqa: E402
from rclpy.serialization import deserialize_message, serialize_message  # noqa: E402

from vasco_gpu.ros.tf_messages import map_update_type, tf_message_type  # noqa: E402

rosbags_typesys = pytest.importorskip("rosbags.typesys")

# map_msgs/msg/OccupancyGridUpdate.msg of ros-planning/navigation_msgs (ros2 branch), comments aside.
UPSTREAM_MAP_UPDATE = """\
std_msgs/Header header
int32 x
int32 y
uint32 width
uint32 height
int8[] data
"""
TF_NAME, MAP_UPDATE_NAME = "tf2_msgs/msg/TFMessage", "map_msgs/msg/OccupancyGridUpdate"


@pytest.fixture(scope="module")
def typestore():
    """rosbags' Kilted types (tf2_msgs included; std_msgs/Header and geometry_msgs are the
    same in Jazzy) plus upstream's OccupancyGridUpdate."""
    store = rosbags_typesys.get_typestore(rosbags_typesys.Stores.ROS2_KILTED)
    store.register(rosbags_typesys.get_types_from_msg(UPSTREAM_MAP_UPDATE, MAP_UPDATE_NAME))
    return store


@pytest.fixture(scope="module")
def node():
    rclpy.init()
    n = rclpy.create_node("vasco_messages_test")
    yield n
    n.destroy_node()
    rclpy.shutdown()


def sample_tf():
    msg = tf_message_type()()
    for k, (parent, child) in enumerate([("odom", "base_link"), ("base_link", "laser")]):
        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = parent, child
        t.header.stamp.sec, t.header.stamp.nanosec = 1700000000 + k, 123456789
        t.transform.translation.x, t.transform.translation.y = 1.5 * k, -2.25
        t.transform.rotation.z, t.transform.rotation.w = 0.6, 0.8
        msg.transforms.append(t)
    return msg


def sample_update():
    msg = map_update_type()()
    msg.header.frame_id, msg.header.stamp.sec, msg.header.stamp.nanosec = "map", 42, 7
    msg.x, msg.y, msg.width, msg.height = -3, 5, 3, 2
    msg.data = [-1, 0, 100, 50, -1, 127]
    return msg


def tf_fields(transforms):
    return [(t.header.frame_id, t.child_frame_id, t.header.stamp.sec, t.header.stamp.nanosec,
             t.transform.translation.x, t.transform.translation.y, t.transform.rotation.z,
             t.transform.rotation.w) for t in transforms]


def update_fields(m):
    return (m.header.frame_id, m.header.stamp.sec, m.header.stamp.nanosec, m.x, m.y, m.width, m.height,
            [int(v) for v in m.data])


def test_round_trip_through_rclpy():
    tf, update = sample_tf(), sample_update()
    back_tf = deserialize_message(serialize_message(tf), tf_message_type())
    back_update = deserialize_message(serialize_message(update), map_update_type())
    assert tf_fields(back_tf.transforms) == tf_fields(tf.transforms)
    assert update_fields(back_update) == update_fields(update)


def test_bytes_read_by_rosbags(typestore):
    """rclpy's CDR bytes, read by another CDR implementation, give the values written."""
    tf, update = sample_tf(), sample_update()
    their_tf = typestore.deserialize_cdr(serialize_message(tf), TF_NAME)
    their_update = typestore.deserialize_cdr(serialize_message(update), MAP_UPDATE_NAME)
    assert tf_fields(their_tf.transforms) == tf_fields(tf.transforms)
    assert update_fields(their_update) == update_fields(update)


@pytest.mark.parametrize("name", [TF_NAME, MAP_UPDATE_NAME])
def test_type_hash_is_upstreams(node, typestore, name):
    """The hash the middleware announces for a publisher of the generated type (from the
    type support library) and the one in the package's share/ type description both equal
    the hash of upstream's definition."""
    expected = typestore.hash_rihs01(name)
    assert expected.startswith("RIHS01_") and len(expected) == 7 + 64
    cls = tf_message_type() if name == TF_NAME else map_update_type()
    topic = f"vasco_messages_test_{cls.__name__.lower()}"
    publisher = node.create_publisher(cls, topic, 1)
    try:
        (info,) = node.get_publishers_info_by_topic(topic)
        assert str(info.topic_type_hash) == expected
    finally:
        node.destroy_publisher(publisher)
    with open(type_description_file(name)) as f:
        assert f'"hash_string": "{expected}"' in f.read()


def type_description_file(name):
    """share/PACKAGE/msg/TYPE.json in a sourced ROS 2 (AMENT_PREFIX_PATH) or in this environment's
    prefix, where the PyPI wheels put share/ (they set no AMENT_PREFIX_PATH)."""
    package, _, base = name.split("/")
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p] + [sys.prefix]
    paths = [os.path.join(p, "share", package, "msg", f"{base}.json") for p in prefixes]
    found = next((p for p in paths if os.path.isfile(p)), None)
    assert found, f"no type description of {name} in {prefixes}"
    return found


def test_the_published_messages_keep_the_canvas_array_where_rclpy_can():
    """/map's and map_updates' messages hold the canvas's array itself (no map-sized copy a
    /map); a distribution whose messages take no check_fields (Humble) gets plain ones."""
    from array import array

    from nav_msgs.msg import OccupancyGrid

    from vasco_gpu.ros.grid import array_keeping_message

    for cls in (OccupancyGrid, map_update_type()):
        msg, data = array_keeping_message(cls), array("b", b"\x01\xff") * 8
        msg.data = data
        assert msg.data is data, cls
        plain = cls(check_fields=False)
        plain.data = data
        assert plain.data is not data and plain.data == data  # what a plain message does: a copy

    class Humble:
        def __init__(self, **kwargs):
            assert not kwargs, "Invalid arguments passed to constructor"

    assert isinstance(array_keeping_message(Humble), Humble)
