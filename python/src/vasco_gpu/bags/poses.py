"""The laser pose at each scan's stamp: from tf (the chain fixed frame -> scan frame), or from a
pose topic's base poses (PoseSeries) and the laser mount, or none (a pose file follows)."""

from __future__ import annotations

from array import array

import numpy as np

from ..msgs.errors import BagError
from ..msgs.geometry import planar, planar_compose, unit_quaternion, wrap_angle, yaw
from ..msgs.header import frame_name, stamp_ns, stamp_seconds, stamp_text
from ..msgs.series import bracket, first_outside, sorted_samples
from ..msgs.tf import MAX_TRANSLATION, TfBuffer, static_mount
from .errors import words


class PoseSeries:
    """Base poses from a pose topic: stamps, (x, y, yaw), the frame and the base frame."""

    def __init__(self, path, topic: str, msgtype: str, fixed_frame: str | None, base_frame: str | None):
        self.path, self.topic, self.msgtype = path, topic, msgtype
        self.fixed_frame = fixed_frame
        self.base_frame = base_frame
        self.ns = array("q")
        self.values = array("d")

    def add(self, msg, receive_ns: int | None = None) -> None:
        if self.msgtype == "nav_msgs/msg/Path":
            self._add_path(msg)
            return
        ns = stamp_ns(msg.header.stamp)
        frame = self._fixed(msg, ns, "pose")
        if self.msgtype == "nav_msgs/msg/Odometry":
            self._check_child(frame_name(msg.child_frame_id), ns)
        pose = msg.pose if self.msgtype == "geometry_msgs/msg/PoseStamped" else msg.pose.pose
        o = pose.orientation
        what = f"pose on {self.topic!r} at stamp {stamp_text(ns)}"
        self._check_position(pose.position, what, ns)
        q = unit_quaternion((o.x, o.y, o.z, o.w), what, self.path)
        self.ns.append(ns)
        self.values.extend((float(pose.position.x), float(pose.position.y), float(yaw(q))))

    def _check_position(self, p, what: str, ns: int) -> None:
        """A position within tf's bound on a translation, as a tf link's must be: NaN, inf and
        1e300 m would give the map an origin no map file can hold."""
        if not all(abs(float(v)) <= MAX_TRANSLATION for v in (p.x, p.y, p.z)):  # NaN too
            raise BagError(self.path, f"{what} has position ({p.x}, {p.y}, {p.z}): not a finite number of metres "
                                      f"up to {MAX_TRANSLATION:g}", topic=self.topic, stamp=stamp_seconds(ns))

    def _fixed(self, msg, ns: int, what: str) -> str:
        """The message's frame, which must be the fixed frame (the first message's when None)."""
        frame = frame_name(msg.header.frame_id)
        if self.fixed_frame is None:
            self.fixed_frame = frame
        elif frame != self.fixed_frame:
            raise BagError(self.path, f"{what} on {self.topic!r} at stamp {stamp_text(ns)} is in frame "
                                      f"{frame!r}, not the fixed frame {self.fixed_frame!r} (pass "
                                      f"fixed_frame={frame!r}, or None to accept the topic's frame)",
                           topic=self.topic, stamp=stamp_seconds(ns))
        return frame

    def _add_path(self, msg) -> None:
        """A nav_msgs/Path: its poses replace the ones before (a LIO or SLAM back end republishes
        its whole trajectory, so the bag's last Path is the final one)."""
        ns = stamp_ns(msg.header.stamp)
        frame = self._fixed(msg, ns, "Path")
        del self.ns[:], self.values[:]
        for k, ps in enumerate(msg.poses):
            pns = stamp_ns(ps.header.stamp)
            if ps.header.frame_id and frame_name(ps.header.frame_id) != frame:
                raise BagError(self.path, f"Path on {self.topic!r} at stamp {stamp_text(ns)}: pose {k} is in "
                                          f"frame {frame_name(ps.header.frame_id)!r}, not {frame!r}",
                               topic=self.topic, stamp=stamp_seconds(pns))
            o = ps.pose.orientation
            what = f"pose {k} of the Path on {self.topic!r} at stamp {stamp_text(ns)}"
            self._check_position(ps.pose.position, what, pns)
            q = unit_quaternion((o.x, o.y, o.z, o.w), what, self.path)
            self.ns.append(pns)
            self.values.extend((float(ps.pose.position.x), float(ps.pose.position.y), float(yaw(q))))

    def _check_child(self, child: str, ns: int) -> None:
        """Odometry's child_frame_id is the base frame; it must agree with base_frame if given."""
        if not child:
            return
        if self.base_frame is None:
            self.base_frame = child
        elif child != self.base_frame:
            raise BagError(self.path, f"odometry on {self.topic!r} at stamp {stamp_text(ns)} has "
                                      f"child_frame_id {child!r}, not the base frame {self.base_frame!r}",
                           topic=self.topic, stamp=stamp_seconds(ns))

    def span(self):
        """(first, last) stamp of the topic's poses in whole nanoseconds; None without any."""
        if not self.ns:
            return None
        times, _ = sorted_samples(self.ns, self.values, 3)
        return int(times[0]), int(times[-1])

    def at(self, ns: np.ndarray) -> np.ndarray:
        """(n, 3) base poses at stamps ns: samples on exact hits, else linear x, y and shortest-arc
        yaw between the bracketing samples; a stamp outside the topic's span is a BagError."""
        if not self.ns:
            raise BagError(self.path, f"pose topic {self.topic!r} has no messages", topic=self.topic)
        times, vals = sorted_samples(self.ns, self.values, 3)
        bad = first_outside(times, ns)
        if bad is not None:
            raise BagError(self.path, f"scan stamp {stamp_text(bad)} is outside the time span "
                                      f"[{stamp_text(times[0])}, {stamp_text(times[-1])}] of pose topic "
                                      f"{self.topic!r} (skip_unposed / --skip-unposed leaves such scans out)",
                           topic=self.topic, stamp=stamp_seconds(bad))
        return planar_at(times, vals, ns)


def planar_at(times: np.ndarray, vals: np.ndarray, ns: np.ndarray) -> np.ndarray:
    """(n, 3) planar poses at stamps ns (within the span of the sorted samples times, vals):
    the sample on an exact hit, else linear x, y and shortest-arc yaw between the bracketing
    samples: the --poses rule, which log2map and the live node's Path take from
    vasco_gpu/pose_series.h (this package does not load the compiled extension)."""
    hit, i, lo, hi, f = bracket(times, ns)
    out = vals[i]  # exact hits: the sample unchanged (a SLAM Path's poses are often at the scans' stamps)
    miss = ~hit
    if miss.any():
        a, b, f = vals[lo[miss]], vals[hi[miss]], f[miss]
        between = np.empty((len(f), 3))
        between[:, :2] = a[:, :2] + (b[:, :2] - a[:, :2]) * f[:, None]
        between[:, 2] = a[:, 2] + wrap_angle(b[:, 2] - a[:, 2]) * f
        out[miss] = between
    return out


def _inside(ns: np.ndarray, inside: np.ndarray | None, pose_at) -> np.ndarray:
    """pose_at(ns) where inside (all when None), NaN rows elsewhere."""
    if inside is None:
        return pose_at(ns)
    poses = np.full((len(ns), 3), np.nan)
    if inside.any():
        poses[inside] = pose_at(ns[inside])
    return poses


def _edges(ns: np.ndarray, span) -> dict | None:
    """The scans before the first and after the last pose: counts and the span's ends."""
    if span is None:
        return None
    before = ns < span[0]
    return {"before": int(before.sum()), "after": int(((ns > span[1]) & ~before).sum()), "first": span[0],
            "last": span[1]}


def poses_for(path, source, scans, ns, tf, series, fixed_frame, base_frame, mount_arg, outside_span="error",
              static_pose=None):
    """(poses (n, 3), mounts (n, 3) or None, pose_source label, edges) for the scans' stamps.

    source "static": every scan at static_pose (the robot's x, y, yaw) composed with the mount
    (laser_mount, else /tf_static's chain base -> laser, else none: static_pose is the laser's).

    outside_span: "error" (a stamp without a pose is a BagError), "edges" (NaN rows for the
    scans before the first and after the last pose of the chain, counted in edges; a stamp in a
    gap of the chain stays an error) or "skip" (NaN rows for every scan without a pose)."""
    n, frame = len(ns), scans.frame_id
    edges = None
    if source == "tf":
        inside = None
        if outside_span != "error" and len(tf):
            root = fixed_frame if fixed_frame is not None else tf.root(frame)
            span = tf.span(root, frame)
            edges = _edges(ns, span)
            if outside_span == "skip":
                inside = tf.covers(root, frame, ns)
            elif span is not None:
                inside = (ns >= span[0]) & (ns <= span[1])
        poses = _inside(ns, inside, lambda t: _tf_poses(path, tf, fixed_frame, frame, t))
        mount = mount_arg if mount_arg is not None else static_mount(path, tf, base_frame or "base_link", frame)
        label = "tf"
    elif source == "topic":
        base = series.base_frame or "base_link"
        mount = mount_arg if mount_arg is not None else static_mount(path, tf, base, frame)
        if mount is None:
            raise BagError(path, f"no static tf chain (/tf_static) from the base frame {base!r} to the "
                                 f"scans' frame {frame!r}; pass laser_mount (--laser-mount x,y,yaw)",
                           topic=series.topic)
        inside = None
        if outside_span != "error":
            span = series.span()
            edges = _edges(ns, span)
            inside = np.zeros(n, dtype=bool) if span is None else (ns >= span[0]) & (ns <= span[1])
        poses = _inside(ns, inside, lambda t: planar_compose(series.at(t), mount))
        label = f"topic:{series.topic}"
    elif source == "static":
        mount = mount_arg if mount_arg is not None else static_mount(path, tf, base_frame or "base_link", frame)
        poses = planar_compose(np.tile(np.asarray(static_pose, dtype=np.float64), (n, 1)),
                               np.zeros(3) if mount is None else mount)
        label = "static"
    else:
        poses = np.full((n, 3), np.nan)
        mount = mount_arg if mount_arg is not None else static_mount(path, tf, base_frame or "base_link", frame)
        label = "none"
    mounts = None if mount is None else np.tile(np.asarray(mount, dtype=np.float64), (n, 1))
    return poses, mounts, label, edges


def _tf_poses(path, tf: TfBuffer, fixed_frame: str | None, frame: str, ns: np.ndarray) -> np.ndarray:
    """(n, 3) laser poses in fixed_frame from tf (None: the root of the laser frame's tree)."""
    if not len(tf):
        raise BagError(path, "/tf and /tf_static hold no transforms")
    if fixed_frame is None:
        fixed_frame = tf.root(frame)
    t, q = tf.lookup(fixed_frame, frame, ns)
    return planar(path, t, q, f"the laser frame {frame!r} in {fixed_frame!r}")


def choose_fixed_frame(path, tf: TfBuffer, frames, wording: str) -> tuple[str, str | None]:
    """(fixed frame, warning or None) for tf poses when none was asked for: 'map' when tf has it;
    else the root that every scan frame reaches through a /tf link (a bag recorded without
    localisation: odom), with a warning; else a BagError naming the roots (or, where no /tf link
    moves the scans, saying where poses come from)."""
    known = set(tf.frames())
    reach = {f: tf.up(f) if f in known else [f] for f in frames}
    roots = sorted({chain[-1] for chain in reach.values()})
    if "map" in known:
        if all("map" in chain for chain in reach.values()):
            return "map", None
        raise BagError(path, _no_root_text(tf, reach, "'map' is in tf, but not every scan frame reaches it",
                                           wording))
    parented = all(len(chain) > 1 for chain in reach.values())
    if len(roots) != 1 or not parented:
        raise BagError(path, _no_root_text(tf, reach, "tf has no 'map' frame and the scans' frames reach no one "
                                                      "root", wording))
    root = roots[0]
    if all(tf.span(root, f) is None for f in frames):  # static links only: nothing moves the scans
        from .topics import no_poses_text
        chains = ", ".join(" -> ".join(reversed(c)) for c in reach.values())
        raise BagError(path, no_poses_text(f"tf links the scans to {root!r} on /tf_static only ({chains}), "
                                           "so it holds no robot motion, and there is no 'map' frame", wording))
    fixed = words(wording, "--fixed-frame FRAME", "fixed_frame=FRAME")
    poses = words(wording, "--poses FILE", "poses=FILE")
    via = "; ".join(_reach_text(f, chain) for f, chain in reach.items())
    return root, (f"the bag has no 'map' frame: the map is made in {root!r}, the root of tf that the "
                  f"scans reach ({via}); {fixed} chooses another. {root!r} follows the robot's odometry, "
                  f"which drifts: for a SLAM-corrected map give the corrected poses with {poses}")


def _reach_text(frame: str, chain: list[str]) -> str:
    via = f" via {', '.join(chain[1:-1])}" if len(chain) > 2 else ""
    return f"{frame!r}{via}"


def _no_root_text(tf: TfBuffer, reach: dict, why: str, wording: str) -> str:
    """Why no fixed frame is clear: which root each scan frame reaches, tf's roots, and the option."""
    parents = {f for f in tf.frames() if len(tf.up(f)) == 1}
    each = "; ".join(f"{f!r} is not in tf" if len(c) == 1 and f not in parents else
                     f"{f!r} reaches {c[-1]!r}" for f, c in reach.items())
    fixed = words(wording, "--fixed-frame FRAME", "fixed_frame=FRAME")
    return (f"{why} ({each}; the roots in tf: {', '.join(sorted(parents)) or 'none'}): pass {fixed} with the "
            "frame the map is to be in, one that every scan frame reaches")
