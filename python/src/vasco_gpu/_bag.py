"""Laser scans and laser poses from ROS bags, as plain NumPy arrays for the mapper.

:func:`read_bag` reads the ``sensor_msgs/LaserScan`` messages of one topic of a ROS 1 ``.bag``,
a ROS 2 bag directory (sqlite3 or MCAP storage, with ``metadata.yaml``) or a bare ``.db3`` /
``.mcap`` file, and the pose of the laser at each scan's ``header.stamp``, taken either from tf
(``/tf``, ``/tf_static``) or from a pose topic (``nav_msgs/Odometry``,
``geometry_msgs/PoseStamped``, ``geometry_msgs/PoseWithCovarianceStamped``).
:func:`write_carmen_log` writes the result as a CARMEN log of ``ROBOTLASER1`` lines.

The bags are read with the pure-Python ``rosbags`` package (its ``AnyReader``), which
deserializes with the type definitions stored in the bag; a ROS 2 bag without them falls back
to the ROS 2 Humble definitions. Importing this module raises ImportError when rosbags is not
installed. It never imports the compiled extension: it returns plain NumPy data.

Scans are kept in bag order (the order ``rosbags`` yields them: by receive time) and are not
sorted by header stamp, as log2map keeps a log's order: the map depends on it (the first scan
sets the grid's frame, and CARMEN's updates round in the order they come).

Range policy: REP 117 readings turned into CARMEN's semantics
---------------------------------------------------------------
CARMEN's mapper uses a beam only if its range is < 50.0 m (a float compare) and skips every
other beam entirely (NaN and +inf included). A beam below 50 m but beyond the mapper's
``range_max`` (``vasco_range_max``) clears free space up to ``range_max`` and marks no hit.
With ``v`` a value of ``msg.ranges`` (float32), ``rmin = msg.range_min``,
``rmax = msg.range_max``:

=============================  ==========================  ==============  ==============
reading ``v``                  meaning (REP 117)           stored          counted as
=============================  ==========================  ==============  ==============
finite, rmin <= v <= rmax      a hit                       v, bit for bit  (not counted)
NaN                            erroneous reading           NaN (skipped)   ``nan``
-inf                           object too close            NaN (skipped)   ``neg_inf``
finite, v < rmin               invalid                     NaN (skipped)   ``below_min``
finite, v > rmax               invalid                     NaN (skipped)   ``above_max``
+inf, ``no_return="skip"``     no return within range      +inf (skipped)  ``pos_inf``
+inf, ``no_return="free"``     no return within range      49.999996       ``pos_inf``
=============================  ==========================  ==============  ==============

``no_return="skip"`` (the default) is CARMEN's own treatment of max-range readings: they clear
nothing. ``no_return="free"`` stores the largest float32 below 50.0
(``np.nextafter(np.float32(50), np.float32(0))``), which the mapper treats as "free up to
range_max, no hit" — what ROS mappers (gmapping, slam_toolbox) do with "no return". A finite
``v > rmax`` stays invalid in both modes: the sensor says the value is not a measurement.
"""

from __future__ import annotations

import math
import os
import re
from array import array
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
from rosbags.highlevel import AnyReader  # an ImportError here: rosbags is not installed
from rosbags.typesys import Stores, get_typestore

__all__ = ["BagError", "BagScans", "NO_RETURN_FREE", "read_bag", "write_carmen_log"]

#: The range stored for a +inf reading with ``no_return="free"``: the largest float32 below 50.
NO_RETURN_FREE = np.nextafter(np.float32(50.0), np.float32(0.0))

LASER_SCAN = "sensor_msgs/msg/LaserScan"
TF_TYPES = ("tf2_msgs/msg/TFMessage", "tf/msg/tfMessage")  # ROS 2 / ROS 1 tf2, old ROS 1 tf
TF_TOPICS = ("/tf", "/tf_static")
POSE_TYPES = (
    "nav_msgs/msg/Odometry",
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
)
POSE_SOURCES = ("auto", "tf", "topic", "none")
NO_RETURN_MODES = ("skip", "free")
COUNT_KEYS = ("messages", "nan", "pos_inf", "neg_inf", "below_min", "above_max")

_NS = 1_000_000_000
_QUAT_TOL = 1e-9  # |q| - 1 beyond this: the quaternion is renormalised


class BagError(Exception):
    """A bag that cannot be read as asked: missing, not a bag, no such topic, no pose at a stamp.

    ``str()`` names the file first; ``.file`` is the bag as given, ``.topic`` the topic the
    problem is on (or None), ``.stamp`` the header stamp in seconds it is at (or None).
    """

    def __init__(self, file, message: str, *, topic: str | None = None, stamp: float | None = None):
        self.file = None if file is None else os.fspath(file)
        self.topic = topic
        self.stamp = stamp
        self.message = message
        super().__init__(message if self.file is None else f"{self.file}: {message}")

    def __reduce__(self):
        return (_make_bag_error, (self.file, self.message, self.topic, self.stamp))


def _make_bag_error(file, message, topic, stamp):
    """Unpickles a BagError (its constructor takes keyword-only arguments)."""
    return BagError(file, message, topic=topic, stamp=stamp)


@dataclass
class BagScans:
    """The scans of one LaserScan topic with the laser pose at each, ready for the mapper.

    Scan ``s`` has ``beam_counts[s]`` beams, stored in ``ranges`` from
    ``beam_counts[:s].sum()``; beam ``i`` points at ``first_angle[s] + i * angle_step[s]`` in
    the laser frame. ``poses`` is the laser pose in the fixed frame, ``mounts`` the laser pose
    in the base frame. ``range_max`` (an addition to the interface, per scan ``msg.range_max``)
    is what :func:`write_carmen_log` writes as the device's maximum range.
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


# ----------------------------------------------------------------------------------------------
# Small helpers


def _stamp_text(ns: int) -> str:
    """A header stamp in whole nanoseconds as exact seconds text: 12.000000001."""
    sec, nsec = divmod(int(ns), _NS)
    return f"{sec}.{nsec:09d}"


def _stamp_seconds(ns) -> np.ndarray | float:
    """Seconds of stamps in nanoseconds as ``sec + nanosec * 1e-9`` in float64 (as documented)."""
    ns = np.asarray(ns, dtype=np.int64)
    sec, nsec = np.divmod(ns, _NS)
    out = sec.astype(np.float64) + nsec.astype(np.float64) * 1e-9
    return float(out) if out.ndim == 0 else out


def _stamp_ns(stamp) -> int:
    """Whole nanoseconds of a ROS time (sec, nanosec; ROS 1 times are read the same way)."""
    return int(stamp.sec) * _NS + int(stamp.nanosec)


def _frame(name: str) -> str:
    """A frame name without ROS 1's leading '/'."""
    return name[1:] if name.startswith("/") else name


def _norm_type(msgtype: str | None) -> str | None:
    """ROS 2 spelling of a message type: sensor_msgs/LaserScan -> sensor_msgs/msg/LaserScan."""
    if msgtype and msgtype.count("/") == 1:
        pkg, name = msgtype.split("/")
        return f"{pkg}/msg/{name}"
    return msgtype


def _short_type(msgtype: str | None) -> str:
    """ROS 1 spelling for messages: sensor_msgs/msg/LaserScan -> sensor_msgs/LaserScan."""
    return (msgtype or "mixed types").replace("/msg/", "/")


def _resolve_topic(name: str, topics) -> str | None:
    """The topic of the bag that name means, with or without the leading '/'; None if absent."""
    for candidate in (name, "/" + name.lstrip("/"), name.lstrip("/")):
        if candidate in topics:
            return candidate
    return None


def _wrap_angle(a):
    """a wrapped into [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


# ----------------------------------------------------------------------------------------------
# Opening


_MAGICS = (  # (first bytes, what it is, the suffix rosbags needs for it)
    (b"#ROSBAG V", "a ROS 1 bag", ".bag"),
    (b"\x89MCAP", "an MCAP file", ".mcap"),
    (b"SQLite format 3\x00", "an SQLite3 file", ".db3"),
)


def _sniff(path: Path) -> tuple[str, str] | None:
    """(what, expected suffix) from a file's first bytes, or None if it is none of the three."""
    with suppress(OSError), path.open("rb") as f:
        head = f.read(16)
        for magic, what, suffix in _MAGICS:
            if head.startswith(magic):
                return what, suffix
    return None


def _storage_target(path) -> Path:
    """The path to hand to rosbags, after the checks whose errors rosbags words poorly.

    rosbags picks the format from the name: a directory is a ROS 2 bag (needs metadata.yaml),
    ``.bag`` ROS 1, ``.mcap`` / ``.db3`` a bare ROS 2 storage file. A directory without
    metadata.yaml but with exactly one storage file is read through that file.
    """
    p = Path(path)
    if not p.exists():
        raise BagError(path, "no such file or directory")
    if p.is_dir():
        if (p / "metadata.yaml").exists():
            return p
        inner = sorted(x for x in p.iterdir() if x.suffix in (".mcap", ".db3") and x.is_file())
        if len(inner) == 1:
            return inner[0]
        if not inner:
            raise BagError(path, "is a directory without metadata.yaml and without a .db3 or .mcap file: "
                                 "not a ROS 2 bag")
        names = ", ".join(x.name for x in inner)
        raise BagError(path, f"is a directory without metadata.yaml holding several storage files ({names}); "
                             "a split bag needs its metadata.yaml")
    if p.stat().st_size == 0:
        raise BagError(path, "is empty (0 bytes): not a ROS bag")
    sniffed = _sniff(p)
    if sniffed is None:
        raise BagError(path, "is not a ROS bag: it starts like none of a ROS 1 bag, an MCAP file or an "
                             "SQLite3 database")
    what, suffix = sniffed
    if p.suffix != suffix:
        raise BagError(path, f"is {what} but its name does not end in {suffix}; rosbags chooses the format "
                             f"by the name, so rename it (or link it) to end in {suffix}")
    return p


def _repair_hint(target: Path, err: BaseException) -> str:
    """A hint for the usual damage: a recording cut short loses what is written at the end."""
    text = str(err).lower()
    if target.suffix == ".bag" and ("index" in text or "header" in text):
        return " (a ROS 1 bag cut short loses its index; 'rosbag reindex' may restore it)"
    if target.suffix == ".mcap" and ("end magic" in text or "footer" in text or "summary" in text):
        return " (an MCAP file cut short has no footer; 'mcap recover' may repair it)"
    return ""


def _reason(err: BaseException) -> str:
    """One line saying what an exception from rosbags says."""
    text = str(err).strip() or type(err).__name__
    return text.splitlines()[0]


@contextmanager
def _open_bag(path):
    """An open rosbags AnyReader on path; any failure to open is a BagError chained to the cause."""
    target = _storage_target(path)
    default = get_typestore(Stores.ROS2_HUMBLE)
    try:
        reader = AnyReader([target], default_typestore=default)
        reader.open()
    except Exception as err:  # rosbags raises many kinds (ReaderError, KeyError, sqlite3, zstd, ...)
        why = f"{_reason(err)}{_repair_hint(target, err)}"
        raise BagError(path, f"cannot be read as a ROS bag: {why}") from err
    try:
        _ensure_types(reader, default)
        yield reader
    finally:
        with suppress(Exception):
            reader.close()


def _ensure_types(reader, default) -> None:
    """Registers the default (ROS 2 Humble) definitions of types the bag uses but does not define.

    AnyReader falls back to the default store only when no connection has a definition; a bag
    that defines some types and not others would otherwise fail on the undefined ones.
    """
    missing = {c.msgtype for c in reader.connections} - set(reader.typestore.fielddefs)
    if missing and reader.is2:
        extra = {k: v for k, v in default.fielddefs.items() if k not in reader.typestore.fielddefs}
        with suppress(Exception):
            reader.typestore.register(extra)


# ----------------------------------------------------------------------------------------------
# Topics


def _topic_listing(topics) -> str:
    """'/a' (pkg/Type), '/b' (pkg/Type) ... or 'none' for an empty bag."""
    if not topics:
        return "none: the bag has no topics"
    return ", ".join(f"{name!r} ({_short_type(info.msgtype)})" for name, info in sorted(topics.items()))


def _topics_of_type(topics, msgtypes) -> list[str]:
    """The topics whose (normalised) message type is one of msgtypes, sorted."""
    return sorted(name for name, info in topics.items() if _norm_type(info.msgtype) in msgtypes)


def _pick_scan_topic(path, topics, scan_topic: str | None) -> str:
    """The LaserScan topic to read: the named one (which must be a LaserScan) or the only one."""
    scans = _topics_of_type(topics, (LASER_SCAN,))
    listing = ", ".join(repr(t) for t in scans) or "none"
    if scan_topic is not None:
        name = _resolve_topic(scan_topic, topics)
        if name is None:
            raise BagError(path, f"no topic {scan_topic!r} in the bag (LaserScan topics: {listing})",
                           topic=scan_topic)
        if name not in scans:
            kind = _short_type(topics[name].msgtype)
            raise BagError(path, f"topic {name!r} is {kind}, not sensor_msgs/LaserScan "
                                 f"(LaserScan topics: {listing})", topic=name)
        return name
    if not scans:
        raise BagError(path, f"no sensor_msgs/LaserScan topic (topics: {_topic_listing(topics)})")
    if len(scans) > 1:
        raise BagError(path, f"several sensor_msgs/LaserScan topics ({listing}); pass scan_topic "
                             "(--scan-topic) to choose one")
    return scans[0]


def _tf_topics(topics) -> list[str]:
    """The bag's /tf and /tf_static topics that carry tf messages (and have any)."""
    found = []
    for name in TF_TOPICS:
        actual = _resolve_topic(name, topics)
        info = topics.get(actual)
        if info is not None and _norm_type(info.msgtype) in TF_TYPES and info.msgcount > 0:
            found.append(actual)
    return found


def _choose_pose_source(path, topics, pose_source: str, pose_topic: str | None) -> str:
    """"tf", "topic" or "none" from the pose_source argument and what the bag has."""
    if pose_source == "auto":
        if pose_topic is not None:
            return "topic"
        if _tf_topics(topics):
            return "tf"
        raise BagError(path, "no /tf and no pose topic to take the laser poses from (pass pose_topic "
                             "(--pose-topic) or a pose file (--poses FILE))")
    if pose_source == "tf" and not _tf_topics(topics):
        raise BagError(path, f"pose_source 'tf' but the bag has no /tf or /tf_static messages (topics: "
                             f"{_topic_listing(topics)})")
    return pose_source


def _check_pose_topic(path, topics, pose_topic: str) -> tuple[str, str]:
    """(topic, normalised type) of the pose topic, which must exist and have a supported type."""
    name = _resolve_topic(pose_topic, topics)
    if name is None:
        raise BagError(path, f"no pose topic {pose_topic!r} in the bag (topics: {_topic_listing(topics)})",
                       topic=pose_topic)
    msgtype = _norm_type(topics[name].msgtype)
    if msgtype not in POSE_TYPES:
        kinds = ", ".join(_short_type(t) for t in POSE_TYPES)
        raise BagError(path, f"pose topic {name!r} is {_short_type(msgtype)}; supported: {kinds}", topic=name)
    return name, msgtype


# ----------------------------------------------------------------------------------------------
# Scans and the REP 117 policy


def _apply_rep117(v: np.ndarray, rmin: float, rmax: float, no_return: str, counts: dict) -> np.ndarray:
    """A float32 copy of one scan's ranges after the policy in the module docstring; counts updated."""
    out = np.asarray(v).astype(np.float32, copy=True)
    finite = np.isfinite(out)
    if finite.all() and (out >= rmin).all() and (out <= rmax).all():
        return out
    nan = np.isnan(out)
    pos = out == np.inf
    neg = out == -np.inf
    below = finite & (out < rmin)
    above = finite & (out > rmax)
    masks = {"nan": nan, "pos_inf": pos, "neg_inf": neg, "below_min": below, "above_max": above}
    for key, mask in masks.items():
        counts[key] += int(mask.sum())
    out[nan | neg | below | above] = np.nan
    if no_return == "free":
        out[pos] = NO_RETURN_FREE
    return out


class _ScanAccumulator:
    """Collects the scans of the chosen topic in bag order, applying the range policy."""

    def __init__(self, path, topic: str, no_return: str):
        self.path, self.topic, self.no_return = path, topic, no_return
        self.frame_id: str | None = None
        self.ns = array("q")
        self.first_angle = array("d")
        self.angle_step = array("d")
        self.range_max = array("d")
        self.beam_counts = array("q")
        self.ranges: list[np.ndarray] = []
        self.counts = dict.fromkeys(COUNT_KEYS, 0)

    def _error(self, ns: int, what: str) -> BagError:
        """A BagError about the scan at stamp ns."""
        return BagError(self.path, f"scan at stamp {_stamp_text(ns)} on {self.topic!r} {what}",
                        topic=self.topic, stamp=_stamp_seconds(ns))

    def add(self, msg) -> None:
        ns = _stamp_ns(msg.header.stamp)
        frame = _frame(msg.header.frame_id)
        if self.frame_id is None:
            self.frame_id = frame
        elif frame != self.frame_id:
            raise self._error(ns, f"is in frame {frame!r}, the first scan in {self.frame_id!r}; all scans "
                                  "of a topic must share their frame")
        rmin, rmax = float(msg.range_min), float(msg.range_max)
        if not rmin <= rmax:
            raise self._error(ns, f"has range_min {rmin!r} > range_max {rmax!r}")
        a0, da = float(msg.angle_min), float(msg.angle_increment)
        if not (math.isfinite(a0) and math.isfinite(da)):
            raise self._error(ns, f"has angle_min {a0!r}, angle_increment {da!r}")
        r = _apply_rep117(msg.ranges, rmin, rmax, self.no_return, self.counts)
        self.ns.append(ns)
        self.first_angle.append(a0)
        self.angle_step.append(da)
        self.range_max.append(rmax)
        self.beam_counts.append(len(r))
        self.ranges.append(r)
        self.counts["messages"] += 1


# ----------------------------------------------------------------------------------------------
# Rigid transforms: translation (n, 3) and quaternion (n, 4) as x, y, z, w, float64


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a * b of quaternions (..., 4) stored x, y, z, w."""
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz], axis=-1)


def _quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v (..., 3) rotated by unit quaternions q (..., 4): v + w t + u x t with t = 2 u x v."""
    u, w = q[..., :3], q[..., 3:4]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def _compose(a, b):
    """a * b for transforms (t, q): first b, then a (T_x_z = T_x_y * T_y_z)."""
    ta, qa = a
    tb, qb = b
    return ta + _quat_rotate(qa, tb), _quat_mul(qa, qb)


def _inverse(a):
    """The inverse of transforms (t, q)."""
    t, q = a
    qi = q * np.array([-1.0, -1.0, -1.0, 1.0])
    return -_quat_rotate(qi, t), qi


def _yaw(q: np.ndarray) -> np.ndarray:
    """Yaw of quaternions (..., 4): atan2(2(w z + x y), 1 - 2(y^2 + z^2))."""
    x, y, z, w = np.moveaxis(q, -1, 0)
    return np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _slerp(q0: np.ndarray, q1: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Spherical linear interpolation of unit quaternions (n, 4) at fractions f (n,).

    Slerp rather than normalised lerp: it is what tf2 does (TimeCache::interpolate), so the
    poses match what ROS tools compute, and it moves at constant angular speed between the
    samples. The two differ by O(angle^3) only; for nearly equal samples (sin < 1e-9) slerp's
    formula is ill-conditioned and nlerp, equal to it there, is used. The shorter arc is taken.
    """
    dot = np.sum(q0 * q1, axis=-1)
    q1 = np.where((dot < 0.0)[:, None], -q1, q1)
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    s = np.sin(theta)
    small = s < 1e-9
    safe = np.where(small, 1.0, s)
    w0 = np.where(small, 1.0 - f, np.sin((1.0 - f) * theta) / safe)
    w1 = np.where(small, f, np.sin(f * theta) / safe)
    out = w0[:, None] * q0 + w1[:, None] * q1
    return out / np.linalg.norm(out, axis=-1, keepdims=True)


def _sorted_samples(ns: array, values: array, width: int):
    """(stamps (k,), values (k, width)) of samples recorded in any order, sorted by stamp, with
    one sample per stamp (the last one recorded for a repeated stamp)."""
    times = np.frombuffer(ns, dtype=np.int64)
    vals = np.frombuffer(values, dtype=np.float64).reshape(-1, width)
    order = np.argsort(times, kind="stable")
    times, vals = times[order], vals[order]
    keep = np.append(times[1:] != times[:-1], True)
    return times[keep], vals[keep]


def _first_outside(times: np.ndarray, ns: np.ndarray) -> int | None:
    """The first of the stamps ns outside [times[0], times[-1]], or None."""
    outside = (ns < times[0]) | (ns > times[-1])
    return int(ns[np.argmax(outside)]) if outside.any() else None


def _bracket(times: np.ndarray, ns: np.ndarray):
    """(hit, hit index, lo, hi, fraction) locating stamps ns (within the span) among sorted
    times: an exact hit at times[index], else between times[lo] and times[hi] at fraction f."""
    i = np.searchsorted(times, ns, side="left")
    hit = times[i] == ns
    lo, hi = np.maximum(i - 1, 0), i
    span = (times[hi] - times[lo]).astype(np.float64)
    f = np.where(hit, 0.0, (ns - times[lo]).astype(np.float64) / np.where(span == 0, 1.0, span))
    return hit, i, lo, hi, f


def _is_identity(t: np.ndarray, q: np.ndarray) -> bool:
    """True for a transform with translation exactly 0 and rotation exactly (0, 0, 0, +-1)."""
    return not t.any() and not q[:3].any() and abs(q[3]) == 1.0


def _unit_quaternion(q, what: str, path) -> np.ndarray:
    """q as a float64 unit quaternion: untouched when within 1e-9 of unit length (exactness),
    renormalised otherwise; a zero or non-finite quaternion is a BagError."""
    q = np.asarray(q, dtype=np.float64)
    n = math.sqrt(float(np.dot(q, q)))
    if not math.isfinite(n) or n < 1e-6:
        raise BagError(path, f"{what} has an invalid rotation quaternion {tuple(q.tolist())}")
    return q if abs(n - 1.0) <= _QUAT_TOL else q / n


# ----------------------------------------------------------------------------------------------
# The tf tree


class _Edge:
    """One parent -> child link of tf: a static transform, or a time series of samples."""

    def __init__(self, parent: str, child: str, static: bool):
        self.parent, self.child, self.static = parent, child, static
        self.ns = array("q")
        self.values = array("d")  # tx ty tz qx qy qz qw per sample
        self._arrays = None

    def add(self, ns: int, t, q) -> None:
        if self.static:  # the latest static transform wins, as in tf2
            del self.ns[:], self.values[:]
        self.ns.append(ns)
        self.values.extend((*t, *q))
        self._arrays = None

    def arrays(self):
        """(stamps (k,), translations (k, 3), quaternions (k, 4)) sorted by stamp."""
        if self._arrays is None:
            times, vals = _sorted_samples(self.ns, self.values, 7)
            self._arrays = (times, vals[:, :3].copy(), vals[:, 3:].copy())
        return self._arrays

    def span_text(self) -> str:
        ns = self.arrays()[0]
        return f"[{_stamp_text(ns[0])}, {_stamp_text(ns[-1])}]"


class _TfTree:
    """tf's frame tree from the TFMessages of /tf and /tf_static, with lookups at scan stamps."""

    def __init__(self, path):
        self.path = path
        self.edges: dict[str, _Edge] = {}  # by child: each child has one parent

    def add_message(self, msg, static: bool, topic: str) -> None:
        for ts in msg.transforms:
            parent, child = _frame(ts.header.frame_id), _frame(ts.child_frame_id)
            ns = _stamp_ns(ts.header.stamp)
            edge = self.edges.get(child)
            if edge is None:
                edge = self.edges[child] = _Edge(parent, child, static)
            elif edge.parent != parent:
                was = f"{edge.parent!r} on {'/tf_static' if edge.static else '/tf'}"
                raise BagError(self.path, f"frame {child!r} has two parents in tf: {was} and {parent!r} on "
                                          f"{topic} (stamp {_stamp_text(ns)}); tf must be a tree",
                               topic=topic, stamp=_stamp_seconds(ns))
            elif edge.static != static:
                raise BagError(self.path, f"tf {parent} -> {child} is on both /tf and /tf_static (stamp "
                                          f"{_stamp_text(ns)} on {topic}); a link is either static or not",
                               topic=topic, stamp=_stamp_seconds(ns))
            tr, rot = ts.transform.translation, ts.transform.rotation
            what = f"tf {parent} -> {child} at stamp {_stamp_text(ns)}"
            q = _unit_quaternion((rot.x, rot.y, rot.z, rot.w), what, self.path)
            edge.add(ns, (float(tr.x), float(tr.y), float(tr.z)), q)

    def frames(self) -> list[str]:
        return sorted({e.child for e in self.edges.values()} | {e.parent for e in self.edges.values()})

    def up(self, frame: str) -> list[str]:
        """frame, its parent, grandparent, ... up to its root."""
        chain = [frame]
        while chain[-1] in self.edges:
            chain.append(self.edges[chain[-1]].parent)
            if len(chain) > len(self.edges) + 1:
                raise BagError(self.path, f"tf has a cycle through {frame!r}")
        return chain

    def _reach_text(self, frame: str) -> str:
        """'laser' reaches 'odom' via base_link / 'map' is the root of its tree."""
        chain = self.up(frame)
        if len(chain) == 1:
            return f"{frame!r} is the root of another tree"
        via = f" via {', '.join(chain[1:-1])}" if len(chain) > 2 else ""
        return f"{frame!r} reaches {chain[-1]!r}{via}"

    def _no_chain_text(self, target: str, source: str) -> str:
        """Why target and source are not connected, naming the missing link."""
        known = set(self.frames())
        if source not in known and target not in known:
            why = f"neither {source!r} nor {target!r} is in tf"
        elif source not in known:
            why = f"{source!r} is not in tf"
        elif target not in known:
            why = f"{self._reach_text(source)}, {target!r} has no connection to it"
        else:
            why = f"{self._reach_text(source)}, {self._reach_text(target)}"
        frames = ", ".join(sorted(known))
        return f"no transform chain from {target!r} to {source!r}: {why} (frames in /tf: {frames})"

    def path_between(self, target: str, source: str) -> tuple[list[str], list[str]]:
        """(frames from source up to the common ancestor, frames from target up to it); a
        BagError naming the missing link when the two are not in one tree."""
        up_s, up_t = self.up(source), self.up(target)
        common = next((f for f in up_s if f in set(up_t)), None)
        if common is None:
            raise BagError(self.path, self._no_chain_text(target, source))
        return up_s[: up_s.index(common) + 1], up_t[: up_t.index(common) + 1]

    def _edge_at(self, edge: _Edge, ns: np.ndarray):
        """The edge's transform at stamps ns: None for an identity static link (to be skipped),
        the sample itself on an exact stamp hit, interpolated between the bracketing samples."""
        times, tr, qs = edge.arrays()
        if edge.static:
            if _is_identity(tr[0], qs[0]):
                return None
            n = len(ns)
            return np.broadcast_to(tr[0], (n, 3)), np.broadcast_to(qs[0], (n, 4))
        bad = _first_outside(times, ns)
        if bad is not None:
            raise BagError(self.path, f"scan stamp {_stamp_text(bad)} is outside the time span "
                                      f"{edge.span_text()} of tf {edge.parent} -> {edge.child} "
                                      f"({len(times)} samples); tf is not extrapolated (skip_unposed / --skip-unposed "
                                      f"leaves such scans out)",
                           topic="/tf", stamp=_stamp_seconds(bad))
        hit, i, lo, hi, f = _bracket(times, ns)
        t = tr[lo] + (tr[hi] - tr[lo]) * f[:, None]
        q = _slerp(qs[lo], qs[hi], f)
        t[hit], q[hit] = tr[i[hit]], qs[i[hit]]  # exact hits: the sample unchanged
        return t, q

    def _down(self, chain: list[str], ns: np.ndarray, static_only: bool):
        """T_ancestor_frame for chain = [frame, ..., ancestor], composed from the ancestor down;
        None when every link is an identity static transform. Identity static links are skipped,
        not multiplied, so an identity mount leaves the pose's bits unchanged. With static_only,
        a dynamic link raises _NotStatic."""
        total = None
        for child in reversed(chain[:-1]):
            edge = self.edges[child]
            if static_only and not edge.static:
                raise _NotStatic(edge)
            link = self._edge_at(edge, ns)
            if link is not None:
                total = link if total is None else _compose(total, link)
        return total

    def inside_spans(self, target: str, source: str, ns: np.ndarray) -> np.ndarray:
        """Which stamps ns lie within the time span of every /tf link between the two frames
        (static links have none): the stamps lookup can answer without extrapolating."""
        up_s, up_t = self.path_between(target, source)
        inside = np.ones(len(ns), dtype=bool)
        for chain in (up_s, up_t):
            for child in chain[:-1]:
                edge = self.edges[child]
                if not edge.static:
                    times = edge.arrays()[0]
                    inside &= (ns >= times[0]) & (ns <= times[-1])
        return inside

    def lookup(self, target: str, source: str, ns: np.ndarray, static_only: bool = False):
        """T_target_source (translations (n, 3), quaternions (n, 4)) at stamps ns:
        inv(T_common_target) * T_common_source through the common ancestor of the two frames."""
        up_s, up_t = self.path_between(target, source)
        a = self._down(up_s, ns, static_only)
        b = self._down(up_t, ns, static_only)
        if a is None:
            n = len(ns)
            a = (np.zeros((n, 3)), np.tile([0.0, 0.0, 0.0, 1.0], (n, 1)))
        if b is None:
            return np.array(a[0], dtype=np.float64), np.array(a[1], dtype=np.float64)
        return _compose(_inverse(b), a)


class _NotStatic(Exception):
    """A chain asked to be static has a /tf (dynamic) link."""

    def __init__(self, edge: _Edge):
        super().__init__(f"{edge.parent} -> {edge.child} is on /tf")
        self.edge = edge


def _planar(path, t: np.ndarray, q: np.ndarray, what: str) -> np.ndarray:
    """(n, 3) x, y, yaw of 3-D transforms; a laser upside down (its z axis pointing down, which
    would mirror the scans in the plane) is a BagError."""
    zz = 1.0 - 2.0 * (q[:, 0] ** 2 + q[:, 1] ** 2)  # z component of the rotated z axis
    if (zz < 0).any():
        raise BagError(path, f"{what} is upside down (its z axis points down): mirrored scans are not "
                             "supported")
    return np.column_stack([t[:, 0], t[:, 1], _yaw(q)])


# ----------------------------------------------------------------------------------------------
# Pose topics and planar poses


class _PoseSeries:
    """Base poses from a pose topic: stamps, (x, y, yaw), the frame and the base frame."""

    def __init__(self, path, topic: str, msgtype: str, fixed_frame: str | None, base_frame: str | None):
        self.path, self.topic, self.msgtype = path, topic, msgtype
        self.fixed_frame = fixed_frame
        self.base_frame = base_frame
        self.ns = array("q")
        self.values = array("d")

    def add(self, msg) -> None:
        ns = _stamp_ns(msg.header.stamp)
        frame = _frame(msg.header.frame_id)
        if self.fixed_frame is None:
            self.fixed_frame = frame
        elif frame != self.fixed_frame:
            raise BagError(self.path, f"pose on {self.topic!r} at stamp {_stamp_text(ns)} is in frame "
                                      f"{frame!r}, not the fixed frame {self.fixed_frame!r} (pass "
                                      f"fixed_frame={frame!r}, or None to accept the topic's frame)",
                           topic=self.topic, stamp=_stamp_seconds(ns))
        if self.msgtype == "nav_msgs/msg/Odometry":
            self._check_child(_frame(msg.child_frame_id), ns)
        pose = msg.pose if self.msgtype == "geometry_msgs/msg/PoseStamped" else msg.pose.pose
        o = pose.orientation
        what = f"pose on {self.topic!r} at stamp {_stamp_text(ns)}"
        q = _unit_quaternion((o.x, o.y, o.z, o.w), what, self.path)
        self.ns.append(ns)
        self.values.extend((float(pose.position.x), float(pose.position.y), float(_yaw(q))))

    def _check_child(self, child: str, ns: int) -> None:
        """Odometry's child_frame_id is the base frame; it must agree with base_frame if given."""
        if not child:
            return
        if self.base_frame is None:
            self.base_frame = child
        elif child != self.base_frame:
            raise BagError(self.path, f"odometry on {self.topic!r} at stamp {_stamp_text(ns)} has "
                                      f"child_frame_id {child!r}, not the base frame {self.base_frame!r}",
                           topic=self.topic, stamp=_stamp_seconds(ns))

    def inside_span(self, ns: np.ndarray) -> np.ndarray:
        """Which stamps ns lie within the topic's time span."""
        if not self.ns:
            return np.zeros(len(ns), dtype=bool)
        times, _ = _sorted_samples(self.ns, self.values, 3)
        return (ns >= times[0]) & (ns <= times[-1])

    def at(self, ns: np.ndarray) -> np.ndarray:
        """(n, 3) base poses at stamps ns: samples on exact hits, else linear x, y and shortest-arc
        yaw between the bracketing samples; a stamp outside the topic's span is a BagError."""
        if not self.ns:
            raise BagError(self.path, f"pose topic {self.topic!r} has no messages", topic=self.topic)
        times, vals = _sorted_samples(self.ns, self.values, 3)
        bad = _first_outside(times, ns)
        if bad is not None:
            raise BagError(self.path, f"scan stamp {_stamp_text(bad)} is outside the time span "
                                      f"[{_stamp_text(times[0])}, {_stamp_text(times[-1])}] of pose topic "
                                      f"{self.topic!r} (skip_unposed / --skip-unposed leaves such scans out)",
                           topic=self.topic, stamp=_stamp_seconds(bad))
        hit, i, lo, hi, f = _bracket(times, ns)
        a, b = vals[lo], vals[hi]
        out = np.empty((len(ns), 3))
        out[:, :2] = a[:, :2] + (b[:, :2] - a[:, :2]) * f[:, None]
        out[:, 2] = a[:, 2] + _wrap_angle(b[:, 2] - a[:, 2]) * f
        out[hit] = vals[i[hit]]  # exact hits: the sample unchanged
        return out


def _planar_compose(base: np.ndarray, mount: np.ndarray) -> np.ndarray:
    """Laser poses base o mount (planar); the base poses unchanged when the mount is (0, 0, 0)."""
    mount = np.broadcast_to(np.asarray(mount, dtype=np.float64), base.shape)
    out = base.copy()
    moved = mount.any(axis=1)
    if moved.any():
        b, m = base[moved], mount[moved]
        c, s = np.cos(b[:, 2]), np.sin(b[:, 2])
        out[moved] = np.column_stack([b[:, 0] + c * m[:, 0] - s * m[:, 1],
                                      b[:, 1] + s * m[:, 0] + c * m[:, 1],
                                      b[:, 2] + m[:, 2]])
    return out


def _planar_uncompose(laser: np.ndarray, mount: np.ndarray) -> np.ndarray:
    """Robot poses r with r o mount = laser; the laser poses unchanged when the mount is 0."""
    mount = np.broadcast_to(np.asarray(mount, dtype=np.float64), laser.shape)
    out = laser.copy()
    moved = mount.any(axis=1)
    if moved.any():
        l, m = laser[moved], mount[moved]
        theta = l[:, 2] - m[:, 2]
        theta = np.where(np.abs(theta) > np.pi, _wrap_angle(theta), theta)
        c, s = np.cos(theta), np.sin(theta)
        out[moved] = np.column_stack([l[:, 0] - c * m[:, 0] + s * m[:, 1],
                                      l[:, 1] - s * m[:, 0] - c * m[:, 1],
                                      theta])
    return out


def _check_mount(laser_mount) -> np.ndarray | None:
    """laser_mount as a float64 (3,) array of finite x, y, yaw, or None; else ValueError."""
    if laser_mount is None:
        return None
    m = np.asarray(laser_mount, dtype=np.float64)
    if m.shape != (3,) or not np.isfinite(m).all():
        raise ValueError(f"laser_mount must be three finite numbers x, y, yaw, not {laser_mount!r}")
    return m


def _static_mount(tf: _TfTree | None, base: str, frame: str) -> np.ndarray | None:
    """The laser pose (x, y, yaw) in base from static tf links only; (0, 0, 0) when the frames
    are equal; None when there is no static chain."""
    if base == frame:
        return np.zeros(3)
    if tf is None or base not in tf.frames() or frame not in tf.frames():
        return None
    try:
        t, q = tf.lookup(base, frame, np.zeros(1, dtype=np.int64), static_only=True)
    except (BagError, _NotStatic):
        return None
    return _planar(tf.path, t, q, f"the laser frame {frame!r} in {base!r}")[0]


# ----------------------------------------------------------------------------------------------
# read_bag


class _Progress:
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


def _read_messages(reader, path, handlers: dict, progress: _Progress) -> None:
    """One pass over the connections of the topics in handlers, in bag order, each message
    deserialized with the bag's definitions and passed to its topic's handler."""
    topics = reader.topics
    connections = [c for name in handlers for c in topics[name].connections]
    stream = reader.messages(connections=connections)
    while True:
        try:
            item = next(stream, None)
        except Exception as err:
            raise BagError(path, f"reading failed after {progress.done} messages: {_reason(err)}") from err
        if item is None:
            break
        connection, t_ns, raw = item
        try:
            msg = reader.deserialize(raw, connection.msgtype)
        except Exception as err:
            raise BagError(path, f"cannot deserialize a {_short_type(connection.msgtype)} message on "
                                 f"{connection.topic!r} received at {_stamp_text(t_ns)}: {_reason(err)}",
                           topic=connection.topic) from err
        handlers[connection.topic](msg)
        progress.tick()


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
    (see the module docstring). progress: progress(done_messages, total_messages).
    outside_span: a scan stamp outside the time span of the poses (a /tf link on the chain, or
    the pose topic) is a BagError ("error", the default) or gets a NaN pose ("skip": the caller
    leaves those scans out; recorders often start the laser before tf).

    Raises BagError for anything about the bag, ValueError for arguments that are wrong in
    themselves.
    """
    _check_arguments(pose_source, no_return, pose_topic, outside_span)
    mount_arg = _check_mount(laser_mount)
    with _open_bag(path) as reader:
        topics = reader.topics
        topic = _pick_scan_topic(path, topics, scan_topic)
        if topics[topic].msgcount == 0:
            raise BagError(path, f"LaserScan topic {topic!r} has no messages", topic=topic)
        source = _choose_pose_source(path, topics, pose_source, pose_topic)
        scans = _ScanAccumulator(path, topic, no_return)
        handlers = {topic: scans.add}
        tf = None
        if _tf_topics(topics):
            tf = _TfTree(path)
            for name in _tf_topics(topics):
                static = name.rstrip("/").endswith("tf_static")
                if static or source == "tf":  # /tf only when it gives the poses
                    handlers[name] = (lambda m, s=static, n=name: tf.add_message(m, s, n))
        series = None
        if source == "topic":
            name, msgtype = _check_pose_topic(path, topics, pose_topic)
            series = _PoseSeries(path, name, msgtype, fixed_frame, base_frame)
            handlers[name] = series.add
        total = sum(topics[name].msgcount for name in handlers)
        ticker = _Progress(progress, total)
        _read_messages(reader, path, handlers, ticker)
        ticker.end()
    if not scans.ns:
        raise BagError(path, f"LaserScan topic {topic!r} has no messages", topic=topic)
    ns = np.frombuffer(scans.ns, dtype=np.int64).copy()
    poses, mounts, label = _poses_for(path, source, scans, ns, tf, series, fixed_frame, base_frame, mount_arg,
                                      outside_span)
    return BagScans(
        path=os.fspath(path), topic=topic, frame_id=scans.frame_id, stamps=_stamp_seconds(ns), poses=poses,
        mounts=mounts, ranges=np.concatenate(scans.ranges) if scans.ranges else np.zeros(0, np.float32),
        beam_counts=np.frombuffer(scans.beam_counts, dtype=np.int64).copy(),
        first_angle=np.frombuffer(scans.first_angle, dtype=np.float64).copy(),
        angle_step=np.frombuffer(scans.angle_step, dtype=np.float64).copy(), counts=dict(scans.counts),
        pose_source=label, range_max=np.frombuffer(scans.range_max, dtype=np.float64).copy(),
    )


def _inside(ns: np.ndarray, inside: np.ndarray | None, pose_at) -> np.ndarray:
    """pose_at(ns) where inside (all when None), NaN rows elsewhere."""
    if inside is None:
        return pose_at(ns)
    poses = np.full((len(ns), 3), np.nan)
    if inside.any():
        poses[inside] = pose_at(ns[inside])
    return poses


def _poses_for(path, source, scans, ns, tf, series, fixed_frame, base_frame, mount_arg, outside_span="error"):
    """(poses (n, 3), mounts (n, 3) or None, pose_source label) for the scans' stamps; with
    outside_span "skip", NaN rows for the scans outside the poses' time span."""
    n, frame = len(ns), scans.frame_id
    skip = outside_span == "skip"
    if source == "tf":
        if skip and tf.edges:
            root = fixed_frame if fixed_frame is not None else tf.up(frame)[-1]
            inside = tf.inside_spans(root, frame, ns)
        else:
            inside = None
        poses = _inside(ns, inside, lambda t: _tf_poses(path, tf, fixed_frame, frame, t))
        mount = mount_arg if mount_arg is not None else _static_mount(tf, base_frame or "base_link", frame)
        label = "tf"
    elif source == "topic":
        base = series.base_frame or "base_link"
        mount = mount_arg if mount_arg is not None else _static_mount(tf, base, frame)
        if mount is None:
            raise BagError(path, f"no static tf chain (/tf_static) from the base frame {base!r} to the "
                                 f"scans' frame {frame!r}; pass laser_mount (--laser-mount x,y,yaw)",
                           topic=series.topic)
        poses = _inside(ns, series.inside_span(ns) if skip else None,
                        lambda t: _planar_compose(series.at(t), mount))
        label = f"topic:{series.topic}"
    else:
        poses = np.full((n, 3), np.nan)
        mount = mount_arg if mount_arg is not None else _static_mount(tf, base_frame or "base_link", frame)
        label = "none"
    mounts = None if mount is None else np.tile(np.asarray(mount, dtype=np.float64), (n, 1))
    return poses, mounts, label


def _tf_poses(path, tf: _TfTree, fixed_frame: str | None, frame: str, ns: np.ndarray) -> np.ndarray:
    """(n, 3) laser poses in fixed_frame from tf (None: the root of the laser frame's tree)."""
    if not tf.edges:
        raise BagError(path, "/tf and /tf_static hold no transforms")
    if fixed_frame is None:
        fixed_frame = tf.up(frame)[-1]
    t, q = tf.lookup(fixed_frame, frame, ns)
    return _planar(path, t, q, f"the laser frame {frame!r} in {fixed_frame!r}")


# ----------------------------------------------------------------------------------------------
# write_carmen_log


def _double_text(v: float) -> str:
    """A double as the shortest text that reads back to it (repr: locale independent)."""
    return repr(float(v))


def _range_texts(r: np.ndarray) -> list[str]:
    """Each float32 range as the shortest text that reads back to the same float32 when parsed as
    a double and narrowed, as CARMEN's and our readers do ("nan", "inf" for those).

    The shortest float32 text can, rarely, lose the round trip through a double (two
    roundings); those few are written as the double's repr, which is exact."""
    r = np.asarray(r, dtype=np.float32)
    texts = [str(x) for x in r]
    if not texts:
        return texts
    back = np.array(texts, dtype=np.float64).astype(np.float32)
    same = (back.view(np.uint32) == r.view(np.uint32)) | (np.isnan(back) & np.isnan(r))
    for i in np.flatnonzero(~same):
        texts[i] = repr(float(r[i]))
    return texts


def _robot_poses(scans: BagScans, robot_poses) -> np.ndarray:
    """The robot pose per scan: robot_poses if given, else the laser pose with the mount undone
    (when mounts are known), else the laser pose."""
    n = len(scans.stamps)
    if robot_poses is not None:
        rp = np.asarray(robot_poses, dtype=np.float64)
        if rp.shape != (n, 3):
            raise ValueError(f"robot_poses must have shape ({n}, 3), not {rp.shape}")
        bad = np.flatnonzero(~np.isfinite(rp).all(axis=1))
        if bad.size:
            raise ValueError(f"robot_poses[{bad[0]}] is not finite: {rp[bad[0]].tolist()}")
        return rp
    if scans.mounts is not None:
        return _planar_uncompose(np.asarray(scans.poses, dtype=np.float64), scans.mounts)
    return np.asarray(scans.poses, dtype=np.float64)


@contextmanager
def _text_out(out):
    """A text stream for out: a path (gzip when the name ends in .gz) or an open text file."""
    if hasattr(out, "write"):
        yield out
        return
    name = os.fspath(out)
    if str(name).endswith(".gz"):
        import gzip

        with gzip.open(name, "wt", compresslevel=6, encoding="ascii", errors="backslashreplace",
                       newline="\n") as f:
            yield f
    else:
        with open(name, "w", encoding="ascii", errors="backslashreplace", newline="\n") as f:
            yield f


def _robotlaser_line(scans: BagScans, s: int, ranges: np.ndarray, robot: np.ndarray) -> str:
    """The ROBOTLASER1 line of scan s (fields as in carmen-formats.md section 1.2)."""
    n = int(scans.beam_counts[s])
    step = float(scans.angle_step[s])
    max_range = float(scans.range_max[s]) if scans.range_max is not None else 50.0
    stamp = _double_text(scans.stamps[s])
    lx, ly, lt = (float(v) for v in scans.poses[s])
    config = [_double_text(scans.first_angle[s]), _double_text(step * (n - 1) if n else 0.0),
              _double_text(step), _double_text(max_range), "0.01", "0"]
    fields = ["ROBOTLASER1", "99", *config, str(n), *_range_texts(ranges), "0",
              _double_text(lx), _double_text(ly), _double_text(lt), *(_double_text(v) for v in robot),
              "0.0", "0.0", "0.0", "0.0", "1000000.0", stamp, "bag", stamp]
    return " ".join(fields) + "\n"


def write_carmen_log(scans: BagScans, out, robot_poses=None) -> None:
    """Writes scans as a CARMEN log: a '#' header line, then one ROBOTLASER1 line per scan.

    Field choices: laser_type 99 (unknown), start_angle = first_angle, fov = angle_step * (n-1),
    angular_res = angle_step; max_range = the scan's msg.range_max (the device's maximum range,
    which is what the field means in CARMEN; 50.0, the mapper's limit, when BagScans has no
    range_max) — the mapper ignores the field and uses its own range limits; accuracy 0.01 (the
    laser-new driver's value; LaserScan has none); no remissions; tv, rv and the safety
    distances 0, turn_axis 1e6; ipc and logger timestamps both the header stamp, host "bag".
    The robot pose is robot_poses[s] if given, else the laser pose with the mount undone.
    Numbers are written to round-trip exactly (doubles by repr, ranges as float32 texts) and
    independently of the locale. A scan without a finite pose is a ValueError naming it.
    """
    n = len(scans.stamps)
    poses = np.asarray(scans.poses, dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(poses).all(axis=1)) if n else np.zeros(0, dtype=np.int64)
    if bad.size:
        raise ValueError(f"scan {bad[0]} (stamp {scans.stamps[bad[0]]!r}) has no finite laser pose "
                         f"{poses[bad[0]].tolist()}; read the bag with poses or fill BagScans.poses first")
    robots = _robot_poses(scans, robot_poses)
    offsets = np.concatenate([[0], np.cumsum(scans.beam_counts)])
    # one ASCII line whatever the bag's name: CARMEN logs are ASCII, and out may be an ASCII stream
    source = re.sub(r"[\r\n]", " ", f"{scans.path} topic {scans.topic}")
    source = source.encode("ascii", "backslashreplace").decode("ascii")
    with _text_out(out) as f:
        f.write(f"# written by vasco_gpu bag2carmen from {source}\n")
        for s in range(n):
            ranges = scans.ranges[offsets[s]:offsets[s + 1]]
            f.write(_robotlaser_line(scans, s, ranges, robots[s]))
