"""The bag's topics: the scan topics to read (the message table's scan types: LaserScan,
MultiEchoLaserScan, PointCloud2; a clear word on sensors that are none of them), the tf topics,
the pose source (tf or a pose topic) and the pose topic's type."""

from __future__ import annotations

from ..msgs.errors import BagError
from ..msgs.header import did_you_mean
from ..msgs.table import POSE_TYPES, SCAN_TYPES, TF_TYPES, UNSUPPORTED_SENSORS, norm_type, short_type
from .errors import words

TF_TOPICS = ("/tf", "/tf_static")


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


def scan_topic_names(scan_topic) -> list[str] | None:
    """The scan topics asked for: None (the only one), a name, names separated by commas (as
    bag2map's --scan-topic hands them on), or a sequence of names; each once, in order."""
    if scan_topic is None:
        return None
    items = [scan_topic] if isinstance(scan_topic, str) else list(scan_topic)
    names: list[str] = []
    for item in items:
        for name in str(item).split(","):
            name = name.strip()
            if name and name not in names:
                names.append(name)
    if not names:
        raise ValueError(f"scan_topic names no topic: {scan_topic!r}")
    return names


def _unsupported_text(name: str, msgtype: str | None) -> str:
    """'/points' (sensor_msgs/PointCloud2): a 3-D point cloud; ... (what to do)."""
    why = UNSUPPORTED_SENSORS.get(norm_type(msgtype) or "", "")
    return f"{name!r} ({short_type(msgtype)}){': ' + why if why else ''}"


def _no_scan_text(topics) -> str:
    """Why a bag has nothing to map: its topics, and its sensors that are not laser scans."""
    text = f"no sensor_msgs/LaserScan, MultiEchoLaserScan or PointCloud2 topic (topics: {topic_listing(topics)})"
    sensors = [name for name, info in sorted(topics.items()) if norm_type(info.msgtype) in UNSUPPORTED_SENSORS]
    if sensors:
        listed = "; ".join(_unsupported_text(name, topics[name].msgtype) for name in sensors)
        text += f"; its sensor topics are neither laser scans nor point clouds, which are all that is mapped: {listed}"
    return text


def pick_scan_topics(path, topics, scan_topic) -> list[str]:
    """The scan topics to read: the named ones (each a LaserScan, MultiEchoLaserScan or
    PointCloud2), or the only one. scan_topic as :func:`scan_topic_names` takes it."""
    scans = topics_of_type(topics, SCAN_TYPES)
    listing = ", ".join(repr(t) for t in scans) or "none"
    names = scan_topic_names(scan_topic)
    if names is None:
        if not scans:
            raise BagError(path, _no_scan_text(topics))
        if len(scans) > 1:
            raise BagError(path, f"several laser scan topics ({listing}); pass scan_topic (--scan-topic) to "
                                 "choose one, or several to map them together")
        return scans
    chosen = []
    for wanted in names:
        name = resolve_topic(wanted, topics)
        if name is None:
            raise BagError(path, f"no topic {wanted!r} in the bag{did_you_mean(wanted, topics)} (scan topics: "
                                 f"{listing})", topic=wanted)
        if name not in scans:
            kind = short_type(topics[name].msgtype)
            hint = UNSUPPORTED_SENSORS.get(norm_type(topics[name].msgtype) or "")
            raise BagError(path, f"topic {name!r} is {kind}, not sensor_msgs/LaserScan, MultiEchoLaserScan or "
                                 "PointCloud2"
                                 f"{' (' + hint + ')' if hint else ''} (scan topics: {listing})", topic=name)
        if name not in chosen:
            chosen.append(name)
    return chosen


def tf_topics(topics) -> list[str]:
    """The bag's /tf and /tf_static topics that carry tf messages (and have any)."""
    found = []
    for name in TF_TOPICS:
        actual = resolve_topic(name, topics)
        info = topics.get(actual)
        if info is not None and norm_type(info.msgtype) in TF_TYPES and info.msgcount > 0:
            found.append(actual)
    return found


def choose_pose_source(path, topics, pose_source: str, pose_topic: str | None, wording: str = "python") -> str:
    """"tf", "topic" or "none" from the pose_source argument and what the bag has."""
    if pose_source == "auto":
        if pose_topic is not None:
            return "topic"
        if tf_topics(topics):
            return "tf"
        candidates = topics_of_type(topics, POSE_TYPES)
        raise BagError(path, no_poses_text("the bag has no /tf and no pose topic", wording, candidates))
    if pose_source == "tf" and not tf_topics(topics):
        raise BagError(path, f"pose_source 'tf' but the bag has no /tf or /tf_static messages (topics: "
                             f"{topic_listing(topics)})")
    return pose_source


def no_poses_text(why: str, wording: str, pose_topics=()) -> str:
    """Why a bag gives the scans no poses, and where a moving sensor's poses come from, in the
    words of the command line or of the Python API (wording: errors.WORDINGS)."""
    say = lambda cli, python: words(wording, cli, python)
    text = f"no poses for the scans: {why}."
    if pose_topics:
        listed = ", ".join(repr(t) for t in pose_topics)
        text += f" Its pose topics ({listed}) give them with {say('--pose-topic TOPIC', 'pose_topic=TOPIC')}."
    return text + (
        " A moving sensor's poses must come from SLAM or odometry: run a SLAM system over the bag offline "
        "(slam_toolbox or Cartographer, playing the bag) and give its trajectory with "
        f"{say('--poses FILE', 'poses=FILE')} (TUM, g2o or a CARMEN log), or record the robot's odometry (an "
        f"Odometry topic, {say('--pose-topic TOPIC', 'pose_topic=TOPIC')}) or its /tf with the scans. A sensor "
        f"that does not move: {say('--static-pose X,Y,THETA', 'static_pose=(X, Y, THETA)')}")


def check_pose_topic(path, topics, pose_topic: str) -> tuple[str, str]:
    """(topic, normalised type) of the pose topic, which must exist and have a supported type."""
    name = resolve_topic(pose_topic, topics)
    if name is None:
        raise BagError(path, f"no pose topic {pose_topic!r} in the bag{did_you_mean(pose_topic, topics)} (topics: "
                             f"{topic_listing(topics)})",
                       topic=pose_topic)
    msgtype = norm_type(topics[name].msgtype)
    if msgtype not in POSE_TYPES:
        kinds = ", ".join(short_type(t) for t in POSE_TYPES)
        raise BagError(path, f"pose topic {name!r} is {short_type(msgtype)}; supported: {kinds}", topic=name)
    return name, msgtype
