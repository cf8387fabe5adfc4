"""The node's posing, without rclpy: a received scan read by its type's adapter (the message
table), kept waiting until tf has its transform map_frame -> its frame (a cloud until its
mount in base_frame is known), posed by tf lookups (one for all the waiting scans of a frame
whose stamps tf covers), refused past transform_timeout (or, with a path_topic, kept for a later
tf or Path: Unposed); stamps that go back in time (a bag played again) noticed; and the Path's
poses checked. The node (node.py) feeds it messages and maps what it gives back.
"""

from __future__ import annotations

import time

import numpy as np

from .. import _core
from .._errors import Error
from ..msgs.cloud import cloud_mount
from ..msgs.errors import BagError
from ..msgs.geometry import planar
from ..msgs.header import frame_name, stamp_ns, stamp_text
from ..msgs.laser import COUNT_KEYS
from ..msgs.path import path_poses
from ..msgs.scan_options import ScanSettings
from ..msgs.table import MessageType
from ..msgs.tf import TfBuffer, TfLinkIgnored, static_mount

__all__ = ["TIME_JUMP_S", "Pending", "Posing", "Refused", "ScanFilter", "TimeJumps", "Unposed", "scan_settings"]

# Seconds a stamp may lie behind the newest one of its source (a scan topic, a /tf link) before
# time counts as gone back: a driver's jitter or a reordered message stays far below a second,
# a bag played again or a simulator restarted goes back by its whole run.
TIME_JUMP_S = 1.0


class Refused(Error):
    """A message the node does not map; the text names the topic and stamp, cause the kind."""

    code = "bad input"

    def __init__(self, text: str, cause: str = "bad messages"):
        super().__init__(text)
        self.cause = cause


class Pending:
    """A scan waiting for its transform until the deadline (monotonic seconds)."""

    __slots__ = ("topic", "ns", "reading", "deadline", "received", "kind", "msg")

    def __init__(self, topic, ns, reading, deadline, received, kind: MessageType, msg=None):
        self.topic, self.ns, self.reading, self.deadline = topic, ns, reading, deadline
        self.received = received  # when received, on perf_counter's clock (DDS's time in a batch)
        self.kind = kind
        self.msg = msg  # a message waiting for its mount (reading is None until read)


# Bytes a scan waiting for a pose counts besides its ranges (as LiveMap's _SCAN_BYTES: stamp,
# pose, mount, angles).
_UNPOSED_BYTES = 8 * 9


class Unposed:
    """Scans that tf gave no pose within transform_timeout, kept (where a Path may still come)
    until a later /tf or a Path covers their stamps. room(): the bytes they may hold (the
    session's max_memory less what the map stores; None: no limit); past it the oldest are
    dropped, each passed to dropped(pending)."""

    def __init__(self, room=lambda: None, dropped=lambda p: None):
        self.room, self.dropped = room, dropped
        self.scans: list[Pending] = []  # oldest first
        self.bytes = 0

    def __len__(self) -> int:
        return len(self.scans)

    @staticmethod
    def size(p: Pending) -> int:
        return p.reading.ranges.nbytes + _UNPOSED_BYTES

    def add(self, p: Pending) -> None:
        self.scans.append(p)
        self.bytes += self.size(p)
        self.fit()

    def fit(self) -> None:
        """Drops the oldest while they hold more than room() (the newest may go too)."""
        room = self.room()
        while self.scans and room is not None and self.bytes > room:
            self.bytes -= self.size(self.scans[0])
            self.dropped(self.scans.pop(0))

    def keep_only(self, kept: list) -> None:
        self.scans = kept
        self.bytes = sum(self.size(p) for p in kept)

    def clear(self) -> None:
        self.keep_only([])


def laser_poses_on_path(scans: list, path_ns, path_poses, max_gap_ns: int, mount_of) -> list:
    """The laser pose of each scan (Pending, read) on a Path of base poses: interpolated at its
    stamp as LiveMap.repose moves a stored scan (_core._repose), composed with its mount
    (mount_of(frame), None: unknown); None for a scan the Path does not pose (outside its span,
    in a gap, no mount)."""
    if not scans or len(path_ns) == 0:
        return [None] * len(scans)
    ns = np.fromiter((p.ns for p in scans), dtype=np.int64, count=len(scans))
    mounts = np.array([(np.nan,) * 3 if m is None else m for m in (mount_of(p.reading.frame) for p in scans)],
                      dtype=np.float64).reshape(-1, 3)
    out = np.full((len(scans), 3), np.nan)
    _core._repose(np.asarray(path_ns, dtype=np.int64), np.ascontiguousarray(path_poses, dtype=np.float64),
                  ns, mounts, out, int(max_gap_ns))
    return [row if np.isfinite(row).all() else None for row in out]


def scan_settings(s) -> ScanSettings:
    """The scan adapters' options from the node's settings."""
    return ScanSettings(no_return=s.no_return, echo=s.echo, z_band=tuple(float(v) for v in s.z_band),
                        cloud_angle_step=s.cloud_angle_step, cloud_range_max=float(s.cloud_range_max))


class ScanFilter:
    """slam_toolbox's throttle_scans and minimum_time_interval, per topic: of the scans of a
    topic, every Nth is taken (the first too), and of those, one whose stamp is within the
    interval of the last one taken is skipped."""

    def __init__(self):
        self.count: dict[str, int] = {}
        self.last: dict[str, int] = {}  # the stamp (ns) of the last scan taken

    def skip(self, topic: str, ns: int, throttle: int, interval_s: float) -> str | None:
        """None for a scan to map; else the cause of its skipping, as the summary counts it."""
        n = self.count.get(topic, 0)
        self.count[topic] = n + 1
        if n % throttle:
            return "scans skipped by throttle_scans"
        last = self.last.get(topic)
        if last is not None and abs(ns - last) < interval_s * 1e9:
            return "scans within minimum_time_interval"
        self.last[topic] = ns
        return None


class TimeJumps:
    """Stamps going back in time, per source (a scan topic, a /tf link): each source's newest
    stamp, and how far a new one lies behind it. A source's own stamps are compared (not all
    sources' together): a link published late, or stamped behind the others, is no jump."""

    def __init__(self, bound_s: float = TIME_JUMP_S):
        self.bound_ns = int(bound_s * 1e9)
        self.newest: dict = {}  # source -> its newest stamp (ns)

    def back(self, source, ns: int) -> int:
        """How far (ns) stamp ns of source lies behind that source's newest, where more than the
        bound; else 0. Either way ns counts as seen."""
        last = self.newest.get(source)
        if last is None or ns >= last:
            self.newest[source] = ns
            return 0
        return last - ns if last - ns > self.bound_ns else 0

    def ahead_of(self, ns: int) -> int:
        """How far (ns) the newest stamp seen lies ahead of ns (a /clock that went back to ns),
        where more than the bound; else 0. 0 too where the stamps seen since the last clear are
        already the new ones (the scans told of the jump before /clock did)."""
        ahead = max(self.newest.values(), default=ns) - ns
        return ahead if ahead > self.bound_ns else 0

    def clear(self) -> None:
        self.newest.clear()


class Posing:
    """The scans waiting for their poses. settings_of(): the node's current settings; name_of(topic):
    the topic's resolved name (for the texts); refuse(topic, cause, text): counts and logs a
    message not mapped; jumped(where, back_ns): stamps went back by more than TIME_JUMP_S (called
    before the message that went back is taken); unposed: where scans that tf gave no pose in
    time wait for a Path (with a path_topic; without one they are refused)."""

    def __init__(self, settings_of, name_of, refuse, jumped=None, unposed: Unposed | None = None, kept=None):
        self.settings_of, self.name_of, self.refuse = settings_of, name_of, refuse
        self.kept = kept or (lambda topic, text: None)  # a scan given up as to tf, kept for a Path
        self.jumped = jumped or (lambda where, back_ns: None)
        self.unposed = unposed if unposed is not None else Unposed()
        self.jumps = TimeJumps()
        self._statics: dict = {}  # child frame -> its latest /tf_static transform: kept over a clear
        self.tf = self._new_tf()
        self.pending: list[Pending] = []
        self.range_counts = dict.fromkeys(COUNT_KEYS, 0)
        self._mounts: dict[str, np.ndarray | None] = {}
        self._scan_settings = (None, None)  # (the node's settings, their ScanSettings)

    def _options(self) -> ScanSettings:
        s = self.settings_of()
        if self._scan_settings[0] is not s:
            self._scan_settings = (s, scan_settings(s))
        return self._scan_settings[1]

    def _new_tf(self) -> TfBuffer:
        tf = TfBuffer(stamp_name="scan stamp", keep=self.settings_of().tf_buffer_duration)
        for ts in self._statics.values():
            tf.add_transform(ts, True)
        return tf

    def clear_time(self) -> None:
        """Time went back: tf's history of /tf dropped (its samples belong to the time before),
        /tf_static kept, as tf2 clears its buffer on a jump back; the newest stamps forgotten."""
        self.tf = self._new_tf()
        self.jumps.clear()

    def stamp_seen(self, source, ns: int, where) -> None:
        """A stamp of source (("scan", topic) or ("tf", child frame)); where() names it for the
        log. Calls jumped when it lies more than TIME_JUMP_S behind the source's newest."""
        back = self.jumps.back(source, ns)
        if back:
            self.jumped(where(), back)
            self.jumps.back(source, ns)  # the new time's first stamp

    def add_tf(self, msg, static: bool) -> None:
        """A TFMessage; BagError for transforms refused."""
        if not static:
            for ts in msg.transforms:
                child = ts.child_frame_id
                self.stamp_seen(("tf", child), stamp_ns(ts.header.stamp), lambda c=child: f"/tf (frame {c!r})")
            self.tf.add_message(msg, False)
            return
        # one by one, as add_message goes: only the links the tree took are kept for its rebuild
        # after a time jump (a refused one would be refused again there, out of a scan's callback)
        ignored = None
        try:
            for ts in msg.transforms:
                try:
                    self.tf.add_transform(ts, True)
                    self._statics[frame_name(ts.child_frame_id)] = ts
                except TfLinkIgnored as e:  # left out; the message's other links still taken
                    ignored = ignored or e
        finally:
            self._mounts.clear()
        if ignored is not None:
            raise ignored

    def add_scan(self, msg, topic: str, kind: MessageType, received: float | None) -> None:
        """A scan message of kind on topic: read now (a type that needs its mount, once that is
        known) and kept until its pose is. received: when DDS received it (perf_counter)."""
        ns = stamp_ns(msg.header.stamp)
        reading = None
        if not kind.mount:
            try:
                # the scan's name made only for a refusal: per scan it cost more than the reading
                reading = kind.read(msg, self._options(), self.range_counts,
                                    lambda what: Refused(f"{self.name_of(topic)}: {kind.noun} at stamp "
                                                         f"{stamp_text(ns)} {what}"))
            except Refused as e:
                self.refuse(topic, f"bad {kind.noun}s", f"{e}; not mapped")  # the first of each topic
                return
            msg = None
        now = time.perf_counter()
        received = now if received is None else min(received, now)  # a batch's: when DDS received it
        deadline = time.monotonic() - (now - received) + self.settings_of().transform_timeout
        self.pending.append(Pending(topic, ns, reading, deadline, received, kind, msg))

    def _where(self, p: Pending) -> str:
        noun = p.kind.noun if p.msg is not None else "scan"
        return f"{self.name_of(p.topic)}: {noun} at stamp {stamp_text(p.ns)}"

    def _read_waiting(self, p: Pending) -> bool:
        """Reads a message that waited for its mount; False while the mount is not known yet.
        Raises Refused for one that cannot be read."""
        s, frame = self.settings_of(), frame_name(p.msg.header.frame_id)
        try:
            mount = cloud_mount(self.tf, s.base_frame, frame)
        except BagError as e:
            if time.monotonic() < p.deadline:
                return False
            raise Refused(f"{self._where(p)} not mapped: its height band is in {s.base_frame!r}, and "
                          f"there is no /tf_static chain {s.base_frame} -> {frame!r} within "
                          f"transform_timeout: {e.message}", f"{p.kind.noun}s without a mount") from None
        where = self._where(p)
        p.reading = p.kind.read(p.msg, self._options(), self.range_counts,
                                lambda what: Refused(f"{where} {what}; not mapped", f"bad {p.kind.noun}s"), mount)
        p.msg = None
        return True

    def mount(self, frame: str):
        """The laser frame in base_frame from /tf_static (cached until /tf_static changes)."""
        if frame not in self._mounts:
            try:
                self._mounts[frame] = static_mount(None, self.tf, self.settings_of().base_frame, frame)
            except BagError:
                self._mounts[frame] = None
        return self._mounts[frame]

    def take_posed(self) -> list:
        """[(pending, laser pose)] of every waiting scan whose transform is there, in the order
        they were taken; drops those past their deadline, keeps the others waiting."""
        now, keep, ready = time.monotonic(), [], []
        for p in self.pending:
            if p.msg is not None:
                try:
                    if not self._read_waiting(p):
                        keep.append(p)
                        continue
                except Refused as e:
                    self.refuse(p.topic, e.cause, str(e))
                    continue
            ready.append(p)
        by_frame: dict[str, list[Pending]] = {}
        for p in ready:
            by_frame.setdefault(p.reading.frame, []).append(p)
        posed = {}  # id(pending) -> laser pose
        for frame, waiting in by_frame.items():
            self._pose_frame(frame, waiting, now, keep, posed)
        self.pending = keep
        ready += self._unposed_by_tf(posed)
        # in the order they were taken: each topic's in the order they came, a batch's topic by
        # topic (sorted by DDS's reception times, the first scans of a replay came out of order)
        return [(p, posed[id(p)]) for p in ready if id(p) in posed]

    def _pose_frame(self, frame: str, waiting: list, now: float, keep: list, posed: dict) -> None:
        """The laser poses of the waiting scans in one frame, by one tf lookup where every stamp
        has its transform; the others one by one (each kept, or refused past its deadline)."""
        target = self.settings_of().map_frame
        ns = np.fromiter((p.ns for p in waiting), dtype=np.int64, count=len(waiting))
        wait = self.tf.waiting_for(target, frame, ns)  # its /tf not there yet: no lookup until it is
        try:
            ok = ~wait & self.tf.covers(target, frame, ns)
        except BagError:  # no chain to the frame (yet): each scan's own lookup says why
            ok = np.zeros(len(ns), dtype=bool)
        if ok.any():
            try:
                t, q = self.tf.lookup(target, frame, ns[ok])
                poses = planar(None, t, q, f"the laser frame {frame!r} in {target!r}")
                for p, pose in zip((p for p, k in zip(waiting, ok) if k), poses):
                    posed[id(p)] = pose
            except BagError:  # one of them refused (upside down): each its own below
                ok[:] = False
        for p, k, w in zip(waiting, ok, wait):
            if k:
                continue
            if w and now < p.deadline:
                keep.append(p)
                continue
            pose = self._pose_one(p, now)
            if pose is not None:
                posed[id(p)] = pose
            elif now < p.deadline:
                keep.append(p)

    def _unposed_by_tf(self, posed: dict) -> list:
        """The scans given up as to tf whose transform has come since: posed (one lookup a
        frame, over the stamps tf now covers), taken from Unposed and returned; the others stay."""
        if not self.unposed.scans:
            return []
        target, taken = self.settings_of().map_frame, []
        by_frame: dict[str, list[Pending]] = {}
        for p in self.unposed.scans:
            by_frame.setdefault(p.reading.frame, []).append(p)
        for frame, waiting in by_frame.items():
            ns = np.fromiter((p.ns for p in waiting), dtype=np.int64, count=len(waiting))
            try:
                ok = ~self.tf.waiting_for(target, frame, ns) & self.tf.covers(target, frame, ns)
                if not ok.any():
                    continue
                t, q = self.tf.lookup(target, frame, ns[ok])
                poses = planar(None, t, q, f"the laser frame {frame!r} in {target!r}")
            except BagError:  # no chain yet, or a pose refused: they wait for a Path
                continue
            for p, pose in zip((p for p, k in zip(waiting, ok) if k), poses):
                posed[id(p)] = pose
                taken.append(p)
        if taken:
            gone = {id(p) for p in taken}
            self.unposed.keep_only([p for p in self.unposed.scans if id(p) not in gone])
        return taken

    def take_on_path(self, path_ns, path_poses, max_gap_ns: int) -> list:
        """[(pending, laser pose)] of the scans still without a pose (waiting for tf, or given up
        as to tf) that a Path poses, taken from both; the others stay as they were."""
        posed = []
        for store in (self.pending, self.unposed.scans):
            read = [p for p in store if p.msg is None]
            poses = laser_poses_on_path(read, path_ns, path_poses, max_gap_ns, self.mount)
            posed += [(p, pose) for p, pose in zip(read, poses) if pose is not None]
        if posed:
            gone = {id(p) for p, _ in posed}
            self.pending = [p for p in self.pending if id(p) not in gone]
            self.unposed.keep_only([p for p in self.unposed.scans if id(p) not in gone])
        return posed

    def _pose_one(self, p: Pending, now: float):
        """One scan's laser pose; None while it has none (refused once past its deadline)."""
        s = self.settings_of()
        try:
            t, q = self.tf.lookup(s.map_frame, p.reading.frame, [p.ns])
            return planar(None, t, q, f"the laser frame {p.reading.frame!r} in {s.map_frame!r}")[0]
        except BagError as e:
            if now >= p.deadline:
                where = f"{self.name_of(p.topic)}: scan at stamp {stamp_text(p.ns)}"
                why = f"no transform within transform_timeout {s.transform_timeout:g} s: {e.message}"
                if s.path_topic:  # a later /tf or Path may pose it
                    self.unposed.add(p)
                    self.kept(p.topic, f"{where}: {why}; it waits for a pose from a later /tf or a Path on "
                                       f"{self.name_of(s.path_topic)}")
                else:
                    self.refuse(p.topic, "scans without a transform", f"{where} not mapped: {why}")
            return None


def check_path(path, map_frame: str, topic: str):
    """(stamps, base poses) of a Path read as arrays (path_cdr.PathArrays); Refused naming the
    topic and stamp for a Path in another frame, a pose in another frame or not a number."""
    return path_poses(path, map_frame, topic, Refused)
