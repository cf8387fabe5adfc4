"""Writes small synthetic ROS bags for the tests of vasco_gpu.bags, with rosbags' own writers.

Three formats: "rosbag1" (a ROS 1 ``.bag`` file), "sqlite3" and "mcap" (ROS 2 bag directories
with that storage plug-in). The messages are built from rosbags' typestores (ROS 1 Noetic for
rosbag1, ROS 2 Humble otherwise) so that the bags carry the type definitions a real recorder
writes; the reader under test then deserializes with the bag's own definitions.

Stamps are given as float64 seconds and split into sec / nanosec (see :func:`split_stamp`).
A float64 time does not survive the trip through whole nanoseconds exactly, so a test that
matches anything by time must use the stamps the reader returns, not the ones given here.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

FORMATS = ("rosbag1", "sqlite3", "mcap")

LASER_SCAN = "sensor_msgs/msg/LaserScan"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
ODOMETRY = "nav_msgs/msg/Odometry"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"


def split_stamp(t: float) -> tuple[int, int]:
    """(sec, nanosec) of a float64 time: sec = floor(t), nanosec rounded, with carry."""
    sec = math.floor(t)
    nanosec = round((t - sec) * 1e9)
    if nanosec >= 1_000_000_000:
        sec += 1
        nanosec -= 1_000_000_000
    return int(sec), int(nanosec)


def stamp_ns(t: float) -> int:
    """The bag's receive time (whole nanoseconds) for a float64 stamp."""
    sec, nanosec = split_stamp(t)
    return sec * 1_000_000_000 + nanosec


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation by yaw about z."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)


class _Messages:
    """Builds messages of one ROS version from its typestore."""

    def __init__(self, ros1: bool):
        self.ros1 = ros1
        self.store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
        if TF_MESSAGE not in self.store.types:  # the Noetic store lacks tf2_msgs
            self.store.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", TF_MESSAGE))
        self.T = self.store.types
        self.seq = 0

    def serialize(self, msg, msgtype: str) -> bytes:
        if self.ros1:
            return self.store.serialize_ros1(msg, msgtype)
        return self.store.serialize_cdr(msg, msgtype)

    def header(self, t: float, frame: str):
        sec, nanosec = split_stamp(t)
        stamp = self.T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
        self.seq += 1
        if self.ros1:
            return self.T["std_msgs/msg/Header"](seq=self.seq, stamp=stamp, frame_id=frame)
        return self.T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)

    def laser_scan(self, t, frame, ranges, angle_min, angle_increment, range_min, range_max):
        ranges = np.asarray(ranges, dtype=np.float32)
        n = len(ranges)
        return self.T[LASER_SCAN](
            header=self.header(t, frame),
            angle_min=float(angle_min),
            angle_max=float(np.float32(angle_min) + np.float32(angle_increment) * np.float32(max(n - 1, 0))),
            angle_increment=float(angle_increment),
            time_increment=0.0,
            scan_time=0.0,
            range_min=float(range_min),
            range_max=float(range_max),
            ranges=ranges,
            intensities=np.zeros(0, dtype=np.float32),
        )

    def pose(self, x, y, yaw):
        qx, qy, qz, qw = yaw_quaternion(yaw)
        return self.T["geometry_msgs/msg/Pose"](
            position=self.T["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=0.0),
            orientation=self.T["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
        )

    def transform(self, t, parent, child, x, y, yaw):
        qx, qy, qz, qw = yaw_quaternion(yaw)
        return self.T["geometry_msgs/msg/TransformStamped"](
            header=self.header(t, parent),
            child_frame_id=child,
            transform=self.T["geometry_msgs/msg/Transform"](
                translation=self.T["geometry_msgs/msg/Vector3"](x=float(x), y=float(y), z=0.0),
                rotation=self.T["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
            ),
        )

    def tf_message(self, transforms):
        return self.T[TF_MESSAGE](transforms=list(transforms))

    def odometry(self, t, frame, child, x, y, yaw):
        vec = self.T["geometry_msgs/msg/Vector3"]
        zero = vec(x=0.0, y=0.0, z=0.0)
        twist = self.T["geometry_msgs/msg/Twist"](linear=zero, angular=zero)
        return self.T[ODOMETRY](
            header=self.header(t, frame),
            child_frame_id=child,
            pose=self.T["geometry_msgs/msg/PoseWithCovariance"](
                pose=self.pose(x, y, yaw), covariance=np.zeros(36, dtype=np.float64)
            ),
            twist=self.T["geometry_msgs/msg/TwistWithCovariance"](
                twist=twist, covariance=np.zeros(36, dtype=np.float64)
            ),
        )

    def pose_stamped(self, t, frame, x, y, yaw):
        return self.T[POSE_STAMPED](header=self.header(t, frame), pose=self.pose(x, y, yaw))


class _Writer:
    """One of rosbags' writers behind one interface: add_connection(topic, type), write(...)."""

    def __init__(self, path: Path, fmt: str, messages: _Messages):
        if fmt not in FORMATS:
            raise ValueError(f"fmt must be one of {FORMATS}, not {fmt!r}")
        self.messages = messages
        if fmt == "rosbag1":
            from rosbags.rosbag1 import Writer

            self.writer = Writer(path)
        else:
            from rosbags.rosbag2 import StoragePlugin, Writer

            plugin = StoragePlugin.MCAP if fmt == "mcap" else StoragePlugin.SQLITE3
            self.writer = Writer(path, version=8, storage_plugin=plugin)
        self.connections = {}

    def __enter__(self):
        self.writer.open()
        return self

    def __exit__(self, *exc):
        self.writer.close()
        return False

    def connection(self, topic: str, msgtype: str):
        if topic not in self.connections:
            store = self.messages.store
            self.connections[topic] = self.writer.add_connection(topic, msgtype, typestore=store)
        return self.connections[topic]

    def write(self, topic: str, msgtype: str, t_ns: int, msg) -> None:
        self.writer.write(self.connection(topic, msgtype), t_ns, self.messages.serialize(msg, msgtype))


def write_bag(
    path,
    fmt,
    stamps,
    ranges_per_scan,
    angle_min,
    angle_increment,
    range_min,
    range_max,
    laser_frame="laser",
    scan_topic="/scan",
    tf_poses=None,
    static_mount=None,
    odom_poses=None,
    pose_stamped=None,
    extra_scan_topics=(),
    tf_stamps=None,
    odom_stamps=None,
    static_transforms=(),
):
    """Writes a bag at path (a .bag file for "rosbag1", a directory otherwise) and returns path.

    One LaserScan per stamp on scan_topic (and on each of extra_scan_topics), frame laser_frame
    (or laser_frame[k] for scan k when it is a list; the static mount then uses the first);
    with no stamps the scan topic's connection is still written, with zero messages; with
    scan_topic None there is no scan topic (a bag of tf only, or with nothing at all).
    tf_poses (n, 3): base poses published as map -> base_link on /tf at tf_stamps (default: the
    scan stamps). static_mount (x, y, yaw): base_link -> laser_frame on /tf_static, once.
    odom_poses (n, 3): nav_msgs/Odometry on /odom, frame map, child base_link, at odom_stamps
    (default: the scan stamps). pose_stamped (n, 3): geometry_msgs/PoseStamped on /pose, frame
    map, at the scan stamps. static_transforms: more (parent, child, x, y, yaw) links, sent
    in one more /tf_static message. Messages are written in time order, the receive time being the
    header stamp.
    """
    path = Path(path)
    messages = _Messages(ros1=fmt == "rosbag1")
    stamps = [float(t) for t in stamps]
    events = []  # (receive ns, order, topic, type, message)

    def add(t, topic, msgtype, msg):
        events.append((stamp_ns(t), len(events), topic, msgtype, msg))

    scan_topics = tuple(extra_scan_topics) if scan_topic is None else (scan_topic, *extra_scan_topics)
    frames = [laser_frame] * len(stamps) if isinstance(laser_frame, str) else list(laser_frame)
    laser_frame = frames[0] if frames else "laser"
    for t, ranges, frame in zip(stamps, ranges_per_scan, frames):
        for topic in scan_topics:
            scan = messages.laser_scan(t, frame, ranges, angle_min, angle_increment, range_min,
                                       range_max)
            add(t, topic, LASER_SCAN, scan)
    if static_mount is not None:
        t0 = stamps[0] if stamps else 0.0
        mount = messages.transform(t0, "base_link", laser_frame, *static_mount)
        add(t0, "/tf_static", TF_MESSAGE, messages.tf_message([mount]))
    if static_transforms:
        t0 = stamps[0] if stamps else 0.0
        links = [messages.transform(t0, *link) for link in static_transforms]
        add(t0, "/tf_static", TF_MESSAGE, messages.tf_message(links))
    if tf_poses is not None:
        for t, p in zip(stamps if tf_stamps is None else tf_stamps, tf_poses):
            link = messages.transform(float(t), "map", "base_link", *p)
            add(float(t), "/tf", TF_MESSAGE, messages.tf_message([link]))
    if odom_poses is not None:
        for t, p in zip(stamps if odom_stamps is None else odom_stamps, odom_poses):
            add(float(t), "/odom", ODOMETRY, messages.odometry(float(t), "map", "base_link", *p))
    if pose_stamped is not None:
        for t, p in zip(stamps, pose_stamped):
            add(t, "/pose", POSE_STAMPED, messages.pose_stamped(t, "map", *p))
    events.sort(key=lambda e: (e[0], e[1]))

    with _Writer(path, fmt, messages) as w:
        for topic in scan_topics:
            w.connection(topic, LASER_SCAN)
        for t_ns, _, topic, msgtype, msg in events:
            w.write(topic, msgtype, t_ns, msg)
    return path


def bag_path(tmp_path, fmt, name="test"):
    """Where write_bag should put a bag of this format: a .bag file or a directory."""
    return Path(tmp_path) / (f"{name}.bag" if fmt == "rosbag1" else name)


MULTI_ECHO = "sensor_msgs/msg/MultiEchoLaserScan"


class Recording:
    """A bag shaped like a real recording, message by message: scans on several topics (LaserScan
    or MultiEchoLaserScan), tf links on /tf and /tf_static, each with its header stamp and the
    time the bag received it (by default the stamp: a late or early receive time is how a
    recorder sees a laser driver whose clock is wrong, or a message that arrives late).

    ``write(path)`` writes them in receive order with the format's writer.
    """

    def __init__(self, fmt: str):
        self.fmt = fmt
        self.messages = _Messages(ros1=fmt == "rosbag1")
        self.events = []  # (receive ns, order, topic, type, message)
        self.topics = {}  # topic -> type, in first-use order (connections are written for all)

    def add(self, receive: float, topic: str, msgtype: str, msg) -> None:
        """Any message, received at `receive` (float seconds)."""
        self.topics.setdefault(topic, msgtype)
        self.events.append((stamp_ns(receive), len(self.events), topic, msgtype, msg))

    def scan(self, topic, t, frame, ranges, angle_min, angle_increment, range_min, range_max, receive=None):
        msg = self.messages.laser_scan(t, frame, ranges, angle_min, angle_increment, range_min, range_max)
        self.add(t if receive is None else receive, topic, LASER_SCAN, msg)

    def multi_echo(self, topic, t, frame, echoes, intensities, angle_min, angle_increment, range_min, range_max,
                   receive=None):
        """echoes, intensities: one float sequence a beam (intensities may be [] for none)."""
        T = self.messages.T
        echo = lambda values: T["sensor_msgs/msg/LaserEcho"](echoes=np.asarray(values, dtype=np.float32))
        n = len(echoes)
        msg = T[MULTI_ECHO](
            header=self.messages.header(t, frame),
            angle_min=float(angle_min),
            angle_max=float(np.float32(angle_min) + np.float32(angle_increment) * np.float32(max(n - 1, 0))),
            angle_increment=float(angle_increment), time_increment=0.0, scan_time=0.0,
            range_min=float(range_min), range_max=float(range_max),
            ranges=[echo(e) for e in echoes], intensities=[echo(i) for i in intensities],
        )
        self.add(t if receive is None else receive, topic, MULTI_ECHO, msg)

    def tf(self, t, parent, child, x, y, yaw, static=False, receive=None):
        link = self.messages.transform(float(t), parent, child, x, y, yaw)
        topic = "/tf_static" if static else "/tf"
        self.add(t if receive is None else receive, topic, TF_MESSAGE, self.messages.tf_message([link]))

    def write(self, path):
        self.events.sort(key=lambda e: (e[0], e[1]))
        with _Writer(Path(path), self.fmt, self.messages) as w:
            for topic, msgtype in self.topics.items():
                w.connection(topic, msgtype)
            for t_ns, _, topic, msgtype, msg in self.events:
                w.write(topic, msgtype, t_ns, msg)
        return Path(path)


def write_foreign_type(path, fmt, topic: str, msgtype: str, definition: str, messages, stamps):
    """A bag whose topic carries msgtype as `definition` (.msg text) defines it, not as ROS does:
    a custom message recorded under a standard name, with the bag's own definition (as a
    recorder stores it). messages: one dict of field values per stamp (float seconds, the time
    the bag received it); a field of a message type is a dict of its own."""
    from rosbags.typesys import Stores

    maker = _Messages(ros1=fmt == "rosbag1")
    maker.store = get_typestore(Stores.EMPTY)  # the writer stores this store's definition
    maker.store.register(get_types_from_msg(definition, msgtype))
    with _Writer(Path(path), fmt, maker) as w:
        for t, fields in zip(stamps, messages):
            w.write(topic, msgtype, stamp_ns(t), _build(maker.store, msgtype, fields))
    return Path(path)


def _build(store, msgtype: str, fields: dict):
    """A message of the store's msgtype from field values, nested messages given as dicts."""
    types = dict(store.fielddefs[msgtype][1])
    values = {k: _build(store, types[k][1], v) if isinstance(v, dict) else v for k, v in fields.items()}
    return store.types[msgtype](**values)


POINT_CLOUD2 = "sensor_msgs/msg/PointCloud2"


def scan_with_angle_max(rec: Recording, topic, t, frame, ranges, angle_min, angle_max, angle_increment,
                        range_min=0.1, range_max=30.0):
    """A LaserScan whose angle_max is given, not derived from the count: as a driver publishes
    one that disagrees with its ranges (velodyne_laserscan's nominal increment)."""
    msg = rec.messages.laser_scan(t, frame, ranges, angle_min, angle_increment, range_min, range_max)
    msg.angle_max = float(angle_max)
    rec.add(t, topic, LASER_SCAN, msg)


def point_cloud(rec: Recording, topic, t, frame, points):
    """A PointCloud2 of (n, 3) points: fields x, y, z as float32, one row, little-endian."""
    T = rec.messages.T
    pts = np.ascontiguousarray(points, dtype="<f4")
    fields = [T["sensor_msgs/msg/PointField"](name=n, offset=4 * k, datatype=7, count=1)
              for k, n in enumerate("xyz")]
    msg = T[POINT_CLOUD2](header=rec.messages.header(t, frame), height=1, width=len(pts), fields=fields,
                          is_bigendian=False, point_step=12, row_step=12 * len(pts),
                          data=np.frombuffer(pts.tobytes(), dtype=np.uint8), is_dense=True)
    rec.add(t, topic, POINT_CLOUD2, msg)
