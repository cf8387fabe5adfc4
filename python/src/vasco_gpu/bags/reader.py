""":func:`read_bag`: the scans of a bag's laser scan topics with the laser pose at each stamp.

The scans of one topic are kept in bag order (the order ``rosbags`` yields them: by receive
time) and are not sorted by header stamp, as log2map keeps a log's order: the map depends on it
(the first scan sets the grid's frame, and CARMEN's updates round in the order they come). The
scans of several topics are merged in stamp order (a stable sort: equal stamps keep the order
of the topics as given).

Importing this module raises ImportError when rosbags is not installed.
"""

from __future__ import annotations

import os
from collections import Counter
from typing import Callable

import numpy as np

from ..msgs.cloud import cloud_mount
from ..msgs.errors import BagError
from ..msgs.header import stamp_seconds, stamp_text
from ..msgs.scan_options import SCAN_DEFAULTS, check_choice
from ..msgs.table import message_type
from ..msgs.tf import TfBuffer, TfLinkIgnored
from .options import STATIC_POSE, checked_pose, scan_settings
from .poses import PoseSeries, choose_fixed_frame, poses_for
from .scans import STAMP_MODES, BagScans, ScanAccumulator
from .storage import open_bag, read_messages
from .topics import check_pose_topic, choose_pose_source, pick_scan_topics, tf_topics

__all__ = ["read_bag"]

POSE_SOURCES = ("auto", "tf", "topic", "static", "none")


class Progress:
    """Calls progress(done, total) every 1% of the messages (at least every 1000) and at the end."""

    def __init__(self, callback: Callable[[int, int], object] | None, total: int):
        self.callback, self.total, self.done, self.reported = callback, total, 0, -1
        self.step = max(1, min(1000, -(-total // 100)))
        self.next = self.step

    def _report(self) -> None:
        self.callback(self.done, max(self.total, self.done))
        self.reported = self.done

    def tick(self) -> None:
        self.done += 1
        if self.callback is not None and self.done >= self.next:
            self._report()
            self.next = self.done + self.step

    def end(self) -> None:
        if self.callback is not None and self.reported != self.done:
            self._report()


class LeftOutLinks:
    """Feeds a bag's TFMessages to the tree, going on past the links it leaves out (a self
    transform, one that would close a cycle: TfLinkIgnored), as the node does: one warning per
    kind, the first such link's text and how many more. Every other TfError stops the reading."""

    def __init__(self, tf: TfBuffer):
        self.tf = tf
        self.first: dict[str, str] = {}
        self.count: Counter = Counter()

    def add(self, msg, static: bool, topic: str) -> None:
        for ts in msg.transforms:
            try:
                self.tf.add_transform(ts, static, topic)
            except TfLinkIgnored as e:
                self.first.setdefault(e.kind, e.message)
                self.count[e.kind] += 1

    def warnings(self) -> list[str]:
        return [text + (f" ({self.count[kind] - 1} more {kind}s left out)" if self.count[kind] > 1 else "")
                for kind, text in self.first.items()]


#: A /tf link's samples further apart than this leave the stamps between them without a
#: transform: tf2's buffer keeps 10 s of history (its default cache time).
TF_MAX_GAP = 10.0
OUTSIDE_SPAN = ("error", "edges", "skip")


def _check_arguments(pose_source, no_return, pose_topic, outside_span, echo, stamp):
    """ValueError for arguments that no bag could make valid."""
    check_choice("no_return", no_return)
    if pose_source not in POSE_SOURCES:
        raise ValueError(f"pose_source must be one of {POSE_SOURCES}, not {pose_source!r}")
    if pose_source == "topic" and pose_topic is None:
        raise ValueError("pose_source 'topic' needs pose_topic")
    if outside_span not in OUTSIDE_SPAN:
        raise ValueError(f"outside_span must be one of {OUTSIDE_SPAN}, not {outside_span!r}")
    check_choice("echo", echo)
    if stamp not in STAMP_MODES:
        raise ValueError(f"stamp must be one of {STAMP_MODES}, not {stamp!r}")


def read_bag(path, scan_topic=None, fixed_frame="map", base_frame=None, pose_topic=None,
             laser_mount=None, pose_source="auto", no_return=SCAN_DEFAULTS["no_return"], progress=None,
             outside_span="error", echo=SCAN_DEFAULTS["echo"], stamp="header", z_band=None, cloud_angle_step=None,
             cloud_range_max=None, static_pose=None, root_if_no_map=False, wording="python") -> BagScans:
    """The scans of the bag's laser scan topics at path, with the laser pose at each stamp.

    scan_topic: the sensor_msgs/LaserScan or MultiEchoLaserScan topic; None takes the only one;
    several (a list, or names separated by commas) are read together, each scan posed in its own
    frame (so each laser with its own mount), and merged in stamp order (one topic keeps bag
    order). fixed_frame: the frame of the poses (with tf, None means the root of the scan
    frame's tree; with a pose topic, None accepts the topic's frame). base_frame: the robot's
    frame (default Odometry's child_frame_id, else "base_link"). pose_topic: a
    nav_msgs/Odometry, geometry_msgs/PoseStamped or PoseWithCovarianceStamped topic of base
    poses, or a nav_msgs/Path topic (its last message: the final trajectory of a LIO or SLAM
    back end). static_pose: (x, y, yaw) of a robot that does not move, every scan at it (with
    the mount; text "X,Y,THETA" too; x and y within tf's bound, 1e12 m, as laser_mount's);
    pose_source "static" then, the bag needs no poses. laser_mount: (x, y, yaw) of the laser in the base frame, instead of /tf_static (one
    topic only). pose_source: "auto" (pose_topic if given, else tf), "tf", "topic" or "none"
    (NaN poses; the caller brings them). no_return: "skip" or "free" (see
    :mod:`vasco_gpu.msgs.laser`). progress: progress(done_messages, total_messages).
    outside_span: a scan stamp without a pose (outside the time span of the poses: of a /tf link
    on the chain, or of the pose topic; or in a gap of over TF_MAX_GAP seconds of a /tf link) is
    a BagError ("error", the default), or gets a NaN pose ("skip": the caller leaves those scans
    out), or gets a NaN pose when it lies before the first or after the last pose of the chain,
    counted in ``edges``, while a gap stays a BagError ("edges"). echo: the echo a
    MultiEchoLaserScan beam gives, "first", "last" (default) or "strongest". stamp: a scan's
    stamp is its "header" stamp (default) or the time the bag received it ("receive", for a
    driver whose clock is wrong); the poses are looked up at it. A sensor_msgs/PointCloud2 topic
    is read as a scan (:mod:`vasco_gpu.msgs.cloud`): z_band (min, max) in metres in the base
    frame, cloud_angle_step in degrees (default 0.25), cloud_range_max in metres (default 50); each
    may be given as text too (bag2map's options: "0.2,1.8").

    root_if_no_map: with fixed_frame "map" and tf poses, a bag whose tf has no 'map' frame is
    mapped in the root that every scan frame reaches through a /tf link (odom, for a recording
    without localisation), with a warning in the result's ``warnings``. wording: the errors and
    warnings name options as the Python API ("python", the default) or bag2map ("cli") does.

    Raises BagError for anything about the bag, ValueError for arguments that are wrong in
    themselves.
    """
    if static_pose is not None:
        static_pose = checked_pose(static_pose, STATIC_POSE)
        if pose_source == "none":
            raise ValueError("static_pose (--static-pose) and a pose file (--poses) both pose the scans: pass one")
        if pose_source not in ("auto", "static") or pose_topic is not None:
            raise ValueError("static_pose (--static-pose) poses every scan: it takes neither pose_topic nor tf")
        pose_source = "static"
    _check_arguments(pose_source, no_return, pose_topic, outside_span, echo, stamp)
    mount_arg = checked_pose(laser_mount, "laser_mount")
    with open_bag(path) as reader:
        topics = reader.topics
        names = pick_scan_topics(path, topics, scan_topic)
        if mount_arg is not None and len(names) > 1:
            raise ValueError("laser_mount (--laser-mount) gives one mount: with several scan topics each "
                             "laser's mount comes from /tf_static")
        for name in names:
            if topics[name].msgcount == 0:
                raise BagError(path, f"scan topic {name!r} has no messages", topic=name)
        source = choose_pose_source(path, topics, pose_source, pose_topic, wording)
        tf = None
        if tf_topics(topics):
            tf = TfBuffer(path, stamp_name="scan stamp", max_gap=TF_MAX_GAP, refuse_repeats=True,
                          outside_hint="skip_unposed / --skip-unposed leaves such scans out")
        settings = scan_settings(no_return, echo, z_band, cloud_angle_step, cloud_range_max)
        mount_of = cloud_mount_of(path, tf, base_frame)
        accs = [ScanAccumulator(path, name, message_type(topics[name].msgtype), settings, stamp, mount_of)
                for name in names]
        handlers = {acc.topic: acc.add for acc in accs}
        left_out = LeftOutLinks(tf)
        if tf is not None:
            for name in tf_topics(topics):
                static = name.rstrip("/").endswith("tf_static")
                if static or source == "tf":  # /tf only when it gives the poses
                    handlers[name] = (lambda m, t, s=static, n=name: left_out.add(m, s, n))
        series = None
        if source == "topic":
            name, msgtype = check_pose_topic(path, topics, pose_topic)
            series = PoseSeries(path, name, msgtype, fixed_frame, base_frame)
            handlers[name] = series.add
        total = sum(topics[name].msgcount for name in handlers)
        ticker = Progress(progress, total)
        read_messages(reader, path, handlers, ticker)
        ticker.end()
    notes = _checked_topics(path, accs, settings, base_frame, wording) + left_out.warnings()
    if source == "tf" and root_if_no_map and fixed_frame == "map":
        fixed_frame, chosen = choose_fixed_frame(path, tf, [acc.frame_id for acc in accs], wording)
        notes.insert(0, chosen)
    parts = []
    for acc in accs:
        ns = np.frombuffer(acc.ns, dtype=np.int64).copy()
        try:
            parts.append((acc, ns) + poses_for(path, source, acc, ns, tf, series, fixed_frame, base_frame,
                                               mount_arg, outside_span, static_pose))
        except BagError as e:
            if len(accs) > 1 and e.topic != acc.topic:  # say which laser's scans
                e.message += f" (scans of {acc.topic!r})"
                e.args = (e.args[0] + f" (scans of {acc.topic!r})",)
            raise
    merged = _merge(path, parts)
    merged.warnings = tuple(f"{path}: {n}" for n in notes if n)
    return merged


def _checked_topics(path, accs, settings, base_frame, wording) -> list:
    """What to warn of for each topic read (or None), after the checks of what it holds: a topic
    without messages, clouds with no point in the height band."""
    notes = []
    for acc in accs:
        if not acc.ns:
            raise BagError(path, f"scan topic {acc.topic!r} has no messages", topic=acc.topic)
        band = acc.band_error(settings.z_band, base_frame or "base_link", wording)
        if band is not None:
            raise band
        notes.append(acc.angles_warning())
    return notes


def cloud_mount_of(path, tf, base_frame):
    """mount_of(frame, ns): a cloud frame's transform in the base frame from what /tf_static has
    given by then (the height band is in the base frame)."""
    base = base_frame or "base_link"

    def mount_of(frame: str, ns: int):
        try:
            if tf is None and frame != base:
                raise BagError(path, "the bag has no /tf_static")
            return cloud_mount(tf, base, frame)
        except BagError as e:
            raise BagError(path, f"the point clouds' height band is in the base frame {base!r}: no static "
                                 f"chain {base} -> {frame!r} on /tf_static before the first cloud (stamp "
                                 f"{stamp_text(ns)}): {e.message}; pass --base-frame {frame} (base_frame="
                                 f"{frame!r}) to take heights in the cloud's own frame", stamp=stamp_seconds(ns)) from None

    return mount_of


def _merge(path, parts) -> BagScans:
    """One BagScans of the topics' scans: in bag order for one topic, else in stamp order."""
    ns = np.concatenate([p[1] for p in parts])
    order = np.argsort(ns, kind="stable") if len(parts) > 1 else np.arange(len(ns))
    index = np.concatenate([np.full(len(p[1]), k, dtype=np.int64) for k, p in enumerate(parts)])[order]
    counts = np.concatenate([np.frombuffer(p[0].beam_counts, dtype=np.int64) for p in parts])
    ranges = [r for p in parts for r in p[0].ranges]
    column = lambda field: np.concatenate([np.frombuffer(getattr(p[0], field), dtype=np.float64)
                                           for p in parts])[order]
    if all(p[3] is None for p in parts):
        mounts = None
    else:
        mounts = np.concatenate([p[3] if p[3] is not None else np.full((len(p[1]), 3), np.nan)
                                 for p in parts])[order]
    total = {}
    for p in parts:
        for key, value in p[0].counts.items():
            pick = {"z_min": min, "z_max": max}.get(key)  # the heights seen: their range, not a sum
            if key not in total:
                total[key] = value
            else:
                total[key] = pick(total[key], value) if pick else total[key] + value
    edges = None
    known = [p[5] for p in parts if p[5] is not None]
    if known:
        edges = {"before": sum(e["before"] for e in known), "after": sum(e["after"] for e in known),
                 "first": stamp_seconds(min(e["first"] for e in known)),
                 "last": stamp_seconds(max(e["last"] for e in known))}
    first = parts[0][0]
    return BagScans(
        path=os.fspath(path), topic=first.topic, frame_id=first.frame_id, stamps=stamp_seconds(ns[order]),
        poses=np.concatenate([p[2] for p in parts])[order], mounts=mounts,
        ranges=np.concatenate([ranges[k] for k in order]) if ranges else np.zeros(0, np.float32),
        beam_counts=counts[order], first_angle=column("first_angle"), angle_step=column("angle_step"),
        counts=total, pose_source=parts[0][4], range_max=column("range_max"),
        topics=tuple(p[0].topic for p in parts), topic_index=index,
        frame_ids=tuple(p[0].frame_id for p in parts), edges=edges,
    )
