""":func:`load_bag`: a ROS bag into a :class:`vasco_gpu.Log`, as load_log gives one; and
:func:`read_for_engine`, the bag's scans in the form the engine takes them (load_bag and
bag2map).

The bag is read by :func:`vasco_gpu.bags.reader.read_bag` (through ``rosbags``: ROS 1 ``.bag``,
ROS 2 sqlite3 and MCAP, no ROS install); what comes after it (Mapper, finish, write_map,
compare, the command line's outputs, transaction and exit statuses) is the CARMEN path's own.
"""

from __future__ import annotations

import os
import warnings
from typing import Any, Callable

import numpy as np

from .. import _core
from ..msgs.scan_options import SCAN_DEFAULTS
from .errors import BagError, BagWarning


def reader_module():
    try:
        from . import reader
    except ImportError as e:  # rosbags missing: say what to install
        raise ImportError(f"reading ROS bags needs the 'rosbags' package (pip install rosbags): {e}") from e
    return reader


def edge_warning(b) -> str | None:
    """The one line about the scans left out before the first and after the last pose, or None."""
    e = b.edges
    if not e or not (e["before"] or e["after"]):
        return None
    topics = ", ".join(b.topics or (b.topic,))
    return (f"{b.path}: {e['before']} scans of {topics} before the first pose ({e['first']:.9f}) and "
            f"{e['after']} after the last ({e['last']:.9f}) have no pose: left out")


def read_for_engine(path, *, scan_topic=None, fixed_frame=None, base_frame=None, pose_topic=None, laser_mount=None,
                    no_return=SCAN_DEFAULTS["no_return"], need_poses=True, skip_unposed=False, progress=None,
                    echo=SCAN_DEFAULTS["echo"],
                    stamp="header", z_band=None, cloud_angle_step=None, cloud_range_max=None, static_pose=None,
                    wording="cli"):
    """The bag's scans as the engine takes them: {'scans', 'stamps', 'mounts', 'unposed', 'edges',
    'warnings', 'bag'}. The scans before the first and after the last pose of their chain are
    left out and counted ('unposed', and 'edges': before, after), with one warning; a scan in a
    gap of the poses is an error, unless skip_unposed leaves out every scan without a pose.
    Without fixed_frame and pose_topic the poses are tf's in 'map', or, in a bag without a 'map'
    frame, in the one root of tf the scans reach (with a warning). wording: errors and warnings
    name options as bag2map does ("cli") or as load_bag does ("python")."""
    reader = reader_module()
    outside = ("skip" if skip_unposed else "edges") if need_poses else "error"
    b = reader.read_bag(os.fspath(path), scan_topic=scan_topic,
                        fixed_frame=fixed_frame if fixed_frame is not None else ("map" if pose_topic is None else None),
                        root_if_no_map=fixed_frame is None and pose_topic is None, wording=wording,
                        base_frame=base_frame, pose_topic=pose_topic, laser_mount=laser_mount,
                        pose_source="auto" if need_poses else "none", no_return=no_return, progress=progress,
                        outside_span=outside, echo=echo, stamp=stamp, z_band=z_band,
                        cloud_angle_step=cloud_angle_step, cloud_range_max=cloud_range_max, static_pose=static_pose)
    keep = np.isfinite(b.poses).all(axis=1) if need_poses else np.ones(len(b.stamps), dtype=bool)
    if need_poses and not keep.any():
        raise BagError(os.fspath(path), _none_posed_text(b, len(keep), stamp), topic=b.topic)
    counts = b.beam_counts[keep]
    ranges = b.ranges[np.repeat(keep, b.beam_counts)]
    scans = _core.Scans(b.poses[keep], ranges, counts.astype(np.float64), b.first_angle[keep], b.angle_step[keep])
    scans.lines[:] = 0  # a bag has no lines: errors name the scan by its index
    mounts = None if b.mounts is None else b.mounts[keep]
    warning = edge_warning(b) if need_poses else None
    edges = {k: (b.edges or {}).get(k, 0) for k in ("before", "after")}
    return {"scans": scans, "stamps": b.stamps[keep], "mounts": mounts, "unposed": int((~keep).sum()), "bag": b,
            "edges": edges, "warnings": list(b.warnings) + ([warning] if warning else [])}


def _none_posed_text(b, n: int, stamp: str) -> str:
    """Why no scan has a pose: the scans' stamps against the poses' span."""
    topics = ", ".join(b.topics or (b.topic,))
    text = f"none of the {n} scans of {topics} lies within the time span of the poses"
    if b.edges:
        text += (f": the scans' stamps run from {b.stamps.min():.9f} to {b.stamps.max():.9f}, the poses "
                 f"from {b.edges['first']:.9f} to {b.edges['last']:.9f}")
    if stamp == "header":
        text += " (a laser driver with a wrong clock: --stamp receive takes the time the bag received each scan)"
    return text


def load_bag(path: str | os.PathLike, scan_topic: str | None = None, fixed_frame: str | None = None,
             base_frame: str | None = None, pose_topic: str | None = None,
             laser_mount: tuple[float, float, float] | None = None, no_return: str = SCAN_DEFAULTS["no_return"],
             param_file: str | os.PathLike | None = None, robot: str = "",
             overrides: dict[str, float | int] | None = None,
             progress: Callable[[int, int], Any] | None = None, echo: str = SCAN_DEFAULTS["echo"],
             stamp: str = "header",
             z_band: tuple[float, float] | None = None, cloud_angle_step: float | None = None,
             cloud_range_max: float | None = None, static_pose: tuple[float, float, float] | None = None,
             **pose_keywords) -> _core.Log:
    """Reads a ROS 1 ``.bag``, a ROS 2 bag (sqlite3 or MCAP) or an ``.mcap`` into a :class:`Log`.

    Scans are the ``sensor_msgs/LaserScan`` (or ``MultiEchoLaserScan``: ``echo`` ``first``,
    ``last`` or ``strongest``; or ``PointCloud2``: the points in ``z_band`` (min, max) metres of
    the base frame, default (0.2, 1.8), nearest point per ``cloud_angle_step`` degrees, default
    0.25, up to ``cloud_range_max`` m, default 50) messages of ``scan_topic`` (default: the only such topic; a list
    of topics maps several lasers together, each in its own frame, merged in stamp order),
    stamped by their header (``stamp='receive'``: by the time the bag received them), ranges mapped to CARMEN's semantics by REP 117 (see docs/bags-and-poses.md, "REP 117 ranges, in CARMEN's terms";
    ``no_return='free'`` makes +inf clear free space). The laser pose at each scan's stamp comes
    from ``/tf`` + ``/tf_static`` (the chain from ``fixed_frame``, default ``map``, to the scan's
    frame, interpolated in time; a bag without a ``map`` frame is mapped in the one root of tf
    that the scans reach, such as ``odom``, with a :class:`BagWarning`), or from ``pose_topic`` (Odometry, PoseStamped,
    PoseWithCovarianceStamped, or a Path: its last message) and the mount (``/tf_static`` or
    ``laser_mount``), or ``static_pose`` (x, y, yaw of a robot that does not move, with the mount),
    or from a pose file: ``poses=FILE`` and the other pose keywords of :func:`load_log`, matched by stamp.
    The scans before the first and after the last pose of the chain are left out and counted
    (``Log.unposed_skipped``) with one :class:`BagWarning`; a scan in a gap of the poses is an
    error, unless ``skip_unposed=True`` (without a pose file) leaves out every scan without one. ``add=[bag, (bag,
    (x, y, theta))]`` and ``transform=`` put several sessions into one grid, as in load_log; ``(bag, 'auto')``
    finds the transform by aligning the bag's map to those before it, as
    :func:`vasco_gpu.align_sessions` does (``align={...}``: its keywords: backend, match_resolution, hints, ...),
    and raises BadInputError naming the bag where it cannot.
    The parameters come from ``param_file`` and ``overrides`` (a bag has no PARAM lines); the map's
    cell is ROS's 0.05 m (``vasco_gpu.ROS_MAP_RESOLUTION``, bag2map's default too) unless
    ``map_resolution=M`` or a vasco_resolution in them says otherwise (see load_log). Errors
    name the bag, and the topic and stamp where one is at fault (:class:`FileError`).
    """
    from .._errors import FileError

    reader_module()
    more = pose_keywords.pop("add", None) or []
    transform = pose_keywords.pop("transform", None)
    sessions = [(path, transform)] + [m if isinstance(m, tuple) else (m, None) for m in more]
    need_poses = pose_keywords.get("poses") is None
    options = dict(scan_topic=scan_topic, fixed_frame=fixed_frame, base_frame=base_frame, pose_topic=pose_topic,
                   laser_mount=laser_mount, no_return=no_return, need_poses=need_poses,
                   skip_unposed=bool(pose_keywords.pop("skip_unposed", False)) if need_poses else False,
                   progress=progress, echo=echo, stamp=stamp, z_band=z_band, cloud_angle_step=cloud_angle_step,
                   cloud_range_max=cloud_range_max, static_pose=static_pose, wording="python")
    if len(sessions) > 1 and pose_keywords.get("poses") is not None:
        raise _core_usage_error("poses= applies to one input: write each session's poses into it first")
    align = pose_keywords.pop("align", None) or {}
    read = []
    for p, t in sessions:
        try:
            one = read_for_engine(p, **options)
        except BagError as e:
            raise FileError(str(e), file=os.fspath(p), line=None, message=str(e)) from e
        for text in one.pop("warnings", []):
            warnings.warn(BagWarning(text), stacklevel=2)
        read.append((p, one, t))
    if any(isinstance(t, str) for _, _, t in read):
        read = _place_auto(read, _session_params(param_file, robot, overrides), align)
    d = None
    for _, one, t in read:
        d = _append_session(d, one, t)
    return _core._log_from_scans(d, os.fspath(path), param_file, robot, overrides, **pose_keywords)


def _session_params(param_file, robot: str, overrides) -> _core.Params:
    """The parameters the bags are mapped with (a bag has no PARAM lines): what the alignment maps."""
    if param_file is not None:
        return _core.Params.from_ini(os.fspath(param_file), robot, **(overrides or {}))
    return _core.Params(**(overrides or {}))


def _place_auto(read: list, params: _core.Params, align: dict) -> list:
    """The sessions read, each "auto" one aligned (vasco_gpu.align_sessions' way) to those before it;
    every session's scans are then in the shared frame (its transform None)."""
    from ..align import _Session, _transform_of, place_sessions

    sessions = []
    for i, (p, one, t) in enumerate(read):
        transform = (0.0, 0.0, 0.0) if t is None else _transform_of(t, os.fspath(p))
        if i == 0 and transform == "auto":
            raise _core_usage_error(f"{os.fspath(p)}: the first bag is the shared frame: its transform is given or none")
        sessions.append(_Session(os.fspath(p), one["scans"], params, transform))
    options = dict(align)
    cell = options.pop("resolution", None)
    place_sessions(sessions, backend=options.pop("backend", "auto"), threads=options.pop("threads", 0),
                   cell=options.get("match_resolution", 0.1) if cell is None else float(cell),
                   refuse=True, hints=options.pop("hints", None), align_options=options)
    return [(p, one, None) for p, one, _ in read]


def _core_usage_error(message: str):
    from .._errors import UsageError
    return UsageError(message)


def _append_session(d: dict | None, more: dict, transform) -> dict:
    """Scans of one more session, taken into the shared frame by `transform`, after d's."""
    if transform is not None:
        x, y, theta = (float(v) for v in transform)
        more["scans"].transform(x, y, theta)
    if d is None:
        return more
    n0, n1 = len(d["scans"]), len(more["scans"])
    d["scans"].extend(more["scans"])
    d["unposed"] += more["unposed"]
    d["edges"] = {k: d["edges"][k] + more["edges"][k] for k in d["edges"]}
    d["stamps"] = np.concatenate([d["stamps"], more["stamps"]])
    if d["mounts"] is not None or more["mounts"] is not None:
        unknown = lambda n: np.full((n, 3), np.nan)
        d["mounts"] = np.concatenate([d["mounts"] if d["mounts"] is not None else unknown(n0),
                                      more["mounts"] if more["mounts"] is not None else unknown(n1)])
    return d
