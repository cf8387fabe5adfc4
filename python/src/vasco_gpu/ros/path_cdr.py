"""nav_msgs/Path read straight from its serialized bytes (CDR, little-endian) into arrays.

Why: rclpy turns a Path into one Python object per field of every pose (six objects a
PoseStamped), ~60 ms for fr079's 4,791 poses on a 2-core machine, more than the GPU's whole
re-render; the node subscribes to the bytes instead (``raw=True``) and reads them in one C++
pass (python/src/path_cdr.cc, the layout there). A Path whose poses are in several frames, or
big-endian, or of another encoding, takes the general route, rclpy's own deserialisation, so
no Path is refused for its layout.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core

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


def _stamp(sec: int, nanosec: int) -> int:
    return sec * 1_000_000_000 + nanosec


def _fast(buf: bytes) -> PathArrays:
    """The bytes read in C++ (_core._path_from_cdr); ValueError for a layout it leaves to rclpy."""
    got = _core._path_from_cdr(bytes(buf))
    if got is None:
        raise ValueError("not a little-endian CDR Path with one frame_id for its poses")
    frame, stamp_ns, pose_frame, stamps, positions, orientations = got
    frames = [pose_frame] * len(stamps)
    return PathArrays(frame, stamp_ns, stamps, frames, positions, orientations, frozenset(frames[:1]))


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
        except ValueError:
            pass
    if path_type is None:
        raise ValueError("not a little-endian CDR nav_msgs/Path")
    try:
        return _general(buf, path_type)
    except Exception as e:  # rclpy's deserialisation errors have no common base
        raise ValueError(f"not a nav_msgs/Path ({e})") from None
