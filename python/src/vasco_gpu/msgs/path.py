"""nav_msgs/Path as the robot's poses: a Path read into arrays (the node's ``path_cdr``) checked
and turned into planar base poses. A Path in another frame than the map's, a pose in another
frame, or a pose that is not a number is refused whole: the node keeps its scans where they are."""

from __future__ import annotations

import numpy as np

from .geometry import QUAT_TOL, yaw
from .header import frame_name, stamp_text
from .tf import MAX_TRANSLATION

__all__ = ["path_poses"]


def path_poses(path, want: str, topic: str, fail):
    """(stamps (k,) int64 ns, base poses (k, 3)) of a Path read as arrays (frame_id, stamp_ns,
    stamps, frame_ids, distinct_frames, positions, orientations) whose poses must be in frame
    want. fail(text, cause) gives the exception to raise, text naming topic and the stamp."""
    frame = frame_name(path.frame_id)
    if frame != want:
        raise fail(f"{topic}: Path at stamp {stamp_text(path.stamp_ns)} is in frame {frame!r}, not "
                   f"map_frame {want!r}", "paths in another frame")
    # the distinct frame_ids first (a Path's are nearly always one): a loop over every pose's
    # cost ~1 ms for fr079's 4,791
    if any(f and frame_name(f) != want for f in path.distinct_frames):
        k = next(k for k, f in enumerate(path.frame_ids) if f and frame_name(f) != want)
        raise fail(f"{topic}: pose {k} (stamp {stamp_text(int(path.stamps[k]))}) is in frame "
                   f"{frame_name(path.frame_ids[k])!r}, not {want!r}", "paths in another frame")
    pos, q = path.positions, path.orientations
    x, y, z, w = q.T  # a sum over rows of 4 is NumPy's slow reduction (0.07 ms here, 0.01 by columns)
    norm = np.sqrt(x * x + y * y + z * z + w * w)
    # whole-array checks first, the rows only for a refusal: every NumPy call costs a Path
    # in a live node several times what it costs in a loop
    if not (np.isfinite(pos).all() and np.isfinite(norm).all() and norm.min(initial=1.0) >= 1e-6):
        k = int(np.argmax(~np.isfinite(pos).all(axis=1) | ~np.isfinite(norm) | (norm < 1e-6)))
        raise fail(f"{topic}: pose {k} (stamp {stamp_text(int(path.stamps[k]))}) has position "
                   f"{tuple(pos[k].tolist())}, orientation {tuple(q[k].tolist())}", "paths with a bad pose")
    # the tf tree's bound: beyond it a double's cell lattice is coarser than the map's cells,
    # and a map's origin can overflow to inf in the files written
    if np.abs(pos[:, :2]).max(initial=0.0) > MAX_TRANSLATION:
        k = int(np.argmax(np.abs(pos[:, :2]).max(axis=1) > MAX_TRANSLATION))
        raise fail(f"{topic}: pose {k} (stamp {stamp_text(int(path.stamps[k]))}) has position "
                   f"{tuple(pos[k].tolist())}, beyond {MAX_TRANSLATION:g} m", "paths with a bad pose")
    _distinct_stamps(path.stamps, topic, fail)
    off = np.abs(norm - 1.0) > QUAT_TOL
    if off.any():
        q = np.where(off[:, None], q / norm[:, None], q)
    poses = np.empty((len(q), 3))
    poses[:, :2], poses[:, 2] = pos[:, :2], yaw(q)
    return path.stamps, poses


def _distinct_stamps(stamps: np.ndarray, topic: str, fail) -> None:
    """Refuses a Path with two poses at one stamp: which one a scan at that stamp takes would be
    a guess (the Path's order is not a time order)."""
    if len(stamps) < 2 or (np.diff(stamps) > 0).all():  # a Path in time order: nothing to sort
        return
    order = np.argsort(stamps, kind="stable")
    same = np.flatnonzero(np.diff(stamps[order]) == 0)
    if len(same):
        a, b = sorted((int(order[same[0]]), int(order[same[0] + 1])))
        raise fail(f"{topic}: poses {a} and {b} of the Path have one stamp, {stamp_text(int(stamps[a]))}: which "
                   f"one a scan there takes would be a guess", "paths with a repeated stamp")
