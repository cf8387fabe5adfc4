"""The bag's topics: message type names, the LaserScan topic to read, the tf topics, the pose
source (tf or a pose topic) and the pose topic's type."""

from __future__ import annotations

from .errors import BagError

LASER_SCAN = "sensor_msgs/msg/LaserScan"
TF_TYPES = ("tf2_msgs/msg/TFMessage", "tf/msg/tfMessage")  # ROS 2 / ROS 1 tf2, old ROS 1 tf
TF_TOPICS = ("/tf", "/tf_static")
POSE_TYPES = (
    "nav_msgs/msg/Odometry",
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
)


def norm_type(msgtype: str | None) -> str | None:
    """ROS 2 spelling of a message type: sensor_msgs/LaserScan -> sensor_msgs/msg/LaserScan."""
    if msgtype and msgtype.count("/") == 1:
        pkg, name = msgtype.split("/")
        return f"{pkg}/msg/{name}"
    return msgtype


def short_type(msgtype: str | None) -> str:
    """ROS 1 spelling for messages: sensor_msgs/msg/LaserScan -> sensor_msgs/LaserScan."""
    return (msgtype or "mixed types").replace("/msg/", "/")


def resolve_topic(name: str, topics) -> str | None:
    """The topic of the bag that name means, with or without the leading '/'; None if absent."""
    for candidate in (name, "/" + name.lstrip("/"), name.lstrip("/")):
        if candidate in topics:
            return candidate
    return None


def topic_listing(topics) -> str:
    """'/a' (pkg/Type), '/b' (pkg/Type) ... or 'none' for an empty bag."""
    if not topics:
        return "none: the bag has no topics"
    return ", ".join(f"{name!r} ({short_type(info.msgtype)})" for name, info in sorted(topics.items()))


def topics_of_type(topics, msgtypes) -> list[str]:
    """The topics whose (normalised) message type is one of msgtypes, sorted."""
    return sorted(name for name, info in topics.items() if norm_type(info.msgtype) in msgtypes)


def pick_scan_topic(path, topics, scan_topic: str | None) -> str:
    """The LaserScan topic to read: the named one (which must be a LaserScan) or the only one."""
    scans = topics_of_type(topics, (LASER_SCAN,))
    listing = ", ".join(repr(t) for t in scans) or "none"
    if scan_topic is not None:
        name = resolve_topic(scan_topic, topics)
        if name is None:
            raise BagError(path, f"no topic {scan_topic!r} in the bag (LaserScan topics: {listing})",
                           topic=scan_topic)
        if name not in scans:
            kind = short_type(topics[name].msgtype)
            raise BagError(path, f"topic {name!r} is {kind}, not sensor_msgs/LaserScan "
                                 f"(LaserScan topics: {listing})", topic=name)
        return name
    if not scans:
        raise BagError(path, f"no sensor_msgs/LaserScan topic (topics: {topic_listing(topics)})")
    if len(scans) > 1:
        raise BagError(path, f"several sensor_msgs/LaserScan topics ({listing}); pass scan_topic "
                             "(--scan-topic) to choose one")
    return scans[0]


def tf_topics(topics) -> list[str]:
    """The bag's /tf and /tf_static topics that carry tf messages (and have any)."""
    found = []
    for name in TF_TOPICS:
        actual = resolve_topic(name, topics)
        info = topics.get(actual)
        if info is not None and norm_type(info.msgtype) in TF_TYPES and info.msgcount > 0:
            found.append(actual)
    return found


def choose_pose_source(path, topics, pose_source: str, pose_topic: str | None) -> str:
    """"tf", "topic" or "none" from the pose_source argument and what the bag has."""
    if pose_source == "auto":
        if pose_topic is not None:
            return "topic"
        if tf_topics(topics):
            return "tf"
        raise BagError(path, "no /tf and no pose topic to take the laser poses from (pass pose_topic "
                             "(--pose-topic) or a pose file (--poses FILE))")
    if pose_source == "tf" and not tf_topics(topics):
        raise BagError(path, f"pose_source 'tf' but the bag has no /tf or /tf_static messages (topics: "
                             f"{topic_listing(topics)})")
    return pose_source


def check_pose_topic(path, topics, pose_topic: str) -> tuple[str, str]:
    """(topic, normalised type) of the pose topic, which must exist and have a supported type."""
    name = resolve_topic(pose_topic, topics)
    if name is None:
        raise BagError(path, f"no pose topic {pose_topic!r} in the bag (topics: {topic_listing(topics)})",
                       topic=pose_topic)
    msgtype = norm_type(topics[name].msgtype)
    if msgtype not in POSE_TYPES:
        kinds = ", ".join(short_type(t) for t in POSE_TYPES)
        raise BagError(path, f"pose topic {name!r} is {short_type(msgtype)}; supported: {kinds}", topic=name)
    return name, msgtype
