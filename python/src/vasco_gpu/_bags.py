"""ROS bags into the engine: load_bag (a Log, as load_log gives), and the console scripts
bag2map (log2map's command line on bags) and bag2carmen (a bag as a CARMEN log).

The bag is read by :mod:`vasco_gpu._bag` (through ``rosbags``: ROS 1 ``.bag``, ROS 2 sqlite3
and MCAP, no ROS install); what comes after it (Mapper, finish, write_map, compare, the
command line's outputs, transaction and exit statuses) is the CARMEN path's own.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from typing import Any, Callable

import numpy as np

from . import _core

# bag2map's options beyond log2map's: (name, help, value name).
BAG_OPTIONS = [
    ("scan-topic", "the sensor_msgs/LaserScan topic (default: the only one)", "TOPIC"),
    ("fixed-frame", "the frame the map is in: the root of the tf chain to each scan (default: map), or the "
     "frame of --pose-topic's poses", "FRAME"),
    ("base-frame", "the robot's frame for --pose-topic (default: the odometry's child frame, else base_link)",
     "FRAME"),
    ("pose-topic", "the robot's poses from a nav_msgs/Odometry, geometry_msgs/PoseStamped or "
     "PoseWithCovarianceStamped topic instead of /tf (the laser mount from /tf_static or --laser-mount)", "TOPIC"),
    ("no-return", "what a +inf range (REP 117: no return) does: skip (default; CARMEN's max-range readings) "
     "or free (clears up to vasco_range_max, as ROS mappers do)", "skip|free"),
]


def _bag_module():
    try:
        from . import _bag
    except ImportError as e:  # rosbags missing: say what to install
        raise ImportError(f"reading ROS bags needs the 'rosbags' package (pip install rosbags): {e}") from e
    return _bag


def _mount_of(text: str | None):
    if not text:
        return None
    parts = text.split(",")
    return tuple(float(p) for p in parts)


def _read(path, *, scan_topic=None, fixed_frame=None, base_frame=None, pose_topic=None, laser_mount=None,
          no_return="skip", need_poses=True, skip_unposed=False, progress=None):
    """The bag's scans as the engine takes them: {'scans', 'stamps', 'mounts', 'unposed'}; with
    skip_unposed the scans outside the poses' time span are left out and counted."""
    bag = _bag_module()
    b = bag.read_bag(os.fspath(path), scan_topic=scan_topic,
                     fixed_frame=fixed_frame if fixed_frame is not None else ("map" if pose_topic is None else None),
                     base_frame=base_frame, pose_topic=pose_topic, laser_mount=laser_mount,
                     pose_source="auto" if need_poses else "none", no_return=no_return, progress=progress,
                     outside_span="skip" if skip_unposed and need_poses else "error")
    keep = np.isfinite(b.poses).all(axis=1) if need_poses else np.ones(len(b.stamps), dtype=bool)
    if need_poses and not keep.any():
        raise bag.BagError(os.fspath(path), f"none of the {len(keep)} scans of {b.topic} lies within the time "
                                            "span of the poses", topic=b.topic)
    counts = b.beam_counts[keep]
    ranges = b.ranges[np.repeat(keep, b.beam_counts)]
    scans = _core.Scans(b.poses[keep], ranges, counts.astype(np.float64), b.first_angle[keep], b.angle_step[keep])
    scans.lines[:] = 0  # a bag has no lines: errors name the scan by its index
    mounts = None if b.mounts is None else b.mounts[keep]
    return {"scans": scans, "stamps": b.stamps[keep], "mounts": mounts, "unposed": int((~keep).sum()), "bag": b}


def load_bag(path: str | os.PathLike, scan_topic: str | None = None, fixed_frame: str | None = None,
             base_frame: str | None = None, pose_topic: str | None = None,
             laser_mount: tuple[float, float, float] | None = None, no_return: str = "skip",
             param_file: str | os.PathLike | None = None, robot: str = "",
             overrides: dict[str, float | int] | None = None,
             progress: Callable[[int, int], Any] | None = None, **pose_keywords) -> _core.Log:
    """Reads a ROS 1 ``.bag``, a ROS 2 bag (sqlite3 or MCAP) or an ``.mcap`` into a :class:`Log`.

    Scans are the ``sensor_msgs/LaserScan`` messages of ``scan_topic`` (default: the only such
    topic), ranges mapped to CARMEN's semantics by REP 117 (see the README's table;
    ``no_return='free'`` makes +inf clear free space). The laser pose at each scan's stamp comes
    from ``/tf`` + ``/tf_static`` (the chain from ``fixed_frame``, default ``map``, to the scan's
    frame, interpolated in time), or from ``pose_topic`` (Odometry, PoseStamped,
    PoseWithCovarianceStamped) and the mount (``/tf_static`` or ``laser_mount``), or from a pose
    file: ``poses=FILE`` and the other pose keywords of :func:`load_log`, matched by stamp.
    ``skip_unposed=True`` without a pose file leaves out (and counts, ``Log.unposed_skipped``)
    the scans outside the poses' time span, which are otherwise an error. ``add=[bag, (bag,
    (x, y, theta))]`` and ``transform=`` put several sessions into one grid, as in load_log.
    The parameters come from ``param_file`` and ``overrides`` (a bag has no PARAM lines). Errors
    name the bag, and the topic and stamp where one is at fault (:class:`FileError`).
    """
    from ._errors import FileError

    bag = _bag_module()
    more = pose_keywords.pop("add", None) or []
    transform = pose_keywords.pop("transform", None)
    sessions = [(path, transform)] + [m if isinstance(m, tuple) else (m, None) for m in more]
    need_poses = pose_keywords.get("poses") is None
    options = dict(scan_topic=scan_topic, fixed_frame=fixed_frame, base_frame=base_frame, pose_topic=pose_topic,
                   laser_mount=laser_mount, no_return=no_return, need_poses=need_poses,
                   skip_unposed=bool(pose_keywords.pop("skip_unposed", False)) if need_poses else False,
                   progress=progress)
    if len(sessions) > 1 and pose_keywords.get("poses") is not None:
        raise _core_usage_error("poses= applies to one input: write each session's poses into it first")
    d = None
    for p, t in sessions:
        try:
            one = _read(p, **options)
        except bag.BagError as e:
            raise FileError(str(e), file=os.fspath(p), line=None, message=str(e)) from e
        d = _append_session(d, one, t)
    return _core._log_from_scans(d, os.fspath(path), param_file, robot, overrides, **pose_keywords)


def _core_usage_error(message: str):
    from ._errors import UsageError
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
    d["stamps"] = np.concatenate([d["stamps"], more["stamps"]])
    if d["mounts"] is not None or more["mounts"] is not None:
        unknown = lambda n: np.full((n, 3), np.nan)
        d["mounts"] = np.concatenate([d["mounts"] if d["mounts"] is not None else unknown(n0),
                                      more["mounts"] if more["mounts"] is not None else unknown(n1)])
    return d


def _tool_reader(path: str, values: dict, progress) -> dict:
    """bag2map's reader of one input: the extra options by name, as given on the command line."""
    mount = values.get("laser-mount")
    return _read(path, scan_topic=values.get("scan-topic"), fixed_frame=values.get("fixed-frame"),
                 base_frame=values.get("base-frame"), pose_topic=values.get("pose-topic"),
                 laser_mount=_mount_of(mount), no_return=values.get("no-return", "skip"),
                 need_poses="poses" not in values, skip_unposed="skip-unposed" in values, progress=progress)


BAG2MAP_SUMMARY = (
    "bag2map: builds a CARMEN evidence-grid map (vasco/egrid.c) from a ROS bag's laser scans.\n"
    "Inputs: ROS 1 .bag, ROS 2 bag directories (sqlite3, MCAP) and .mcap files. Outputs by extension:\n"
    ".map, .map.gz (CARMEN), .pgm (+ .yaml, ROS map_server), .png. Every other option is log2map's.")


def bag2map_main(argv: list[str] | None = None) -> int:
    """The console script bag2map: log2map's command line with ROS bags as inputs."""
    args = list(sys.argv[1:] if argv is None else argv)
    return _core._run_tool(["bag2map", *args], "bag2map", BAG2MAP_SUMMARY, "BAG",
                           "ROS 1 .bag, ROS 2 bag directory (sqlite3 or MCAP) or .mcap file",
                           BAG_OPTIONS, _tool_reader)


def _bag2carmen_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="bag2carmen", description=(
        "Writes a ROS bag's laser scans and poses as a CARMEN log (ROBOTLASER1 lines), for CARMEN's own "
        "tools and log2map. The output is written whole or not at all."))
    p.add_argument("bag", metavar="BAG", help="ROS 1 .bag, ROS 2 bag directory (sqlite3 or MCAP) or .mcap file")
    p.add_argument("out", metavar="OUT", help="the CARMEN log to write (.log, .clf; gzipped if .gz)")
    for name, help_text, metavar in BAG_OPTIONS:
        p.add_argument("--" + name, help=help_text, metavar=metavar)
    p.add_argument("--laser-mount", metavar="X,Y,THETA", help="the laser in the robot's frame (for --pose-topic)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress")
    return p


def _write_whole(out: str, write: Callable[[str], None]) -> None:
    """Writes to a temporary beside `out`, renamed over it only when complete."""
    directory = os.path.dirname(os.path.abspath(out))
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(out) + ".", suffix=".tmp", dir=directory)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, out)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def bag2carmen_main(argv: list[str] | None = None) -> int:
    """The console script bag2carmen. Exit 0 done, 1 bad input, 2 usage error."""
    parser = _bag2carmen_parser()
    try:
        a = parser.parse_args(sys.argv[1:] if argv is None else argv)
    except SystemExit as e:
        return 0 if e.code == 0 else 2
    try:
        mount = _mount_of(a.laser_mount)
    except ValueError:
        print(f"bag2carmen: --laser-mount '{a.laser_mount}': expected X,Y,THETA", file=sys.stderr)
        return 2
    if os.path.exists(a.out) and os.path.exists(a.bag) and os.path.samefile(a.out, a.bag):
        print(f"bag2carmen: {a.out}: the output is the input", file=sys.stderr)
        return 2
    bag = _bag_module()
    try:
        d = _read(a.bag, scan_topic=a.scan_topic, fixed_frame=a.fixed_frame, base_frame=a.base_frame,
                  pose_topic=a.pose_topic, laser_mount=mount, no_return=a.no_return or "skip")
        ext = a.out.lower()
        if not (ext.endswith(".log") or ext.endswith(".clf") or ext.endswith(".log.gz") or ext.endswith(".clf.gz")):
            print(f"bag2carmen: {a.out}: expected a .log or .clf name (gzipped if .gz)", file=sys.stderr)
            return 2
        gz = ext.endswith(".gz")

        def write(tmp):
            if gz:
                import gzip
                with gzip.open(tmp, "wt", compresslevel=6, encoding="ascii", newline="\n") as f:
                    bag.write_carmen_log(d["bag"], f)
            else:
                with open(tmp, "w", encoding="ascii", newline="\n") as f:
                    bag.write_carmen_log(d["bag"], f)

        _write_whole(a.out, write)
    except (bag.BagError, ValueError, OSError) as e:
        print(f"bag2carmen: {e}", file=sys.stderr)
        return 1
    if not a.quiet:
        b = d["bag"]
        print(f"bag2carmen: {a.bag}: {len(b.stamps)} scans of {b.topic} -> {a.out}", file=sys.stderr)
    return 0
