"""A bag's scans: ScanAccumulator collects one topic's messages through the message table's
reader (:mod:`vasco_gpu.msgs.table`: LaserScan, MultiEchoLaserScan, PointCloud2), and BagScans
holds the scans of one or more topics with their poses. The range policy (REP 117 into
CARMEN's semantics) is :mod:`vasco_gpu.msgs.laser`'s."""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass

import numpy as np

from ..msgs.errors import BagError
from ..msgs.header import frame_name, stamp_ns, stamp_seconds, stamp_text
from ..msgs.laser import ANGLES_OFF, COUNT_KEYS
from ..msgs.scan_options import ScanSettings
from ..msgs.table import MessageType
from .errors import words

__all__ = ["BagScans", "STAMP_MODES", "ScanAccumulator"]

STAMP_MODES = ("header", "receive")


@dataclass
class BagScans:
    """The scans of one LaserScan topic with the laser pose at each, ready for the mapper.

    Scan ``s`` has ``beam_counts[s]`` beams, stored in ``ranges`` from
    ``beam_counts[:s].sum()``; beam ``i`` points at ``first_angle[s] + i * angle_step[s]`` in
    the laser frame. ``poses`` is the laser pose in the fixed frame, ``mounts`` the laser pose
    in the base frame. ``range_max`` (an addition to the interface, per scan ``msg.range_max``)
    is what :func:`write_carmen_log` writes as the device's maximum range.

    Several topics (``topics``, each with its frame in ``frame_ids``) are merged in stamp
    order; ``topic_index[s]`` is scan s's topic in ``topics``, ``topic`` and ``frame_id`` are
    the first's. ``edges``: the scans before the first and after the last pose of their topic's
    chain, left out (``outside_span="edges"``): {"before", "after", "first", "last"} (counts,
    and the first and last stamp with a pose, in seconds) or None. ``warnings``: lines to warn
    of (a fixed frame chosen for a bag without 'map'; scans whose angle_max disagrees with their
    ranges by rounding, once a topic).
    """

    path: str
    topic: str
    frame_id: str
    stamps: np.ndarray
    poses: np.ndarray
    mounts: np.ndarray | None
    ranges: np.ndarray
    beam_counts: np.ndarray
    first_angle: np.ndarray
    angle_step: np.ndarray
    counts: dict
    pose_source: str
    range_max: np.ndarray | None = None
    topics: tuple = ()
    topic_index: np.ndarray | None = None
    frame_ids: tuple = ()
    edges: dict | None = None
    warnings: tuple = ()  # what the caller should warn of, one line each (BagWarning's)


class ScanAccumulator:
    """Collects the scans of one topic in bag order through its type's reader (kind, a row of the
    message table) with the options of settings. mount_of(frame, ns): the frame's static
    transform in the base frame at the first scan, for a type whose reading needs its mount
    (a PointCloud2's height band)."""

    def __init__(self, path, topic: str, kind: MessageType, settings: ScanSettings, stamp: str = "header",
                 mount_of=None):
        self.path, self.topic, self.kind, self.settings = path, topic, kind, settings
        self.receive = stamp == "receive"
        self.mount_of = mount_of
        self._mount = None
        self.frame_id: str | None = None
        self.ns = array("q")
        self.first_angle = array("d")
        self.angle_step = array("d")
        self.range_max = array("d")
        self.beam_counts = array("q")
        self.ranges: list[np.ndarray] = []
        self.counts = dict.fromkeys(COUNT_KEYS, 0)
        self.angles_note: str | None = None  # the first scan taken although its angles disagree

    def _error(self, ns: int, what: str) -> BagError:
        """A BagError about the scan at stamp ns."""
        return BagError(self.path, f"scan at stamp {stamp_text(ns)} on {self.topic!r} {what}",
                        topic=self.topic, stamp=stamp_seconds(ns))

    def add(self, msg, receive_ns: int | None = None) -> None:
        """One message; receive_ns: when the bag received it (the scan's stamp with stamp "receive")."""
        ns = int(receive_ns) if self.receive and receive_ns is not None else stamp_ns(msg.header.stamp)
        frame = frame_name(msg.header.frame_id)
        if self.frame_id is None:
            self.frame_id = frame
        elif frame != self.frame_id:
            raise self._error(ns, f"is in frame {frame!r}, the first scan in {self.frame_id!r}; all scans "
                                  "of a topic must share their frame")
        if self.kind.mount and not self.ns:  # the first scan: its frame's mount, for the height band
            self._mount = self.mount_of(frame, ns)
        scan = self.kind.read(msg, self.settings, self.counts, lambda what: self._error(ns, what), self._mount)
        if self.angles_note is None and self.counts.get(ANGLES_OFF):
            self.angles_note = _angles_text(msg, ns)
        self.ns.append(ns)
        self.first_angle.append(scan.first_angle)
        self.angle_step.append(scan.angle_step)
        self.range_max.append(scan.range_max)
        self.beam_counts.append(len(scan.ranges))
        self.ranges.append(scan.ranges)

    def angles_warning(self) -> str | None:
        """The one line about the scans taken although angle_max disagrees with their ranges."""
        off = self.counts.get(ANGLES_OFF, 0)
        if not off:
            return None
        return (f"{off} of the {len(self.ns)} scans on {self.topic!r} have angles that disagree with their "
                f"ranges by rounding (the first, {self.angles_note}): beam i is taken at angle_min + i * "
                "angle_increment, as RViz and laser_geometry take it")

    def band_error(self, band, base: str, wording: str) -> BagError | None:
        """The error for point clouds whose height band kept no point of the finite ones seen."""
        seen = self.counts.get("points_seen", 0)
        if not self.kind.mount or not seen or self.counts.get("points_in_band", 0):
            return None
        lo, hi = self.counts["z_min"], self.counts["z_max"]
        flag = words(wording, f"--z-band {band[0]:g},{band[1]:g}", f"z_band=({band[0]:g}, {band[1]:g})")
        fix = words(wording, "--z-band MIN,MAX", "z_band=(MIN, MAX)")
        text = (f"every one of the {seen} points of the {len(self.ns)} clouds on {self.topic!r} lies outside "
                f"the height band {flag} (metres in the base frame {base!r}): their heights run from {lo:.3f} to "
                f"{hi:.3f} m; pass {fix} with the band of the obstacles' heights")
        if hi - lo < 0.5:  # a cloud already flattened (as a 2-D lidar's, at its mount's height)
            text += f" (these points: {_band_around(lo, hi, wording)})"
        return BagError(self.path, text, topic=self.topic)


def _band_around(lo: float, hi: float, wording: str) -> str:
    """The option that keeps heights lo to hi, with 5 cm either side, in whole centimetres."""
    a, b = math.floor((lo - 0.05) * 100) / 100, math.ceil((hi + 0.05) * 100) / 100
    return words(wording, f"--z-band {a:g},{b:g}", f"z_band=({a:g}, {b:g})")


def _angles_text(msg, ns: int) -> str:
    """What is off in a LaserScan taken although its angle_max disagrees with its ranges."""
    n, a0, a1, da = len(msg.ranges), float(msg.angle_min), float(msg.angle_max), float(msg.angle_increment)
    return (f"stamp {stamp_text(ns)}, has {n} ranges, but angle_min {a0:.9g} to angle_max {a1:.9g} by "
            f"{da:.9g} makes {(a1 - a0) / da + 1:.1f} beams; its last beam is at {a0 + (n - 1) * da:.9g}")
