"""Rigid transforms as the reader needs them: 3-D ones as a translation (n, 3) and a quaternion
(n, 4) stored x, y, z, w in float64 (composition, inverse, slerp, yaw), and planar poses
(x, y, yaw: composition with a laser mount and its inverse)."""

from __future__ import annotations

import math

import numpy as np

from .errors import BagError

QUAT_TOL = 1e-9  # |q| - 1 beyond this: the quaternion is renormalised


def wrap_angle(a):
    """a wrapped into [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


# ----------------------------------------------------------------------------------------------
# 3-D: translation (n, 3) and quaternion (n, 4) as x, y, z, w, float64


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a * b of quaternions (..., 4) stored x, y, z, w."""
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz], axis=-1)


def quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v (..., 3) rotated by unit quaternions q (..., 4): v + w t + u x t with t = 2 u x v."""
    u, w = q[..., :3], q[..., 3:4]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def compose(a, b):
    """a * b for transforms (t, q): first b, then a (T_x_z = T_x_y * T_y_z)."""
    ta, qa = a
    tb, qb = b
    return ta + quat_rotate(qa, tb), quat_mul(qa, qb)


def inverse(a):
    """The inverse of transforms (t, q)."""
    t, q = a
    qi = q * np.array([-1.0, -1.0, -1.0, 1.0])
    return -quat_rotate(qi, t), qi


def yaw(q: np.ndarray) -> np.ndarray:
    """Yaw of quaternions (..., 4): atan2(2(w z + x y), 1 - 2(y^2 + z^2))."""
    x, y, z, w = np.moveaxis(q, -1, 0)
    return np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def slerp(q0: np.ndarray, q1: np.ndarray, f: np.ndarray) -> np.ndarray:
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


def is_identity(t: np.ndarray, q: np.ndarray) -> bool:
    """True for a transform with translation exactly 0 and rotation exactly (0, 0, 0, +-1)."""
    return not t.any() and not q[:3].any() and abs(q[3]) == 1.0


def unit_quaternion(q, what, path, error: type[BagError] = BagError) -> np.ndarray:
    """q as a float64 unit quaternion: untouched when within 1e-9 of unit length (exactness),
    renormalised otherwise; a zero or non-finite quaternion is an `error` (a BagError) naming
    `what` (a string, or a function giving it: made only for the error)."""
    q = np.asarray(q, dtype=np.float64)
    n = math.sqrt(float(np.dot(q, q)))
    if not math.isfinite(n) or n < 1e-6:
        raise error(path, f"{what() if callable(what) else what} has an invalid rotation quaternion "
                          f"{tuple(q.tolist())}")
    return q if abs(n - 1.0) <= QUAT_TOL else q / n


def planar(path, t: np.ndarray, q: np.ndarray, what: str) -> np.ndarray:
    """(n, 3) x, y, yaw of 3-D transforms; a laser upside down (its z axis pointing down, which
    would mirror the scans in the plane) is a BagError."""
    zz = 1.0 - 2.0 * (q[:, 0] ** 2 + q[:, 1] ** 2)  # z component of the rotated z axis
    if (zz < 0).any():
        raise BagError(path, f"{what} is upside down (its z axis points down): mirrored scans are not "
                             "supported")
    return np.column_stack([t[:, 0], t[:, 1], yaw(q)])


# ----------------------------------------------------------------------------------------------
# Planar poses (n, 3): x, y, yaw


def planar_compose(base: np.ndarray, mount: np.ndarray) -> np.ndarray:
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


def planar_uncompose(laser: np.ndarray, mount: np.ndarray) -> np.ndarray:
    """Robot poses r with r o mount = laser; the laser poses unchanged when the mount is 0."""
    mount = np.broadcast_to(np.asarray(mount, dtype=np.float64), laser.shape)
    out = laser.copy()
    moved = mount.any(axis=1)
    if moved.any():
        l, m = laser[moved], mount[moved]
        theta = l[:, 2] - m[:, 2]
        theta = np.where(np.abs(theta) > np.pi, wrap_angle(theta), theta)
        c, s = np.cos(theta), np.sin(theta)
        out[moved] = np.column_stack([l[:, 0] - c * m[:, 0] + s * m[:, 1],
                                      l[:, 1] - s * m[:, 0] - c * m[:, 1],
                                      theta])
    return out


def check_mount(laser_mount, what: str = "laser_mount") -> np.ndarray | None:
    """laser_mount (or another planar pose, named what) as a float64 (3,) array of finite x, y,
    yaw, or None; else ValueError."""
    if laser_mount is None:
        return None
    m = np.asarray(laser_mount, dtype=np.float64)
    if m.shape != (3,) or not np.isfinite(m).all():
        raise ValueError(f"{what} must be three finite numbers x, y, yaw, not {laser_mount!r}")
    return m
