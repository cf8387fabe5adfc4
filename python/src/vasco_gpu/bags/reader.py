""":func:`read_bag`: the scans of one LaserScan topic of a bag with the laser pose at each stamp.

Scans are kept in bag order (the order ``rosbags`` yields them: by receive time) and are not
sorted by header stamp, as log2map keeps a log's order: the map depends on it (the first scan
sets the grid's frame, and CARMEN's updates round in the order they come).

Importing this module raises ImportError when rosbags is not installed.
"""

from __future__ import annotations

import os
from typing import Callable

import numpy as np

from .errors import BagError
from .geometry import check_mount
from .header import stamp_seconds
from .poses import PoseSeries, poses_for
from .scans import NO_RETURN_MODES, BagScans, ScanAccumulator
from .storage import open_bag, read_messages
from .tf import TfBuffer
from .topics import check_pose_topic, choose_pose_source, pick_scan_topic, tf_topics

__all__ = ["read_bag"]

POSE_SOURCES = ("auto", "tf", "topic", "none")


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


def _check_arguments(pose_source, no_return, pose_topic, outside_span="error"):
    """ValueError for arguments that no bag could make valid."""
    if no_return not in NO_RETURN_MODES:
        raise ValueError(f"no_return must be one of {NO_RETURN_MODES}, not {no_return!r}")
    if pose_source not in POSE_SOURCES:
        raise ValueError(f"pose_source must be one of {POSE_SOURCES}, not {pose_source!r}")
    if pose_source == "topic" and pose_topic is None:
        raise ValueError("pose_source 'topic' needs pose_topic")
    if outside_span not in ("error", "skip"):
        raise ValueError(f"outside_span must be 'error' or 'skip', not {outside_span!r}")


def read_bag(path, scan_topic=None, fixed_frame="map", base_frame=None, pose_topic=None,
             laser_mount=None, pose_source="auto", no_return="skip", progress=None,
             outside_span="error") -> BagScans:
    """The scans of one LaserScan topic of the bag at path, with the laser pose at each stamp.

    scan_topic: the LaserScan topic; None takes the only one. fixed_frame: the frame of the
    poses (with tf, None means the root of the scan frame's tree; with a pose topic, None accepts
    the topic's frame). base_frame: the robot's frame (default Odometry's child_frame_id, else
    "base_link"). pose_topic: a nav_msgs/Odometry, geometry_msgs/PoseStamped or
    PoseWithCovarianceStamped topic of base poses. laser_mount: (x, y, yaw) of the laser in the
    base frame, instead of /tf_static. pose_source: "auto" (pose_topic if given, else tf),
    "tf", "topic" or "none" (NaN poses; the caller brings them). no_return: "skip" or "free"
    (see :mod:`vasco_gpu.bags.scans`). progress: progress(done_messages, total_messages).
    outside_span: a scan stamp outside the time span of the poses (a /tf link on the chain, or
    the pose topic) is a BagError ("error", the default) or gets a NaN pose ("skip": the caller
    leaves those scans out; recorders often start the laser before tf).

    Raises BagError for anything about the bag, ValueError for arguments that are wrong in
    themselves.
    """
    _check_arguments(pose_source, no_return, pose_topic, outside_span)
    mount_arg = check_mount(laser_mount)
    with open_bag(path) as reader:
        topics = reader.topics
        topic = pick_scan_topic(path, topics, scan_topic)
        if topics[topic].msgcount == 0:
            raise BagError(path, f"LaserScan topic {topic!r} has no messages", topic=topic)
        source = choose_pose_source(path, topics, pose_source, pose_topic)
        scans = ScanAccumulator(path, topic, no_return)
        handlers = {topic: scans.add}
        tf = None
        if tf_topics(topics):
            tf = TfBuffer(path, stamp_name="scan stamp",
                          outside_hint="skip_unposed / --skip-unposed leaves such scans out")
            for name in tf_topics(topics):
                static = name.rstrip("/").endswith("tf_static")
                if static or source == "tf":  # /tf only when it gives the poses
                    handlers[name] = (lambda m, s=static, n=name: tf.add_message(m, s, n))
        series = None
        if source == "topic":
            name, msgtype = check_pose_topic(path, topics, pose_topic)
            series = PoseSeries(path, name, msgtype, fixed_frame, base_frame)
            handlers[name] = series.add
        total = sum(topics[name].msgcount for name in handlers)
        ticker = Progress(progress, total)
        read_messages(reader, path, handlers, ticker)
        ticker.end()
    if not scans.ns:
        raise BagError(path, f"LaserScan topic {topic!r} has no messages", topic=topic)
    ns = np.frombuffer(scans.ns, dtype=np.int64).copy()
    poses, mounts, label = poses_for(path, source, scans, ns, tf, series, fixed_frame, base_frame, mount_arg,
                                     outside_span)
    return BagScans(
        path=os.fspath(path), topic=topic, frame_id=scans.frame_id, stamps=stamp_seconds(ns), poses=poses,
        mounts=mounts, ranges=np.concatenate(scans.ranges) if scans.ranges else np.zeros(0, np.float32),
        beam_counts=np.frombuffer(scans.beam_counts, dtype=np.int64).copy(),
        first_angle=np.frombuffer(scans.first_angle, dtype=np.float64).copy(),
        angle_step=np.frombuffer(scans.angle_step, dtype=np.float64).copy(), counts=dict(scans.counts),
        pose_source=label, range_max=np.frombuffer(scans.range_max, dtype=np.float64).copy(),
    )
