"""The console scripts bag2map (log2map's command line on bags) and bag2carmen (a bag as a
CARMEN log).

bag2map runs log2map's own command line, in C++ (``vasco_gpu._core._run_tool``, DESIGN §1),
with the bag options of BAG_OPTIONS added to it and :func:`_tool_reader` in place of the log
reader; the command line hands the reader the bag options given, and some of log2map's own
(HANDED_ON), as text by name. bag2carmen parses its command line with argparse, its bag
options from the same table.
"""

from __future__ import annotations

import argparse
import io
import os
import sys
from dataclasses import dataclass

from .. import _core
from ..msgs.scan_options import SCAN_DEFAULTS
from .carmen_writer import write_carmen_log
from .errors import BagError
from .load import reader_module, read_for_engine
from .options import checked_pose, option_error


@dataclass(frozen=True)
class BagOption:
    """An option of both tools: --flag METAVAR, which sets read_for_engine's keyword."""

    flag: str
    keyword: str
    help: str
    metavar: str
    default: str | None = None  # bag2carmen's value when the option is not given, or empty

    def value(self, parsed: argparse.Namespace) -> str | None:
        """The option's value in bag2carmen's parsed command line."""
        given = getattr(parsed, self.keyword)
        return given if self.default is None else (given or self.default)


# bag2map's options beyond log2map's, and bag2carmen's bag options.
BAG_OPTIONS = (
    BagOption("scan-topic", "scan_topic", "a sensor_msgs/LaserScan, MultiEchoLaserScan or PointCloud2 topic "
              "(default: the only one); repeat it (or separate names by commas) to map several lasers together, each "
              "at its own mount, their scans in stamp order", "TOPIC"),
    BagOption("fixed-frame", "fixed_frame", "the frame the map is in: the root of the tf chain to each scan "
              "(default: map; in a bag without a map frame, the one root of tf that every scan reaches, e.g. odom, with a "
              "warning), or the frame of --pose-topic's poses", "FRAME"),
    BagOption("base-frame", "base_frame", "the robot's frame for --pose-topic and a point cloud's height band "
              "(default: the odometry's child frame, else base_link)", "FRAME"),
    BagOption("pose-topic", "pose_topic", "the robot's poses from a nav_msgs/Odometry, geometry_msgs/PoseStamped "
              "or PoseWithCovarianceStamped topic, or a nav_msgs/Path topic (its last message: a LIO or SLAM "
              "back end's final trajectory), instead of /tf (the laser mount from /tf_static or "
              "--laser-mount)", "TOPIC"),
    BagOption("static-pose", "static_pose", "a robot that does not move: every scan at this robot pose "
              "(the laser mount from /tf_static or --laser-mount; without one, the laser's pose)", "X,Y,THETA"),
    BagOption("no-return", "no_return", "what a +inf range (REP 117: no return) does: skip (default; CARMEN's "
              "max-range readings) or free (clears up to vasco_range_max, as ROS mappers do)", "skip|free",
              default=SCAN_DEFAULTS["no_return"]),
    BagOption("echo", "echo", "the echo a MultiEchoLaserScan beam gives: first, last (default) or strongest "
              "(the largest intensity)", "first|last|strongest", default=SCAN_DEFAULTS["echo"]),
    BagOption("z-band", "z_band", "point clouds: the heights kept, in metres in the base frame (--base-frame), "
              "MIN,MAX (default 0.2,1.8: the floor and the ceiling out)", "MIN,MAX"),
    BagOption("cloud-angle-step", "cloud_angle_step", "point clouds: the beams' angle step in degrees, the "
              "nearest point of the band per step (default 0.25)", "DEGREES"),
    BagOption("cloud-range-max", "cloud_range_max", "point clouds: points farther than this (m) are no return "
              "(default 50)", "M"),
    BagOption("stamp", "stamp", "a scan's time: its header stamp (default) or the time the bag received it "
              "(receive: for a laser driver whose clock is wrong)", "header|receive", default="header"),
)


def _mount_of(text: str | None):
    """X,Y,THETA text as a tuple of floats, None for none; ValueError for a bad number."""
    if not text:
        return None
    parts = text.split(",")
    return tuple(float(p) for p in parts)


# log2map's own options that its command line hands to bag2map's reader too, with the bag
# options (vasco_gpu/app/log2map_steps.cc): (flag, read_for_engine's keyword, its value from
# the option's text). --laser-mount's text is one log2map has already checked as X,Y,THETA.
HANDED_ON = (
    ("poses", "need_poses", lambda text: False),  # a pose file gives the poses: the bag need not
    ("laser-mount", "laser_mount", _mount_of),
    ("skip-unposed", "skip_unposed", lambda text: True),
)


def _tool_reader(path: str, values: dict, progress) -> dict:
    """bag2map's reader of one input: `values` holds the options given, as text by flag."""
    keywords = {o.keyword: values[o.flag] for o in BAG_OPTIONS if o.flag in values}
    keywords.update({keyword: value(values[flag]) for flag, keyword, value in HANDED_ON if flag in values})
    try:
        d = read_for_engine(path, progress=progress, **keywords)
    except BagError as e:  # the command line names the input before the message: not twice
        if e.file is None or os.fspath(e.file) != os.fspath(path):
            raise
        raise type(e)(None, e.message, topic=e.topic, stamp=e.stamp) from None
    _warn(d.pop("warnings", []))
    return d


def _warn(texts, tool: str = "bag2map") -> None:
    """tool: warning: TEXT on stderr (a line of its own, after a progress bar's)."""
    for text in texts:
        lead = "\n" if sys.stderr.isatty() else ""
        print(f"{lead}{tool}: warning: {text}", file=sys.stderr, flush=True)


def _given_values(args: list[str], flags) -> dict:
    """{flag: text} of the options among flags given as --FLAG VALUE or --FLAG=VALUE, before any
    '--' (the last one where one is repeated); a flag without a value is left to the parser."""
    values, k = {}, 0
    while k < len(args) and args[k] != "--":
        a = args[k]
        name = a[2:].split("=", 1)[0] if a.startswith("--") else None
        if name in flags and "=" in a:
            values[name] = a.split("=", 1)[1]
        elif name in flags and k + 1 < len(args):
            values[name] = args[k + 1]
            k += 1
        k += 1
    return values


def _usage_error(values: dict, tool: str) -> str | None:
    """'TOOL: --static-pose 'nan': ...' for a bag option no bag could make valid (a usage error,
    exit 2, said before any bag is read), else None. --laser-mount's form is log2map's to check
    (bag2map): here only the bound on its position."""
    mount = values.pop("laser-mount", None)
    why = option_error(values)
    if why is None and mount is not None:
        try:
            checked_pose(mount, "laser_mount (--laser-mount X,Y,THETA)")
        except ValueError as e:
            bounded = "within" in str(e)  # three finite numbers, too far out
            why = f"--laser-mount {mount!r}: {e}" if bounded or tool == "bag2carmen" else None
    return None if why is None else f"{tool}: {why}"


def _join_repeated(args: list[str], flag: str) -> list[str]:
    """--FLAG given more than once (the command line takes each option once) as one --FLAG with
    the values joined by commas, where the first was; arguments after '--' are left alone."""
    option, values, out, first, k = "--" + flag, [], [], None, 0
    while k < len(args):
        a = args[k]
        if a == "--":
            out.extend(args[k:])
            break
        if a == option and k + 1 < len(args):
            values.append(args[k + 1])
            k += 2
        elif a.startswith(option + "="):
            values.append(a[len(option) + 1:])
            k += 1
        else:
            out.append(a)
            k += 1
            continue
        if first is None:
            first = len(out)
    if len(values) > 1:
        out[first:first] = [option, ",".join(values)]
        return out
    return args


def _bag2map_summary() -> str:
    extensions = ", ".join(f["extension"] for f in _core.map_formats())  # the engine's format table
    return ("bag2map: builds a CARMEN evidence-grid map (vasco/egrid.c) from a ROS bag's laser scans.\n"
            "Inputs: ROS 1 .bag, ROS 2 bag directories (sqlite3, MCAP) and .mcap files. Outputs by extension:\n"
            f"{extensions}. Every other option is log2map's.\n"
            "bag2map --info BAG prints what the bag holds (topics, tf tree, scans, poses) and the command "
            "that maps it.")


def _info_main(args: list[str]) -> int:
    """bag2map --info BAG...: each bag's report (bags/info.py) on stdout. Exit 0, 1 when a
    BAG is not a bag (named on stderr, as bag2map's own errors are), 2 for other arguments."""
    end = args.index("--") if "--" in args else len(args)  # after '--' a name may start with '-'
    bags = [a for a in args[:end] if a != "--info"] + args[end + 1:]
    if not bags or any(a.startswith("-") for a in args[:end] if a != "--info"):
        print("bag2map: --info takes bags only: bag2map --info BAG [BAG...]", file=sys.stderr)
        return 2
    reader_module()  # without rosbags: the ImportError that says to install it
    from .info import bag_info

    status, printed = 0, False
    for bag in bags:
        try:
            text = bag_info(bag).text()
        except BagError as e:
            print(f"bag2map: {e}", file=sys.stderr)
            status = 1
            continue
        print(("\n" if printed else "") + text, end="", flush=True)  # a blank line between reports
        printed = True
    return status


def bag2map_main(argv: list[str] | None = None) -> int:
    """The console script bag2map: log2map's command line with ROS bags as inputs; with --info,
    what each bag holds and the command that maps it (:func:`vasco_gpu.bag_info`)."""
    args = list(sys.argv[1:] if argv is None else argv)
    if "--info" in args[:args.index("--") if "--" in args else len(args)]:
        return _info_main(args)
    args = _join_repeated(args, "scan-topic")
    usage = _usage_error(_given_values(args, {o.flag for o in BAG_OPTIONS} | {"laser-mount"}), "bag2map")
    if usage:
        print(usage, file=sys.stderr)
        return 2
    # the names before the first option (an option's value, e.g. --poses robot.log, may be a log)
    leading = args[:next((i for i, a in enumerate(args) if a.startswith("-")), len(args))]
    logs = [a for a in leading if _is_carmen_log(a)]
    if logs:
        print(f"bag2map: '{logs[0]}' is a CARMEN log, and bag2map reads ROS bags: map it with log2map (log2map "
              f"{logs[0]} OUTPUT; the same options)", file=sys.stderr)
        return 2
    return _core._run_tool(["bag2map", *args], "bag2map", _bag2map_summary(), "BAG",
                           "ROS 1 .bag, ROS 2 bag directory (sqlite3 or MCAP) or .mcap file",
                           [(o.flag, o.help, o.metavar) for o in BAG_OPTIONS], _tool_reader)


def _is_carmen_log(name: str) -> bool:
    """A name with a CARMEN log's extension (.log, .clf; gzipped or not)."""
    plain = name[:-3] if name.lower().endswith(".gz") else name
    return plain.lower().endswith(tuple(_core.carmen_log_extensions()))


def _carmen_log_names() -> str:
    """".log or .clf": the pipeline's CARMEN log extensions, for a message."""
    return " or ".join(_core.carmen_log_extensions())


def _bag2carmen_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="bag2carmen", description=(
        "Writes a ROS bag's laser scans and poses as a CARMEN log (ROBOTLASER1 lines), for CARMEN's own "
        "tools and log2map. The output is written whole or not at all."))
    p.add_argument("bag", metavar="BAG", help="ROS 1 .bag, ROS 2 bag directory (sqlite3 or MCAP) or .mcap file")
    p.add_argument("out", metavar="OUT",
                   help=f"the CARMEN log to write ({', '.join(_core.carmen_log_extensions())}; gzipped if .gz)")
    for o in BAG_OPTIONS:
        repeated = {"action": "append"} if o.flag == "scan-topic" else {}
        p.add_argument("--" + o.flag, dest=o.keyword, help=o.help, metavar=o.metavar, **repeated)
    p.add_argument("--laser-mount", metavar="X,Y,THETA", help="the laser in the robot's frame (for --pose-topic)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress")
    p.add_argument("--version", action="version", version=f"bag2carmen (vasco_gpu) {_core.__version__}")
    return p


def bag2carmen_main(argv: list[str] | None = None) -> int:
    """The console script bag2carmen. Exit 0 done, 1 bad input, 2 usage error."""
    _core._remove_temporaries_on_signals()  # SIGINT, SIGTERM, SIGHUP: no temporary left behind
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
    given = {o.flag: getattr(a, o.keyword) for o in BAG_OPTIONS if getattr(a, o.keyword) is not None}
    usage = _usage_error({**given, "laser-mount": a.laser_mount} if a.laser_mount else given, "bag2carmen")
    if usage:
        print(usage, file=sys.stderr)
        return 2
    if os.path.exists(a.out) and os.path.exists(a.bag) and os.path.samefile(a.out, a.bag):
        print(f"bag2carmen: {a.out}: the output is the input", file=sys.stderr)
        return 2
    reader_module()  # without rosbags: the ImportError that says to install it
    try:
        d = read_for_engine(a.bag, laser_mount=mount, **{o.keyword: o.value(a) for o in BAG_OPTIONS})
        _warn(d.pop("warnings", []), "bag2carmen")
        ext = a.out.lower()
        gz = ext.endswith(".gz")
        if not (ext[:-3] if gz else ext).endswith(tuple(_core.carmen_log_extensions())):
            print(f"bag2carmen: {a.out}: expected a {_carmen_log_names()} name (gzipped if .gz)", file=sys.stderr)
            return 2

        # The engine's output file (atomic_file.h): a hidden temporary beside the target, renamed
        # over it only when complete; a FIFO or directory target refused; gone on a failure.
        out = _core._OutputFile(a.out)
        try:
            with os.fdopen(out.take_fd(), "wb") as raw:
                import gzip
                sink = gzip.GzipFile(filename="", mode="wb", compresslevel=6, fileobj=raw, mtime=0) if gz else raw
                text = io.TextIOWrapper(sink, encoding="ascii", newline="\n")
                try:
                    write_carmen_log(d["bag"], text)
                    text.flush()
                finally:
                    text.detach()  # the wrappers let go of raw whatever happened (no late flush)
                if gz:
                    sink.close()  # the gzip trailer; raw stays open for the with
            out.commit()
        finally:
            out.abandon()  # nothing once committed
    except (BagError, ValueError, OSError) as e:
        print(f"bag2carmen: {e}", file=sys.stderr)
        return 1
    if not a.quiet:
        b = d["bag"]
        print(f"bag2carmen: {a.bag}: {len(b.stamps)} scans of {', '.join(b.topics or (b.topic,))} -> {a.out}",
              file=sys.stderr)
    return 0
