""":func:`bag_info`: what a bag holds for the mapper, and the bag2map command it calls for
(``bag2map --info BAG`` prints it).

Only what the answer needs is read: the topics, their types and message counts from the bag's
index or metadata; the tf tree from /tf_static and a bounded sample of /tf (its first and its
last messages: a link that starts late, such as a localiser's map -> odom, still shows); and
the first message of each scan and pose topic, for its frame. Scan data beyond that first
message is never read.

The module imports rosbags (through :mod:`.storage`) only when bag_info is called, so that
``vasco_gpu.bag_info`` is there without it.
"""

from __future__ import annotations

import os
import shlex
from dataclasses import dataclass, field
from pathlib import Path

from ..msgs.header import NS, frame_name, stamp_text
from ..msgs.table import POSE_TYPES, SCAN_TYPES, TF_TYPES, UNSUPPORTED_SENSORS, norm_type, short_type
from .topics import resolve_topic, topics_of_type

__all__ = ["BagInfo", "PoseSource", "ScanSource", "TfLink", "TfTree", "TopicSummary", "bag_info"]

#: /tf messages read from the start of the bag and from its end: a tree's links are all
#: published within the first seconds, except those that start late (a localiser's map -> odom).
TF_HEAD = 1000
TF_TAIL = 1000
#: /tf_static messages read at most (a recorder latches them once per publisher).
STATIC_LIMIT = 1000

# The pose topics a suggested command takes first: dense base poses before sparse ones.
_POSE_PREFERENCE = ("nav_msgs/msg/Odometry", "geometry_msgs/msg/PoseStamped",
                    "geometry_msgs/msg/PoseWithCovarianceStamped", "nav_msgs/msg/Path")
_SLAM_HINT = ("poses must come from SLAM or odometry first: e.g. slam_toolbox or Cartographer run offline on "
              "the bag, their trajectory then given with --poses FILE")


@dataclass(frozen=True)
class TopicSummary:
    """A topic: its type (ROS 1 spelling), message count, mean rate over the bag's duration
    (None for fewer than two messages) and its role for the mapper ("scan", "pose", "tf", "")."""

    name: str
    type: str
    count: int
    rate_hz: float | None
    role: str


@dataclass(frozen=True)
class TfLink:
    """parent -> child, from /tf_static (static) or /tf, and the transforms of it read."""

    parent: str
    child: str
    static: bool
    count: int


@dataclass
class TfTree:
    """The tf links seen (by child: tf gives each frame one parent), the frames named with a
    second parent or on both /tf and /tf_static (conflicts), and how much of /tf was read."""

    links: dict = field(default_factory=dict)
    conflicts: list = field(default_factory=list)
    tf_read: int = 0
    tf_total: int = 0
    static_read: int = 0
    static_total: int = 0

    @property
    def complete(self) -> bool:
        """Whether every /tf message was read (else links seen only in between are missing)."""
        return self.tf_read >= self.tf_total

    def frames(self) -> list[str]:
        return sorted({k.child for k in self.links.values()} | {k.parent for k in self.links.values()})

    def roots(self) -> list[str]:
        """The frames with no parent."""
        return [f for f in self.frames() if f not in self.links]

    def up(self, frame: str) -> list[str]:
        """frame, its parent, ... up to its root (a cycle stops where it closes)."""
        chain = [frame]
        while chain[-1] in self.links and self.links[chain[-1]].parent not in chain:
            chain.append(self.links[chain[-1]].parent)
        return chain

    def add(self, msg, static: bool) -> None:
        for ts in msg.transforms:
            parent, child = frame_name(ts.header.frame_id), frame_name(ts.child_frame_id)
            link = self.links.get(child)
            if link is None:
                self.links[child] = TfLink(parent, child, static, 1)
            elif link.parent != parent or link.static != static:
                where = lambda s: "/tf_static" if s else "/tf"
                text = (f"{child!r}: {link.parent!r} on {where(link.static)} and {parent!r} on {where(static)}")
                if text not in self.conflicts:
                    self.conflicts.append(text)
            else:
                self.links[child] = TfLink(parent, child, static, link.count + 1)


@dataclass(frozen=True)
class ScanSource:
    """A scan topic: its type, count and the frame of its first message (None without one)."""

    topic: str
    type: str
    count: int
    frame: str | None


@dataclass(frozen=True)
class PoseSource:
    """A pose topic ("topic": its frame and, for Odometry, child frame, from its first message)."""

    topic: str
    type: str
    count: int
    frame: str | None
    child: str | None


@dataclass
class BagInfo:
    """What :func:`bag_info` found. command: the bag2map command line that maps the bag (the
    default one, or with the options the bag needs); refusal: why bag2map with no options
    would refuse the bag (None when it would not); notes: what else to know."""

    path: str
    storage: str
    start: float | None
    end: float | None
    message_count: int
    topics: list
    tf: TfTree
    scans: list
    poses: list
    command: list | None = None
    refusal: str | None = None
    notes: list = field(default_factory=list)

    @property
    def duration(self) -> float:
        return 0.0 if self.start is None else self.end - self.start

    def command_line(self) -> str | None:
        return None if self.command is None else shlex.join(self.command)

    def text(self) -> str:
        """The plain-text report bag2map --info prints."""
        return _report(self)


def bag_info(path: str | os.PathLike) -> BagInfo:
    """What the bag at path holds for the mapper: its topics (type, count, rate), duration, tf
    tree, scan topics and pose sources, and the bag2map command that maps it or why bag2map
    would refuse it. Reads the index and a bounded sample (module docstring); a file that is
    not a bag is a BagError naming it. ``bag_info(path).text()`` is bag2map --info's report."""
    try:
        from .storage import open_bag
    except ImportError as e:  # rosbags missing: say what to install
        raise ImportError(f"reading ROS bags needs the 'rosbags' package (pip install rosbags): {e}") from e

    with open_bag(path) as reader:
        topics = reader.topics
        count = sum(t.msgcount for t in topics.values())
        start = end = None
        if count:
            start, end = reader.start_time / NS, reader.end_time / NS
        duration = 0.0 if start is None else end - start
        summaries = [TopicSummary(name, short_type(t.msgtype), t.msgcount, _rate(t.msgcount, duration),
                                  _role(t.msgtype)) for name, t in sorted(topics.items())]
        info = BagInfo(os.fspath(path), _storage(Path(path)), start, end, count, summaries,
                       _tf_tree(reader, topics), [], [])
        for name in topics_of_type(topics, SCAN_TYPES):
            first = _first_message(reader, topics[name], info.notes, name)
            info.scans.append(ScanSource(name, short_type(topics[name].msgtype), topics[name].msgcount,
                                         frame_name(first.header.frame_id) if first is not None else None))
        for name in topics_of_type(topics, POSE_TYPES):
            first = _first_message(reader, topics[name], info.notes, name)
            child = getattr(first, "child_frame_id", None)
            info.poses.append(PoseSource(name, short_type(topics[name].msgtype), topics[name].msgcount,
                                         frame_name(first.header.frame_id) if first is not None else None,
                                         frame_name(child) if child else None))
    _decide(info)
    return info


def _rate(count: int, duration: float) -> float | None:
    """Messages a second over the bag's duration: (count - 1) intervals of a topic recorded throughout."""
    return (count - 1) / duration if count > 1 and duration > 0 else None


def _role(msgtype: str) -> str:
    t = norm_type(msgtype)
    if t in SCAN_TYPES:
        return "scan"
    if t in POSE_TYPES:
        return "pose"
    if t in TF_TYPES:
        return "tf"
    return "sensor, not mapped" if t in UNSUPPORTED_SENSORS else ""


def _storage(p: Path) -> str:
    """What the bag is, by its name and files (open_bag has checked its first bytes)."""
    if p.is_dir():
        kinds = {x.suffix for x in p.iterdir()}
        store = "MCAP" if ".mcap" in kinds else "sqlite3" if ".db3" in kinds else "unknown storage"
        return f"ROS 2 bag directory ({store})"
    return {".bag": "ROS 1 bag", ".mcap": "ROS 2 MCAP file", ".db3": "ROS 2 sqlite3 file"}.get(p.suffix, "bag")


def _first_message(reader, topic, notes: list, name: str):
    """The topic's first message, deserialized; None when it has none or it cannot be read."""
    if not topic.msgcount:
        return None
    stream = reader.messages(connections=topic.connections)
    try:
        connection, t_ns, raw = next(stream)
        return reader.deserialize(raw, connection.msgtype)
    except Exception as err:  # rosbags raises many kinds: the report says so and goes on
        from .storage import reason

        notes.append(f"the first message of {name!r} cannot be read: {reason(err)}")
        return None
    finally:
        stream.close()


def _tf_tree(reader, topics) -> TfTree:
    """The tree from every /tf_static message (up to STATIC_LIMIT) and the first TF_HEAD and
    last TF_TAIL messages of /tf (all of them when there are no more)."""
    tree = TfTree()
    static = resolve_topic("/tf_static", topics)
    if static is not None and norm_type(topics[static].msgtype) in TF_TYPES:
        tree.static_total = topics[static].msgcount
        tree.static_read = _read_tf(reader, topics[static].connections, True, tree, STATIC_LIMIT)
    moving = resolve_topic("/tf", topics)
    if moving is None or norm_type(topics[moving].msgtype) not in TF_TYPES:
        return tree
    connections, total = topics[moving].connections, topics[moving].msgcount
    tree.tf_total = total
    if total <= TF_HEAD + TF_TAIL:
        tree.tf_read = _read_tf(reader, connections, False, tree, total)
        return tree
    tree.tf_read = _read_tf(reader, connections, False, tree, TF_HEAD)
    # the tail: the last stretch of the bag that holds about TF_TAIL /tf messages at its mean rate
    span = reader.end_time - reader.start_time
    start = reader.end_time - int(span * TF_TAIL / total) - 1
    tree.tf_read += _read_tf(reader, connections, False, tree, TF_TAIL, start)
    return tree


def _read_tf(reader, connections, static: bool, tree: TfTree, limit: int, start: int | None = None) -> int:
    """Adds up to limit tf messages (from receive time start) to the tree; how many it read."""
    done = 0
    stream = reader.messages(connections=connections, start=start)
    try:
        for connection, t_ns, raw in stream:
            if done >= limit:
                break
            try:
                tree.add(reader.deserialize(raw, connection.msgtype), static)
            except Exception as err:  # a damaged message: named, and the rest still read
                from .storage import reason

                tree.conflicts.append(f"a message on {connection.topic!r} received at {stamp_text(t_ns)} "
                                      f"cannot be read: {reason(err)}")
            done += 1
    finally:
        stream.close()
    return done


# ---- the command bag2map would run ---------------------------------------------------------


def _output_name(path: str) -> str:
    """The map a suggested command writes: the bag's name with .map for its storage suffix."""
    name = Path(path.rstrip("/")).name or "bag"
    for suffix in (".bag", ".mcap", ".db3"):
        if name.endswith(suffix):
            name = name[: -len(suffix)]
    return (name or "bag") + ".map"


def _listing(names) -> str:
    return ", ".join(repr(n) for n in names) or "none"


def _decide(info: BagInfo) -> None:
    """Sets info.command, info.refusal and info.notes by the rules bag2map's reader follows."""
    for conflict in info.tf.conflicts:
        info.notes.append(f"tf is not a tree: {conflict}")
    if not info.tf.complete:
        info.notes.append(f"the tf tree is from {info.tf.tf_read} of the {info.tf.tf_total} /tf messages (the "
                          "first and the last ones): a link published only in between is not shown")
    options: list[str] = []
    scans = _chosen_scans(info, options)
    if scans is None:
        return
    if info.tf.links:
        posed = _tf_options(info, scans, options)
    else:
        posed = _topic_options(info, scans, options, "the bag has no /tf or /tf_static transforms")
    if posed:
        _cloud_options(info, scans, options)
        info.command = ["bag2map", *options, info.path, _output_name(info.path)]


def _refuse(info: BagInfo, why: str) -> None:
    """Records why bag2map with no options refuses the bag (the first reason found)."""
    if info.refusal is None:
        info.refusal = why


def _chosen_scans(info: BagInfo, options: list) -> list | None:
    """The scan topics bag2map reads (adding --scan-topic when it must be named); None when
    there is nothing to map."""
    if not info.scans:
        sensors = [t.name for t in info.topics if t.role == "sensor, not mapped"]
        why = "no sensor_msgs/LaserScan, MultiEchoLaserScan or PointCloud2 topic"
        if sensors:
            why += f" (its sensors {_listing(sensors)} are neither laser scans nor point clouds)"
        _refuse(info, why)
        return None
    full = [s for s in info.scans if s.count]
    if not full:
        _refuse(info, f"the scan topics ({_listing(s.topic for s in info.scans)}) have no messages")
        return None
    if len(info.scans) > 1:
        _refuse(info, f"several scan topics ({_listing(s.topic for s in info.scans)}): --scan-topic chooses "
                      "one, or several to map together")
        for s in full:
            options += ["--scan-topic", s.topic]
    return full


def _tf_options(info: BagInfo, scans: list, options: list) -> bool:
    """Options for poses from tf; False when tf cannot pose the scans and no option can."""
    tree = info.tf
    known = set(tree.frames())
    lost = [s for s in scans if s.frame is not None and s.frame not in known]
    if lost:
        why = (f"the scans' frame {lost[0].frame!r} is not in the tf tree (frames: {_listing(sorted(known))})")
        return _topic_options(info, scans, options, why)
    roots = {tree.up(s.frame)[-1] for s in scans if s.frame is not None}
    if len(roots) > 1:
        _refuse(info, f"the scan topics' frames reach different tf roots ({_listing(sorted(roots))}): no one "
                      "frame holds them all")
        return False
    if not roots:
        return True  # no frame known (an unreadable first scan): the default, as bag2map would try
    root = roots.pop()
    if root != "map":
        if "map" in known:
            _refuse(info, f"'map' has no connection to the scans' frame {scans[0].frame!r} (its tf root is "
                          f"{root!r})")
            info.notes.append(f"--fixed-frame {root} maps in {root!r}, the root of the scans' tf tree")
        else:
            info.notes.append(f"no 'map' frame: the scans' tf tree has the root {root!r}, so the map is drawn in "
                              f"it (--fixed-frame {root})")
        options += ["--fixed-frame", root]
        if "odom" in root:
            info.notes.append("odometry drifts: for a SLAM-corrected map, give the SLAM poses with --poses FILE")
    if not any(_moving(tree, s.frame) for s in scans if s.frame is not None):
        info.notes.append(f"tf holds the scans' frame still (static links up to {root!r}): every scan at one pose")
    return True


def _moving(tree: TfTree, frame: str) -> bool:
    chain = tree.up(frame)
    return any(not tree.links[f].static for f in chain[:-1])


def _topic_options(info: BagInfo, scans: list, options: list, why: str) -> bool:
    """Options for poses from a pose topic, after why tf cannot give them; False without one."""
    if not info.poses:
        _refuse(info, f"{why}, and it has no pose topic: {_SLAM_HINT}; --static-pose X,Y,THETA maps a sensor "
                      "that does not move")
        return False
    pose = min(info.poses, key=lambda p: _POSE_PREFERENCE.index(norm_type(p.type)))
    _refuse(info, f"{why}; --pose-topic takes the robot's poses from a pose topic instead")
    options += ["--pose-topic", pose.topic]
    base = pose.child or "base_link"
    frame = scans[0].frame
    if frame is not None and frame != base and not _static_chain(info.tf, base, frame):
        options += ["--laser-mount", "X,Y,THETA"]
        info.notes.append(f"X,Y,THETA: the laser's pose in the robot's frame {base!r} (no static tf chain "
                          f"{base} -> {frame} gives it)")
    return True


def _static_chain(tree: TfTree, ancestor: str, frame: str) -> bool:
    """Whether frame hangs below ancestor by static links only."""
    chain = tree.up(frame)
    return ancestor in chain and all(tree.links[f].static for f in chain[:chain.index(ancestor)])


def _cloud_options(info: BagInfo, scans: list, options: list) -> None:
    """A point cloud's height band is in the base frame: it needs a static chain to the cloud."""
    base = next((options[k + 1] for k in range(len(options) - 1) if options[k] == "--base-frame"), None)
    base = base or next((p.child for p in info.poses if p.child), None) or "base_link"
    for s in scans:
        if norm_type(s.type) != "sensor_msgs/msg/PointCloud2" or s.frame is None or s.frame == base:
            continue
        if not _static_chain(info.tf, base, s.frame):
            _refuse(info, f"the point cloud {s.topic!r} has no static tf chain from the base frame {base!r} to "
                          f"its frame {s.frame!r}, which its height band (--z-band) needs")
            options += ["--base-frame", s.frame]
            info.notes.append(f"--base-frame {s.frame}: the height band in the cloud's own frame")
            return


# ---- the report ------------------------------------------------------------------------------


def _report(info: BagInfo) -> str:
    lines = [f"bag: {info.path} ({info.storage})"]
    if info.start is None:
        lines.append("messages: none")
    else:
        lines.append(f"time: {info.start:.3f} to {info.end:.3f} s ({info.duration:.3f} s), "
                     f"{info.message_count} messages")
    lines += ["", "topics (rate: mean over the bag's duration):"]
    lines += _table([[t.name, t.type, str(t.count), f"{t.rate_hz:.2f} Hz" if t.rate_hz else "-", t.role]
                     for t in info.topics]) or ["  none"]
    lines += ["", _tree_heading(info.tf)]
    lines += _tree_lines(info.tf)
    lines.append(f"roots (frames with no parent): {', '.join(info.tf.roots()) or 'none'}")
    lines += ["", "scan topics:"]
    lines += _table([[s.topic, s.type, f"{s.count} messages", f"frame {s.frame or '?'}",
                      _chain_text(info.tf, s.frame)] for s in info.scans]) or ["  none"]
    lines += ["", "pose sources:"]
    sources = [["tf", "/tf, /tf_static", f"{len(info.tf.links)} links", "", ""]] if info.tf.links else []
    sources += [[p.topic, p.type, f"{p.count} messages", f"frame {p.frame or '?'}",
                 f"child {p.child}" if p.child else ""] for p in info.poses]
    lines += _table(sources) or ["  none"]
    lines.append("")
    if info.refusal is not None:
        lines.append(f"bag2map with no options refuses it: {info.refusal}")
    if info.command is not None:
        lines.append("bag2map maps it with:" if info.refusal is None else "instead:")
        lines.append("  " + info.command_line())
    lines += [f"note: {n}" for n in info.notes]
    return "\n".join(lines) + "\n"


def _table(rows: list) -> list[str]:
    """Rows of cells as lines, each column as wide as its widest cell."""
    if not rows:
        return []
    widths = [max(len(r[k]) for r in rows) for k in range(len(rows[0]))]
    return ["  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]


def _tree_heading(tree: TfTree) -> str:
    if not tree.tf_total and not tree.static_total:
        return "tf tree: the bag has no /tf or /tf_static messages"
    read = f"all {tree.tf_total}" if tree.complete else f"{tree.tf_read} of {tree.tf_total} (the first and last)"
    static = f"all {tree.static_total}" if tree.static_read >= tree.static_total else \
        f"the first {tree.static_read} of {tree.static_total}"
    return f"tf tree ({read} /tf and {static} /tf_static messages read):"


def _tree_lines(tree: TfTree) -> list[str]:
    """Each frame under its parent, indented by depth, with how it is linked."""
    children: dict = {}
    for link in tree.links.values():
        children.setdefault(link.parent, []).append(link.child)
    lines: list[str] = []

    def walk(frame: str, depth: int, seen: set) -> None:
        link = tree.links.get(frame)
        how = "root" if link is None or depth == 0 else \
            f"parent {link.parent}, " + ("static" if link.static else f"moving, {link.count} transforms read")
        lines.append(f"  {'  ' * depth}{frame}  ({how})")
        for child in sorted(children.get(frame, ())):
            if child not in seen:
                walk(child, depth + 1, seen | {child})

    for root in tree.roots():
        walk(root, 0, {root})
    return lines


def _chain_text(tree: TfTree, frame: str | None) -> str:
    """'tf: map -> base_link -> laser, moving', or where the frame is missing."""
    if frame is None:
        return ""
    if frame not in tree.frames():
        return "not in tf"
    chain = tree.up(frame)
    return f"tf: {' -> '.join(reversed(chain))}, {'moving' if _moving(tree, frame) else 'static'}"
