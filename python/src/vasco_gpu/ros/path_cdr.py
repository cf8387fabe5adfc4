"""nav_msgs/Path read straight from its serialized bytes (CDR, little-endian) into arrays.

Why: rclpy turns a Path into one Python object per field of every pose (six objects a
PoseStamped), ~60 ms for fr079's 4,791 poses on a 2-core machine, more than the GPU's whole
re-render; the node subscribes to the bytes instead (``raw=True``) and reads them here in well
under a millisecond. The layout (XCDR1, the ROS 2 default): a 4-byte encapsulation header, then
the Path's header {int32 sec, uint32 nanosec, string frame_id}, uint32 pose count, and per
PoseStamped {int32 sec, uint32 nanosec, string frame_id, 3 + 4 float64}, each primitive aligned
to its size from the end of the encapsulation header, a string as uint32 length (with its NUL)
and its bytes. Every pose after the first starts 8-aligned (it follows a float64), so poses whose
frame_id has one length share one stride: read as one NumPy record array. Anything else (other
frame_id lengths, big-endian, another encoding) takes the general route, rclpy's own
deserialisation, so no Path is refused for its layout.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

__all__ = ["PathArrays", "read_path"]

CDR_LE = b"\x00\x01"


@dataclass
class PathArrays:
    """A Path as arrays: the Path's frame and stamp, each pose's stamp (ns), frame_id, position
    (k, 3) and orientation (k, 4, x y z w); distinct_frames: the poses' frame_ids, once each
    (a set of 4,791 strings costs a live node most of a millisecond; the fast route knows it)."""

    frame_id: str
    stamp_ns: int
    stamps: np.ndarray
    frame_ids: list
    positions: np.ndarray
    orientations: np.ndarray
    distinct_frames: frozenset


def _align(offset: int, size: int) -> int:
    return (offset + size - 1) // size * size


class _Reader:
    """Primitive reads at CDR alignment (offsets relative to the end of the 4-byte header)."""

    def __init__(self, buf: bytes):
        self.buf, self.pos = buf, 0

    def _at(self, size: int) -> int:
        self.pos = _align(self.pos, size)
        at = self.pos + 4
        if at + size > len(self.buf):
            raise ValueError("truncated")
        self.pos += size
        return at

    def u32(self) -> int:
        return struct.unpack_from("<I", self.buf, self._at(4))[0]

    def i32(self) -> int:
        return struct.unpack_from("<i", self.buf, self._at(4))[0]

    def string(self) -> str:
        n = self.u32()
        at = self.pos + 4
        if n == 0 or at + n > len(self.buf):
            raise ValueError("bad string")
        self.pos += n
        return self.buf[at:at + n - 1].decode("utf-8", "replace")

    def f64(self, count: int) -> tuple:
        at = self._at(8)
        self.pos += 8 * (count - 1)
        if at + 8 * count > len(self.buf):
            raise ValueError("truncated")
        return struct.unpack_from(f"<{count}d", self.buf, at)


def _stamp(sec: int, nanosec: int) -> int:
    return sec * 1_000_000_000 + nanosec


def _fast(buf: bytes) -> PathArrays:
    r = _Reader(buf)
    sec, nsec = r.i32(), r.u32()
    frame = r.string()
    k = r.u32()
    stamps = np.empty(k, dtype=np.int64)
    pos, quat, frames = np.empty((k, 3)), np.empty((k, 4)), [None] * k
    if k == 0:
        return PathArrays(frame, _stamp(sec, nsec), stamps, [], pos, quat, frozenset())
    ps, pn = r.i32(), r.u32()  # the first pose, read field by field (its padding may differ)
    frames[0] = r.string()
    values = r.f64(7)
    stamps[0], pos[0], quat[0] = _stamp(ps, pn), values[:3], values[3:]
    if k > 1:
        n = len(frames[0].encode()) + 1
        doubles = _align(12 + n, 8)
        rec = np.dtype({"names": ["sec", "nsec", "len", "frame", "v"],
                        "formats": ["<i4", "<u4", "<u4", f"S{n}", ("<f8", 7)],
                        "offsets": [0, 4, 8, 12, doubles], "itemsize": doubles + 56})
        start = 4 + r.pos
        if start % 8 != 4 % 8 or start + rec.itemsize * (k - 1) > len(buf):  # 8-aligned from the header's end
            raise ValueError("layout")
        a = np.frombuffer(buf, dtype=rec, count=k - 1, offset=start)
        if not ((a["len"] == n).all() and (a["frame"] == frames[0].encode()).all()):
            raise ValueError("frame ids differ")
        stamps[1:] = a["sec"].astype(np.int64) * 1_000_000_000 + a["nsec"]
        pos[1:], quat[1:] = a["v"][:, :3], a["v"][:, 3:]
        frames[1:] = [frames[0]] * (k - 1)
    return PathArrays(frame, _stamp(sec, nsec), stamps, frames, pos, quat, frozenset(frames[:1]))


def _general(buf: bytes, path_type) -> PathArrays:
    from rclpy.serialization import deserialize_message

    msg = deserialize_message(buf, path_type)
    k = len(msg.poses)
    stamps = np.array([_stamp(p.header.stamp.sec, p.header.stamp.nanosec) for p in msg.poses], dtype=np.int64)
    pos = np.array([(p.pose.position.x, p.pose.position.y, p.pose.position.z) for p in msg.poses]).reshape(k, 3)
    quat = np.array([(p.pose.orientation.x, p.pose.orientation.y, p.pose.orientation.z, p.pose.orientation.w)
                     for p in msg.poses]).reshape(k, 4)
    frames = [p.header.frame_id for p in msg.poses]
    return PathArrays(msg.header.frame_id, _stamp(msg.header.stamp.sec, msg.header.stamp.nanosec), stamps,
                      frames, pos, quat, frozenset(frames))


def read_path(buf: bytes, path_type=None) -> PathArrays:
    """A serialized nav_msgs/Path as arrays; path_type (nav_msgs.msg.Path) deserialises what the
    fast reader does not take. ValueError for bytes that are not a Path."""
    if buf[:2] == CDR_LE:
        try:
            return _fast(buf)
        except (ValueError, struct.error):
            pass
    if path_type is None:
        raise ValueError("not a little-endian CDR nav_msgs/Path")
    try:
        return _general(buf, path_type)
    except Exception as e:  # rclpy's deserialisation errors have no common base
        raise ValueError(f"not a nav_msgs/Path ({e})") from None
