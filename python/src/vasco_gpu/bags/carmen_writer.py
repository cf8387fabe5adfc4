""":func:`write_carmen_log`: a bag's scans and poses (BagScans) as a CARMEN log of ROBOTLASER1
lines, numbers written to read back exactly (bag2carmen)."""

from __future__ import annotations

import math
import os
import re
from contextlib import contextmanager

import numpy as np

from ..msgs.geometry import planar_uncompose
from .scans import BagScans

__all__ = ["write_carmen_log"]


def _double_text(v: float) -> str:
    """A double as the shortest text that reads back to it (repr: locale independent)."""
    return repr(float(v))


def range_texts(r: np.ndarray) -> list[str]:
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


# maximum_range where a scan's range_max is not finite and no reading of its topic is as far:
# what CARMEN takes for a laser whose log line states no range (an old FLASER line; the SICK LMS
# of CARMEN's logs reaches about 80 m).
CARMEN_MAX_RANGE = 80.0


def _max_ranges(scans: BagScans) -> np.ndarray:
    """The maximum_range field of each scan: its range_max where finite (50.0 without any).

    REP 117 lets a driver give range_max = +inf: it knows no limit, and every finite reading is
    a measurement. CARMEN's maximum_range must be a finite number (log2map and CARMEN's readers
    refuse "inf"), and CARMEN's programs that use it (localize, its mappers) take a reading at or
    beyond it for a max-range reading, not a hit. So an infinite (or NaN) range_max becomes the
    whole metre above the largest finite reading of the scan's topic in the bag, and at least
    CARMEN_MAX_RANGE: no measurement turns into a max-range reading, a +inf reading (no return)
    stays one, and a topic whose readings are all short does not claim a short-range device."""
    n = len(scans.stamps)
    if scans.range_max is None:
        return np.full(n, 50.0)
    out = np.asarray(scans.range_max, dtype=np.float64).copy()
    unbounded = ~np.isfinite(out)
    if not unbounded.any():
        return out
    topic = np.zeros(n, np.int64) if scans.topic_index is None else np.asarray(scans.topic_index, np.int64)
    beam_topic = np.repeat(topic, scans.beam_counts)
    for k in np.unique(topic[unbounded]):
        r = scans.ranges[(beam_topic == k) & np.isfinite(scans.ranges)]
        out[unbounded & (topic == k)] = _above(float(r.max())) if r.size else CARMEN_MAX_RANGE
    return out


def _above(largest: float) -> float:
    """The whole metre above a reading, at least CARMEN_MAX_RANGE (and above it even where a
    float64 has no whole metres: a reading beyond 2^53 m)."""
    return max(CARMEN_MAX_RANGE, math.floor(largest) + 1.0, math.nextafter(largest, math.inf))


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
        return planar_uncompose(np.asarray(scans.poses, dtype=np.float64), scans.mounts)
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


def _robotlaser_line(scans: BagScans, s: int, ranges: np.ndarray, robot: np.ndarray, max_range: float) -> str:
    """The ROBOTLASER1 line of scan s (fields as in carmen-formats.md section 1.2)."""
    n = int(scans.beam_counts[s])
    step = float(scans.angle_step[s])
    stamp = _double_text(scans.stamps[s])
    lx, ly, lt = (float(v) for v in scans.poses[s])
    config = [_double_text(scans.first_angle[s]), _double_text(step * (n - 1) if n else 0.0),
              _double_text(step), _double_text(max_range), "0.01", "0"]
    fields = ["ROBOTLASER1", "99", *config, str(n), *range_texts(ranges), "0",
              _double_text(lx), _double_text(ly), _double_text(lt), *(_double_text(v) for v in robot),
              "0.0", "0.0", "0.0", "0.0", "1000000.0", stamp, "bag", stamp]
    return " ".join(fields) + "\n"


def write_carmen_log(scans: BagScans, out, robot_poses=None) -> None:
    """Writes scans as a CARMEN log: a '#' header line, then one ROBOTLASER1 line per scan.

    Field choices: laser_type 99 (unknown), start_angle = first_angle, fov = angle_step * (n-1),
    angular_res = angle_step; max_range = the scan's msg.range_max (the device's maximum range,
    which is what the field means in CARMEN; 50.0, the mapper's limit, when BagScans has no
    range_max; an infinite one above every reading of its topic, as :func:`_max_ranges` argues)
    — the mapper ignores the field and uses its own range limits; accuracy 0.01 (the
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
    max_ranges = _max_ranges(scans)
    offsets = np.concatenate([[0], np.cumsum(scans.beam_counts)])
    # one ASCII line whatever the bag's name: CARMEN logs are ASCII, and out may be an ASCII stream
    source = re.sub(r"[\r\n]", " ", f"{scans.path} topic {scans.topic}")
    source = source.encode("ascii", "backslashreplace").decode("ascii")
    with _text_out(out) as f:
        f.write(f"# written by vasco_gpu bag2carmen from {source}\n")
        for s in range(n):
            ranges = scans.ranges[offsets[s]:offsets[s + 1]]
            f.write(_robotlaser_line(scans, s, ranges, robots[s], float(max_ranges[s])))
