"""The console script carmen2bag: a CARMEN log as a ROS bag (:mod:`.bag_writer` writes it), to
try bag2map without a robot.

``carmen2bag LOG OUT`` reads the log with the package's own reader (:func:`vasco_gpu.load_log`)
and writes it as OUT by OUT's extension (``.bag``, ``.mcap``, ``.db3``), whole or not at all:
SIGINT, SIGTERM and SIGHUP leave no temporary behind. Exit 0 written, 1 a log that cannot be
read or an output that cannot be written (the message names the file), 2 usage.
"""

from __future__ import annotations

import argparse
import math
import os
import sys

from .bag_writer import (BASE_FRAME, CLOUD_CEILING_Z, CLOUD_FLOOR_Z, CLOUD_HIT_Z, CLOUD_TOPIC, FIXED_FRAME,
                         LASER_FRAME, SCAN_TOPIC, Carmen2BagError, output_kind, write_bag)

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    from .. import _core  # the pipeline's CARMEN log extensions (loaded here, not at import)

    p = argparse.ArgumentParser(prog="carmen2bag", description=(
        "Writes a CARMEN log's scans as a ROS bag: sensor_msgs/LaserScan on /scan (frame laser), the laser "
        "poses as map -> base_link on /tf, base_link -> laser (the identity) on /tf_static; ranges CARMEN's "
        "mapper skips (50 m and beyond) as +inf (REP 117). bag2map maps it as log2map maps the log. The "
        "output is written whole or not at all."))
    p.add_argument("log", metavar="LOG",
                   help=f"CARMEN log ({', '.join(_core.carmen_log_extensions())}; gzipped if .gz)")
    p.add_argument("out", metavar="OUT", help="the bag to write: OUT.bag (ROS 1), OUT.mcap or OUT.db3 (ROS 2)")
    p.add_argument("--cloud", action="store_true", help=(
        f"write sensor_msgs/PointCloud2 (x, y, z float32) on {CLOUD_TOPIC} instead: each beam's end at "
        f"z = {CLOUD_HIT_Z} m, floor points at z = {CLOUD_FLOOR_Z} and ceiling points at z = {CLOUD_CEILING_Z} m"))
    p.add_argument("--topic", metavar="T", help=f"the scans' topic (default {SCAN_TOPIC}, with --cloud {CLOUD_TOPIC})")
    p.add_argument("--period", metavar="S", type=float, help=(
        "stamps S, 2S, 3S, ... seconds instead of the log's (for a log whose scans share stamps or have none)"))
    p.add_argument("-q", "--quiet", action="store_true", help="no summary line")
    p.add_argument("--version", action="version", version=f"carmen2bag (vasco_gpu) {_core.__version__}")
    return p


def main(argv: list[str] | None = None) -> int:
    """The console script carmen2bag. Exit 0 written, 1 bad log or unwritable output, 2 usage."""
    parser = _parser()
    try:
        a = parser.parse_args(sys.argv[1:] if argv is None else argv)
    except SystemExit as e:
        return 0 if e.code == 0 else 2
    if a.period is not None and not (math.isfinite(a.period) and a.period > 0):
        print(f"carmen2bag: --period {a.period!r}: expected a positive number of seconds", file=sys.stderr)
        return 2
    if a.topic is not None and not a.topic.startswith("/"):
        print(f"carmen2bag: --topic {a.topic!r}: expected a name starting with '/'", file=sys.stderr)
        return 2
    try:
        output_kind(a.out)
        if os.path.exists(a.out) and os.path.exists(a.log) and os.path.samefile(a.out, a.log):
            raise Carmen2BagError(a.out, "the output is the input", usage=True)
    except Carmen2BagError as e:
        print(f"carmen2bag: {e}", file=sys.stderr)
        return 2
    try:
        import rosbags  # noqa: F401
    except ImportError:
        print("carmen2bag: needs the Python package rosbags (pip install rosbags; Python >= 3.10)", file=sys.stderr)
        return 1
    from .. import Error, _core, load_log

    _core._remove_temporaries_on_signals()  # SIGINT, SIGTERM, SIGHUP: no temporary left behind

    try:
        log = load_log(a.log)
        written = write_bag(log, a.out, log_path=a.log, cloud=a.cloud, period=a.period, topic=a.topic)
    except Carmen2BagError as e:
        print(f"carmen2bag: {e}", file=sys.stderr)
        return 2 if e.usage else 1
    except (Error, OSError, ValueError) as e:  # a FileError names the file (and line) itself
        text = str(e)
        print(f"carmen2bag: {text if a.log in text else f'{a.log}: {text}'}", file=sys.stderr)
        return 1
    if not a.quiet:
        kind = "PointCloud2" if a.cloud else "LaserScan"
        print(f"carmen2bag: {a.log}: {written.scans} scans -> {a.out} ({written.what}: {kind} on {written.topic}, "
              f"{FIXED_FRAME} -> {BASE_FRAME} on /tf, {BASE_FRAME} -> {LASER_FRAME} on /tf_static)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
