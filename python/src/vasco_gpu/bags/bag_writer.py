"""A CARMEN log as a ROS bag (the console script carmen2bag, :mod:`.carmen2bag`): to try bag2map
without a robot.

:func:`write_bag` takes a log as the package's own reader gives it (:func:`vasco_gpu.load_log`:
the scans log2map maps, their laser poses and stamps) and writes, with rosbags' writers, by
OUT's extension: ``.bag`` a ROS 1 bag, ``.mcap`` a bare MCAP file, ``.db3`` a bare sqlite3 file
(the last two ROS 2 storage files, which bag2map reads as they are). Per scan, at its stamp:

===============  ===============================  =================================================
topic            type                             content
===============  ===============================  =================================================
``/scan``        ``sensor_msgs/LaserScan``        frame ``laser``; the scan's angles (float32, the
                                                  field's type) and ranges by REP 117 (below)
``/tf``          ``tf2_msgs/TFMessage``           ``map`` -> ``base_link``: the scan's laser pose
``/tf_static``   ``tf2_msgs/TFMessage``           ``base_link`` -> ``laser``, the identity, once
===============  ===============================  =================================================

A CARMEN log gives the laser's poses only, so ``base_link`` is the laser. Ranges: CARMEN's
mapper uses a reading only below 50 m and skips every other one (the laser's max-range
readings, 81.91 m on a SICK); those are written as +inf, REP 117's "no return", which bag2map
skips too, and ``range_max`` is the largest float32 below 50 m, so that every reading CARMEN
uses is a measurement (``range_min`` 0). NaN stays NaN. So bag2map's map of the bag is
log2map's map of the log except where the float32 angles move a beam's end across a cell
border (docs/bags-and-poses.md, "How close a bag's map is to the log's").

``--cloud`` writes ``sensor_msgs/PointCloud2`` on ``/points`` (frame ``laser``, fields x, y, z
float32, 12 bytes a point) in place of the scans: for each beam CARMEN uses, its end point at
z = CLOUD_HIT_Z (0.5 m), a floor point at z = CLOUD_FLOOR_Z (0) and a ceiling point at
z = CLOUD_CEILING_Z (2.5 m), the last two halfway along the beam; a reader keeps the walls with
a z band around 0.5 m that excludes the floor and the ceiling.

Stamps: the log's (each scan's ipc timestamp) as header stamps and receive times, messages in
time order. tf holds one pose per stamp, so every scan needs a stamp of its own in whole
nanoseconds; ``--period S`` gives scan i the stamp (i + 1) S instead. The log's PARAM lines are
not carried (a bag has none): give bag2map ``--param-file`` or ``--vasco_KEY``.

The output is written whole or not at all, through the engine's output transaction
(``_core._OutputFile``, carmen_compat/atomic_file.h): rosbags' writers take a path, so the bag
is made in a hidden scratch path beside OUT (registered with the signal clean-up before it is
made), then copied into the transaction's temporary, which replaces OUT on commit; the scratch
path goes either way. With the console script's signal handlers (``_remove_temporaries_on_signals``)
an interrupted run leaves nothing behind either.
"""

from __future__ import annotations

import math
import os
import secrets
import shutil
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._errors import Error

__all__ = ["CLOUD_CEILING_Z", "CLOUD_FLOOR_Z", "CLOUD_HIT_Z", "Carmen2BagError", "OUTPUT_KINDS",
           "RANGE_MAX", "Written", "bag_ranges", "cloud_points", "output_kind", "write_bag"]

#: CARMEN's mapper uses a reading only below this range (m).
CARMEN_RANGE_LIMIT = 50.0
#: The LaserScan's range_max: the largest float32 below 50 m.
RANGE_MAX = float(np.nextafter(np.float32(CARMEN_RANGE_LIMIT), np.float32(0.0)))
#: --cloud's heights (m, in the laser's frame): beam ends, floor, ceiling.
CLOUD_HIT_Z = 0.5
CLOUD_FLOOR_Z = 0.0
CLOUD_CEILING_Z = 2.5

FIXED_FRAME, BASE_FRAME, LASER_FRAME = "map", "base_link", "laser"
SCAN_TOPIC, CLOUD_TOPIC = "/scan", "/points"

LASER_SCAN = "sensor_msgs/msg/LaserScan"
POINT_CLOUD2 = "sensor_msgs/msg/PointCloud2"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
POINT_FIELD_FLOAT32 = 7  # sensor_msgs/PointField.FLOAT32

#: OUT's extension -> (rosbags writer, ROS 2 storage plug-in, what it is).
OUTPUT_KINDS = {
    ".bag": ("rosbag1", None, "ROS 1 bag"),
    ".mcap": ("rosbag2", "MCAP", "ROS 2 MCAP file"),
    ".db3": ("rosbag2", "SQLITE3", "ROS 2 sqlite3 file"),
}


class Carmen2BagError(Error):
    """A log that cannot be written as a bag, or an output that cannot be written: ``str()``
    names the file first; ``.file`` is it, ``.usage`` True for a command-line mistake."""

    code = "bad input"

    def __init__(self, file, message: str, usage: bool = False):
        self.file = os.fspath(file)
        self.usage = usage
        super().__init__(f"{self.file}: {message}")


def output_kind(out) -> str:
    """OUT's extension (lower case) if it is one of OUTPUT_KINDS; else a usage error."""
    ext = Path(out).suffix.lower()
    if ext not in OUTPUT_KINDS:
        raise Carmen2BagError(out, "expected a .bag (ROS 1), .mcap or .db3 (ROS 2) name", usage=True)
    return ext


def bag_ranges(ranges: np.ndarray) -> np.ndarray:
    """One scan's float32 ranges as the LaserScan carries them: a reading CARMEN's mapper skips
    (not below 50 m) becomes +inf, NaN stays NaN, every other passes bit for bit."""
    out = np.array(ranges, dtype=np.float32, copy=True)
    out[~(out < CARMEN_RANGE_LIMIT) & ~np.isnan(out)] = np.inf
    return out


def cloud_points(ranges: np.ndarray, first_angle: float, angle_step: float) -> np.ndarray:
    """(k, 3) float32 points of one scan for --cloud, beam by beam: the end point at
    CLOUD_HIT_Z, then a floor and a ceiling point halfway along the beam, for each beam CARMEN
    uses (finite, below 50 m); the angles are CARMEN's, first_angle + i * angle_step."""
    r = np.asarray(ranges, dtype=np.float64)
    used = np.isfinite(r) & (r < CARMEN_RANGE_LIMIT)
    angle = first_angle + np.arange(len(r), dtype=np.float64) * angle_step
    x, y = (r * np.cos(angle))[used], (r * np.sin(angle))[used]
    pts = np.empty((len(x), 3, 3), dtype=np.float64)
    pts[:, 0] = np.stack([x, y, np.full_like(x, CLOUD_HIT_Z)], axis=1)
    pts[:, 1] = np.stack([x / 2, y / 2, np.full_like(x, CLOUD_FLOOR_Z)], axis=1)
    pts[:, 2] = np.stack([x / 2, y / 2, np.full_like(x, CLOUD_CEILING_Z)], axis=1)
    return pts.reshape(-1, 3).astype(np.float32)


def split_stamp(t: float) -> tuple[int, int]:
    """(sec, nanosec) of float64 seconds: sec = floor(t), nanosec rounded, with carry."""
    sec = math.floor(t)
    nanosec = round((t - sec) * 1e9)
    if nanosec >= 1_000_000_000:
        sec, nanosec = sec + 1, nanosec - 1_000_000_000
    return int(sec), int(nanosec)


def scan_stamps(log, path, period: float | None) -> np.ndarray:
    """Each scan's stamp in whole nanoseconds (int64): the log's, or (i + 1) * period. The log's
    must be known, not negative and each a stamp of its own (tf holds one pose per stamp)."""
    n = len(log)
    if period is not None:
        return np.array([sec * 1_000_000_000 + nanosec for sec, nanosec in
                         (split_stamp((i + 1) * period) for i in range(n))], dtype=np.int64)
    lines = log.scans.lines
    stamps = log.stamps
    ns = np.zeros(n, dtype=np.int64)
    seen = {}
    for i, t in enumerate(stamps.tolist()):
        if not (math.isfinite(t) and t >= 0):
            raise Carmen2BagError(path, f"line {int(lines[i])}: a scan without a usable timestamp ({t!r}); "
                                        "--period S gives the scans stamps of their own")
        sec, nanosec = split_stamp(t)
        ns[i] = sec * 1_000_000_000 + nanosec
        if ns[i] in seen:
            raise Carmen2BagError(path, f"line {int(lines[i])}: the scan has the stamp {t!r} of line "
                                        f"{seen[ns[i]]}, and tf holds one pose per stamp; "
                                        "--period S gives the scans stamps of their own")
        seen[ns[i]] = int(lines[i])
    return ns


class _Messages:
    """Messages of one ROS version, built from rosbags' typestore (Noetic or Humble)."""

    def __init__(self, ros1: bool):
        from rosbags.typesys import Stores, get_types_from_msg, get_typestore

        self.ros1 = ros1
        self.store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
        if TF_MESSAGE not in self.store.types:  # the Noetic store lacks tf2_msgs
            self.store.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", TF_MESSAGE))
        self.T = self.store.types
        self.seq = 0

    def serialize(self, msg, msgtype: str) -> bytes:
        return self.store.serialize_ros1(msg, msgtype) if self.ros1 else self.store.serialize_cdr(msg, msgtype)

    def header(self, ns: int, frame: str):
        stamp = self.T["builtin_interfaces/msg/Time"](sec=int(ns // 1_000_000_000), nanosec=int(ns % 1_000_000_000))
        if self.ros1:
            self.seq += 1
            return self.T["std_msgs/msg/Header"](seq=self.seq, stamp=stamp, frame_id=frame)
        return self.T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)

    def tf(self, ns: int, parent: str, child: str, x: float, y: float, yaw: float):
        T = self.T
        transform = T["geometry_msgs/msg/TransformStamped"](
            header=self.header(ns, parent), child_frame_id=child,
            transform=T["geometry_msgs/msg/Transform"](
                translation=T["geometry_msgs/msg/Vector3"](x=float(x), y=float(y), z=0.0),
                rotation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2.0),
                                                          w=math.cos(yaw / 2.0))))
        return T[TF_MESSAGE](transforms=[transform])

    def laser_scan(self, ns: int, ranges: np.ndarray, first_angle: float, angle_step: float):
        n = len(ranges)
        a0, da = np.float32(first_angle), np.float32(angle_step)
        return self.T[LASER_SCAN](
            header=self.header(ns, LASER_FRAME), angle_min=float(a0),
            angle_max=float(a0 + da * np.float32(max(n - 1, 0))), angle_increment=float(da),
            time_increment=0.0, scan_time=0.0, range_min=0.0, range_max=RANGE_MAX,
            ranges=ranges, intensities=np.zeros(0, dtype=np.float32))

    def point_cloud(self, ns: int, points: np.ndarray):
        field = self.T["sensor_msgs/msg/PointField"]
        fields = [field(name=c, offset=4 * k, datatype=POINT_FIELD_FLOAT32, count=1) for k, c in enumerate("xyz")]
        data = np.ascontiguousarray(points, dtype="<f4").view(np.uint8).reshape(-1)
        return self.T[POINT_CLOUD2](
            header=self.header(ns, LASER_FRAME), height=1, width=len(points), fields=fields,
            is_bigendian=False, point_step=12, row_step=12 * len(points), data=data, is_dense=True)


class _Writer:
    """One of rosbags' writers: add a connection once per topic, write serialized messages."""

    def __init__(self, path: Path, ext: str, messages: _Messages):
        kind, plugin, _ = OUTPUT_KINDS[ext]
        self.messages = messages
        if kind == "rosbag1":
            from rosbags.rosbag1 import Writer

            self.writer = Writer(path)
        else:
            from rosbags.rosbag2 import StoragePlugin, Writer

            self.writer = Writer(path, version=8, storage_plugin=getattr(StoragePlugin, plugin))
        self.connections = {}

    def __enter__(self):
        self.writer.open()
        return self

    def __exit__(self, *exc):
        self.writer.close()
        return False

    def write(self, topic: str, msgtype: str, ns: int, msg) -> None:
        if topic not in self.connections:
            extra = {"latching": 1} if self.messages.ros1 and topic == "/tf_static" else {}  # as rosbag record
            self.connections[topic] = self.writer.add_connection(topic, msgtype, typestore=self.messages.store,
                                                                 **extra)
        self.writer.write(self.connections[topic], int(ns), self.messages.serialize(msg, msgtype))


@dataclass
class Written:
    """What write_bag wrote: scans, the topic of the scans (or clouds), the kind of OUT."""

    scans: int
    topic: str
    what: str


def _write_messages(w: _Writer, log, ns: np.ndarray, cloud: bool, topic: str) -> None:
    m = w.messages
    scans = log.scans
    poses = scans.poses
    first = np.asarray(scans.first_angle)
    step = np.asarray(scans.angle_step)
    order = np.argsort(ns, kind="stable")  # a recorder's order: by time
    w.write("/tf_static", TF_MESSAGE, ns[order[0]], m.tf(ns[order[0]], BASE_FRAME, LASER_FRAME, 0.0, 0.0, 0.0))
    for s in order.tolist():
        t = int(ns[s])
        x, y, theta = poses[s].tolist()
        w.write("/tf", TF_MESSAGE, t, m.tf(t, FIXED_FRAME, BASE_FRAME, x, y, theta))
        r = scans.ranges_of(s)
        if cloud:
            w.write(topic, POINT_CLOUD2, t, m.point_cloud(t, cloud_points(r, float(first[s]), float(step[s]))))
        else:
            w.write(topic, LASER_SCAN, t, m.laser_scan(t, bag_ranges(r), float(first[s]), float(step[s])))


def _check_target(out: Path) -> None:
    if out.is_dir():
        raise Carmen2BagError(out, "is a directory: carmen2bag writes one file")
    if out.exists() and not out.is_file():
        raise Carmen2BagError(out, "is not a regular file: it would not be replaced")
    if not out.parent.is_dir():
        raise Carmen2BagError(out, f"cannot be written: no directory {str(out.parent)!r}")


@contextmanager
def _scratch(out: Path, ext: str):
    """The path rosbags' writer makes the bag in, hidden beside out, and the file it makes
    there; every name it may make is registered with the signal clean-up before it is made
    (a ROS 2 writer makes a directory of the storage file, its journal and metadata.yaml),
    and removed when done, whatever happens."""
    from .. import _core

    path = out.parent / f".{out.name}.tmp.{os.getpid()}.{secrets.token_hex(4)}"
    if ext == ".bag":
        made, names = path, [path]
    else:
        made = path / f"{path.name}{ext}"
        names = [path, made, path / f"{path.name}{ext}-journal", path / "metadata.yaml"]
    registered = [_core._TemporaryOnSignal(p) for p in names]
    try:
        yield path, made
    finally:
        if path.is_dir():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink(missing_ok=True)
        for r in registered:
            r.release()


def _commit_copy(made: Path, out: Path) -> None:
    """made's bytes as out, through the output transaction (whole or not at all)."""
    from .. import _core

    target = _core._OutputFile(out)
    try:
        with os.fdopen(target.take_fd(), "wb") as dst, made.open("rb") as src:
            shutil.copyfileobj(src, dst, 1 << 20)
        target.commit()
    finally:
        target.abandon()


def write_bag(log, out, *, log_path="log", cloud: bool = False, period: float | None = None,
              topic: str | None = None) -> Written:
    """Writes `log` (a :class:`vasco_gpu.Log`) as a bag at `out` (its extension decides the
    format, OUTPUT_KINDS), whole or not at all. Raises Carmen2BagError naming the file."""
    out = Path(out)
    ext = output_kind(out)
    if len(log) == 0:
        raise Carmen2BagError(log_path, "has no scans (FLASER or ROBOTLASER1 lines) to write")
    ns = scan_stamps(log, log_path, period)
    topic = topic or (CLOUD_TOPIC if cloud else SCAN_TOPIC)
    _check_target(out)
    try:
        with _scratch(out, ext) as (path, made):
            with _Writer(path, ext, _Messages(ros1=ext == ".bag")) as w:
                _write_messages(w, log, ns, cloud, topic)
            if not made.is_file():
                raise Carmen2BagError(out, f"cannot be written: the bag writer made no {ext} file")
            _commit_copy(made, out)
    except Carmen2BagError:
        raise
    except OSError as e:
        raise Carmen2BagError(out, f"cannot be written: {e.strerror or e}") from e
    except Exception as e:  # rosbags' writers raise their own errors, the transaction FileError: said as this output's
        raise Carmen2BagError(out, f"cannot be written: {e}") from e
    return Written(len(log), topic, OUTPUT_KINDS[ext][2])
