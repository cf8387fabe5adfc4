"""sensor_msgs/PointCloud2 as a planar scan: the 3-D lidar's points in a height band become
beams from the sensor's origin, one per angle bin, as pointcloud_to_laserscan makes them. The
one adapter of bags and the live node (beside :mod:`.laser` for LaserScans).

What a cloud's beam means
-------------------------
A bin's beam is the nearest point of the band in it (the range in the sensor's xy plane): a hit,
and free space up to it, as a LaserScan beam. A bin with no point in the band is "no return"
(+inf), which ``no_return`` decides as for LaserScans: skipped (the default), or free up to
``cloud_range_max`` — only for a sensor that truly sees nothing there (open space), never for
one whose returns the band or the range left out. Points beyond ``cloud_range_max`` count as no
return; NaN points are skipped. Bin k is centred on ``-pi + k * angle_step`` (a point exactly on
a centre stays in its bin whatever the rounding), so a cloud made of a LaserScan's beam ends at
the same angles gives that LaserScan back.

The band is in the base frame (the floor and the ceiling out): each point goes through the
sensor's mount (its static transform in the base frame) before its height is compared; the
beams are then taken in the sensor's own frame, whose planar pose the scan gets.
"""

from __future__ import annotations

import math

import numpy as np

from .header import frame_name
from .laser import LaserReading, apply_rep117
from .scan_options import SCAN_DEFAULTS, ScanSettings

__all__ = ["cloud_mount", "cloud_points_xyz", "read_cloud", "read_point_cloud"]

_FLOAT32, _FLOAT64 = 7, 8  # sensor_msgs/PointField datatypes


def cloud_mount(tf, base: str, frame: str):
    """The cloud frame's transform in the base frame, (t (3,), q (4,)), from static tf links
    (read_cloud's mount); None when the cloud is in the base frame. A TfError when tf has no
    static chain between them."""
    if frame == base:
        return None
    t, q = tf.lookup(base, frame, np.zeros(1, dtype=np.int64), static_only=True)
    return t[0], q[0]


def cloud_points_xyz(msg, fail) -> np.ndarray:
    """(n, 3) float64 x, y, z of a PointCloud2's points (organised or not, any point layout with
    float32 or float64 x, y and z fields), NaN points kept. fail(what) gives the error to raise."""
    fields = {f.name: f for f in msg.fields}
    missing = [n for n in "xyz" if n not in fields]
    if missing:
        raise fail(f"has no field {missing[0]!r} (fields: {', '.join(fields) or 'none'})")
    order = ">" if msg.is_bigendian else "<"
    formats = []
    for n in "xyz":
        kind = {_FLOAT32: "f4", _FLOAT64: "f8"}.get(int(fields[n].datatype))
        if kind is None:
            raise fail(f"field {n!r} has datatype {fields[n].datatype}, not float32 (7) or float64 (8)")
        formats.append(order + kind)
    width, height, step, row = int(msg.width), int(msg.height), int(msg.point_step), int(msg.row_step)
    data = bytes(msg.data) if not isinstance(msg.data, (bytes, np.ndarray)) else msg.data
    data = np.frombuffer(data, dtype=np.uint8) if not isinstance(data, np.ndarray) else data.view(np.uint8)
    size = max(int(fields[n].offset) + int(formats[i][2]) for i, n in enumerate("xyz"))
    if width * height == 0:  # no point: no layout to read (a point_step past NumPy's int limit included)
        return np.empty((0, 3))
    if step < size or row < width * step or len(data) < height * row:
        raise fail(f"has {len(data)} bytes for {height} rows of {row} bytes, {width} points of {step} "
                   f"bytes (x, y, z need {size})")
    dtype = np.dtype({"names": list("xyz"), "formats": formats,
                      "offsets": [int(fields[n].offset) for n in "xyz"], "itemsize": step})
    rows = data[:height * row].reshape(height, row)[:, :width * step]
    pts = np.ascontiguousarray(rows).view(dtype).reshape(-1)
    return np.column_stack([pts["x"], pts["y"], pts["z"]]).astype(np.float64)


def read_cloud(msg, *, no_return: str, counts: dict, fail, z_band=SCAN_DEFAULTS["z_band"],
               angle_step: float = math.radians(SCAN_DEFAULTS["cloud_angle_step"]),
               range_max: float = SCAN_DEFAULTS["cloud_range_max"], mount=None) -> LaserReading:
    """A PointCloud2 as a LaserReading (module docstring); angle_step in radians. mount: (t (3,), q (4,)) of the
    cloud's frame in the base frame (None: the cloud is in the base frame). counts: read_laser's
    COUNT_KEYS, plus ``points`` (in the band and range), ``bins_empty`` and the heights seen
    (:func:`_count_heights`)."""
    p = cloud_points_xyz(msg, fail)
    finite = np.isfinite(p).all(axis=1)
    z = p[:, 2]
    if mount is not None:
        t, q = mount
        x, y, w = q[0], q[1], q[3]
        # z of R(q) p + t: the third row of the rotation matrix
        z = (2 * (q[0] * q[2] - w * q[1])) * p[:, 0] + (2 * (q[1] * q[2] + w * q[0])) * p[:, 1] + \
            (1 - 2 * (x * x + y * y)) * p[:, 2] + t[2]
    r = np.hypot(p[:, 0], p[:, 1])
    in_band = finite & (z >= z_band[0]) & (z <= z_band[1])
    _count_heights(counts, z[finite], int(in_band.sum()))
    keep = in_band & (r > 0) & (r <= range_max)
    n = int(round(2 * math.pi / angle_step))
    a0 = -math.pi
    k = np.floor((np.arctan2(p[keep, 1], p[keep, 0]) - a0) / angle_step + 0.5).astype(np.int64) % n
    ranges = np.full(n, np.inf)
    np.minimum.at(ranges, k, r[keep])
    counts["points"] = counts.get("points", 0) + int(keep.sum())
    counts["bins_empty"] = counts.get("bins_empty", 0) + int(np.isinf(ranges).sum())
    out = apply_rep117(ranges.astype(np.float32), 0.0, float(np.float32(range_max)), no_return, counts)
    counts["messages"] += 1
    return LaserReading(frame_name(msg.header.frame_id), a0, angle_step, float(range_max), out)


def _count_heights(counts: dict, z: np.ndarray, in_band: int) -> None:
    """The heights seen, for the error of a band that keeps no point: counts' ``points_seen``
    (finite points), ``points_in_band``, ``z_min`` and ``z_max`` (in the base frame)."""
    counts["points_seen"] = counts.get("points_seen", 0) + len(z)
    counts["points_in_band"] = counts.get("points_in_band", 0) + in_band
    if len(z):
        counts["z_min"] = min(counts.get("z_min", math.inf), float(z.min()))
        counts["z_max"] = max(counts.get("z_max", -math.inf), float(z.max()))


def read_point_cloud(msg, settings: ScanSettings, counts: dict, fail, mount=None) -> LaserReading:
    """The message table's reader of a PointCloud2 (table.py); options: no_return, z_band,
    cloud_angle_step, cloud_range_max."""
    return read_cloud(msg, no_return=settings.no_return, counts=counts, fail=fail,
                      z_band=tuple(float(v) for v in settings.z_band), angle_step=settings.angle_step,
                      range_max=float(settings.cloud_range_max), mount=mount)
