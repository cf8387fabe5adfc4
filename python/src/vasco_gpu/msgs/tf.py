"""tf's frame tree: TfBuffer takes TFMessages (from a bag's /tf and /tf_static, or live from a
ROS 2 node's subscriptions) and looks up the transform between two frames at given stamps."""

from __future__ import annotations

import numpy as np

from .errors import BagError, TfError
from .geometry import compose, inverse, is_identity, planar, slerp, unit_quaternion
from .header import NS, did_you_mean, frame_name, stamp_ns, stamp_seconds, stamp_text
from .series import bracket, first_outside

__all__ = ["TfBuffer", "TfLinkIgnored", "static_mount"]

# The stamps a tf message can carry: builtin_interfaces/Time's sec is an int32 (ROS 1's time a
# uint32), its nanosec a uint32. Any two such stamps are less than 2^63 ns apart, so the int64
# arithmetic on them (spans, gaps, interpolation, keep) cannot overflow; a stamp beyond them is
# no ROS time and would wrap around.
MIN_STAMP_NS = -(2**31) * NS
MAX_STAMP_NS = (2**32 - 1) * NS + (2**32 - 1)

# The largest translation a link may have, in metres: seven times the sun's distance, beyond any
# frame a robot uses (ECEF and UTM coordinates are below 1e7 m), and float64 still resolves a
# quarter millimetre there. A chain of such links cannot overflow float64 when composed or
# interpolated (1e308 m could), so every lookup gives finite numbers.
MAX_TRANSLATION = 1e12

# Frames an error lists at most: a tree of thousands of frames keeps the message readable.
LISTED_FRAMES = 20
# Frames beyond which a missing frame gets no "did you mean": difflib compares the name with
# every frame (half a second for 20,000 alike names), in a lookup a live node repeats while it
# waits for a transform.
CLOSE_MATCH_FRAMES = 2000


class TfLinkIgnored(TfError):
    """A link the tree leaves out while it keeps every other: a self transform (parent and child
    the same frame, which tf2 drops too) or a link that would close a cycle (a reversed
    ``base_link -> map`` while ``map -> base_link`` is there). Nothing of it is stored, so the
    links already there go on answering; a reader that goes on (the node, bag2map) reports it
    once per ``kind``: "self link" or "cycle"."""

    def __init__(self, file, message: str, *, kind: str, topic: str | None = None, stamp: float | None = None):
        super().__init__(file, message, topic=topic, stamp=stamp)
        self.kind = kind

    def __reduce__(self):
        return (_make_ignored, (self.file, self.message, self.kind, self.topic, self.stamp))


def _make_ignored(file, message, kind, topic, stamp):
    return TfLinkIgnored(file, message, kind=kind, topic=topic, stamp=stamp)


class _Edge:
    """One parent -> child link of tf: a static transform, or a time series of samples.

    The samples live in NumPy buffers that grow by doubling. While they arrive in stamp order
    (a live /tf's, most bags'), arrays() gives views of them, so a live lookup per scan costs a
    binary search, not a sort and copy of the link's whole history (~50 us a scan at 40 Hz with
    60 s kept); samples out of order are sorted once per change."""

    def __init__(self, parent: str, child: str, static: bool, keep_ns: int | None = None,
                 file=None, refuse_repeats: bool = False):
        self.parent, self.child, self.static = parent, child, static
        self.keep_ns, self.file, self.refuse_repeats = keep_ns, file, refuse_repeats
        self._times = np.empty(16, dtype=np.int64)
        self._values = np.empty((16, 7))  # tx ty tz qx qy qz qw per sample
        self._n = 0
        self._in_order = True  # every stamp greater than the one before (none repeated)
        self._arrays = None  # sorted copies, while samples came out of order
        self.newest = None  # the newest stamp (ns), None before the first sample: waiting_for's

    def __len__(self) -> int:
        return self._n

    def add(self, ns: int, t, q) -> None:
        if self.static:  # the latest static transform wins, as in tf2; fresh buffers, so that
            self._n, self.newest = 0, None  # arrays() given out before keep what they were
            self._times, self._values, self._in_order = np.empty(1, dtype=np.int64), np.empty((1, 7)), True
        if self._n == len(self._times):
            self._grow(2 * self._n)
        self._in_order = self._in_order and (self.newest is None or ns > self.newest)
        self.newest = ns if self.newest is None else max(self.newest, ns)
        self._times[self._n] = ns
        self._values[self._n, :3], self._values[self._n, 3:] = t, q
        self._n += 1
        self._arrays = None
        if self.keep_ns is not None and self._n % 256 == 0:
            self._forget()

    def _grow(self, capacity: int) -> None:
        # new buffers, not resized ones: views that arrays() gave out stay valid
        times, values = np.empty(capacity, dtype=np.int64), np.empty((capacity, 7))
        times[:self._n], values[:self._n] = self._times[:self._n], self._values[:self._n]
        self._times, self._values = times, values

    def _forget(self) -> None:
        """Drops the samples older than the newest less keep_ns (a live buffer's bounded history,
        as tf2's cache time), keeping two at least."""
        times, vals = self._sorted()
        keep = times >= times[-1] - self.keep_ns
        keep[-2:] = True
        self._times, self._values = times[keep], vals[keep]  # copies (fancy indexing): fresh buffers
        self._n, self._in_order, self._arrays = len(self._times), True, None

    def _sorted(self):
        """(stamps (k,), values (k, 7)) sorted by stamp, one sample a stamp (the later one
        recorded for a repeated stamp)."""
        times, vals = self._times[:self._n], self._values[:self._n]
        if self._in_order:
            return times, vals
        order = np.argsort(times, kind="stable")
        times, vals = times[order], vals[order]
        keep = np.append(times[1:] != times[:-1], True)
        return times[keep], vals[keep]

    def arrays(self):
        """(stamps (k,), translations (k, 3), quaternions (k, 4)) sorted by stamp, read-only
        views; two samples at one stamp that differ are a TfError when the buffer refuses
        repeats (a bag's: two publishers of one link), else the later one is taken (a live
        buffer, as tf2 goes on)."""
        if self._arrays is None:
            times, vals = self._sorted()
            if self.refuse_repeats and len(times) < self._n:
                self._check_repeats()
            arrays = (times, vals[:, :3], vals[:, 3:])
            for a in arrays:
                a.flags.writeable = False
            if not self._in_order:  # a sort's copies are kept until the next sample
                self._arrays = arrays
            return arrays
        return self._arrays

    def _check_repeats(self) -> None:
        times, vals = self._times[:self._n], self._values[:self._n]
        order = np.argsort(times, kind="stable")
        t, v = times[order], vals[order]
        differ = (t[1:] == t[:-1]) & (v[1:] != v[:-1]).any(axis=1)
        if differ.any():
            k = int(np.argmax(differ))
            raise TfError(self.file, f"tf {self.parent} -> {self.child} has two different samples at stamp "
                                     f"{stamp_text(int(t[k]))}: {tuple(v[k].tolist())} and {tuple(v[k + 1].tolist())} "
                                     "(two publishers of one link?)", topic="/tf", stamp=stamp_seconds(int(t[k])))

    def span_text(self) -> str:
        ns = self.arrays()[0]
        return f"[{stamp_text(ns[0])}, {stamp_text(ns[-1])}]"


class TfBuffer:
    """tf's frame tree from TFMessages, with lookups at stamps in whole nanoseconds.

    Feed it with :meth:`add_message` (a ``tf2_msgs/TFMessage`` or anything shaped like one:
    ``.transforms``, each with ``.header.frame_id``, ``.header.stamp.sec`` / ``.nanosec``,
    ``.child_frame_id``, ``.transform.translation`` and ``.transform.rotation``), in any order
    and at any time; then :meth:`lookup` gives ``T_target_source`` at stamps. As in tf2, each
    frame has one parent; a static link (``/tf_static``) holds its latest transform at every
    stamp, a dynamic one (``/tf``) is interpolated between its samples (linear translation,
    slerp) and never extrapolated.

    ``max_gap`` (seconds, default None: no limit) refuses a stamp between two samples of a link
    further apart than that: tf2's buffer keeps 10 s of history, so a live lookup across a wider
    gap finds the older sample gone.

    ``keep`` (seconds, default None: every sample, a bag's whole history) bounds what a live
    buffer holds: a link forgets its samples older than its newest less ``keep`` (tf2's cache
    time, 10 s by default).

    ``refuse_repeats``: two samples of a link at one stamp that differ are a TfError (a bag's
    recording of two publishers of one link) instead of the later one winning.

    ``file``, ``stamp_name`` and ``outside_hint`` shape the error messages only: the bag the
    transforms come from (None when fed live), what the looked-up stamps are, and a hint added
    to the error for a stamp outside a link's samples (or in a gap). Errors are :class:`TfError`.
    """

    def __init__(self, file=None, *, stamp_name: str = "stamp", outside_hint: str = "",
                 max_gap: float | None = None, keep: float | None = None, refuse_repeats: bool = False):
        self.file = file
        self.refuse_repeats = refuse_repeats
        self.keep_ns = _duration_ns(keep, "keep")
        self.stamp_name = stamp_name
        self.outside_hint = outside_hint
        self.max_gap_ns = _duration_ns(max_gap, "max_gap")
        self._edges: dict[str, _Edge] = {}  # by child: each child has one parent
        self._parents: set[str] = set()  # frames with a child: only such a frame can close a cycle

    def __len__(self) -> int:
        """The number of parent -> child links."""
        return len(self._edges)

    def add_message(self, msg, static: bool = False, topic: str | None = None) -> None:
        """Adds the transforms of one TFMessage; static: it came on /tf_static. topic (default
        /tf or /tf_static) is named by the errors. A link left out (TfLinkIgnored) does not stop
        the others, as tf2 takes each transform of a message on its own: the first one left out
        is raised once the rest are in. Any other TfError stops the message where it is."""
        ignored = None
        for ts in msg.transforms:
            try:
                self.add_transform(ts, static, topic)
            except TfLinkIgnored as e:
                ignored = ignored or e
        if ignored is not None:
            raise ignored

    def add_transform(self, ts, static: bool = False, topic: str | None = None) -> None:
        """Adds one TransformStamped (or anything shaped like one)."""
        if topic is None:
            topic = "/tf_static" if static else "/tf"
        parent, child = frame_name(ts.header.frame_id), frame_name(ts.child_frame_id)
        ns = stamp_ns(ts.header.stamp)
        if parent == child:  # tf2's TF_SELF_TRANSFORM: dropped whatever its numbers
            raise TfLinkIgnored(self.file, f"{_link_text(parent, child, ns, topic)} links a frame to itself: "
                                           "ignored, as tf2 does", kind="self link", topic=topic,
                                stamp=_seconds_or_none(ns))
        if not MIN_STAMP_NS <= ns <= MAX_STAMP_NS:  # checked first: no edge is made for it
            raise TfError(self.file, f"{_link_text(parent, child, ns, topic)}: the stamp is not a ROS time (sec "
                                     f"{ts.header.stamp.sec}, nanosec {ts.header.stamp.nanosec})", topic=topic)
        tr, rot = ts.transform.translation, ts.transform.rotation
        t = (float(tr.x), float(tr.y), float(tr.z))
        if not all(abs(v) <= MAX_TRANSLATION for v in t):  # NaN too
            raise TfError(self.file, f"{_link_text(parent, child, ns, topic)} has translation {t}: not a finite "
                                     f"number of metres up to {MAX_TRANSLATION:g}", topic=topic,
                          stamp=stamp_seconds(ns))
        # the link's name made only for a refusal: per /tf message it cost more than the checks
        q = unit_quaternion((rot.x, rot.y, rot.z, rot.w), lambda: _link_text(parent, child, ns, topic), self.file,
                            TfError)
        edge = self._edges.get(child)
        if edge is None:
            if child in self._parents:  # a frame without children is no one's ancestor: no walk
                self._check_no_cycle(parent, child, ns, topic)
            edge = self._edges[child] = _Edge(parent, child, static, self.keep_ns, self.file,
                                              self.refuse_repeats)
            self._parents.add(parent)
        elif edge.parent != parent:
            was = f"{edge.parent!r} on {'/tf_static' if edge.static else '/tf'}"
            raise TfError(self.file, f"frame {child!r} has two parents in tf: {was} and {parent!r} on "
                                     f"{topic} (stamp {stamp_text(ns)}); tf must be a tree",
                          topic=topic, stamp=stamp_seconds(ns))
        elif edge.static != static:
            raise TfError(self.file, f"tf {parent} -> {child} is on both /tf and /tf_static (stamp "
                                     f"{stamp_text(ns)} on {topic}); a link is either static or not",
                          topic=topic, stamp=stamp_seconds(ns))
        edge.add(ns, t, q)

    def _check_no_cycle(self, parent: str, child: str, ns: int, topic: str) -> None:
        """TfLinkIgnored when child is already above parent: the new link would close a loop,
        and every lookup through it would fail. Refused as it arrives, as a second parent is,
        so the tree stays a tree."""
        chain = self.up(parent)
        if child in chain:
            down = chain[chain.index(child)::-1]  # child down to parent, as the links there run
            raise TfLinkIgnored(self.file, f"{_link_text(parent, child, ns, topic)} would close a cycle: "
                                           f"{_chain_text(down)} is already in tf; "
                                           "refused (tf must be a tree), the links there are kept",
                                kind="cycle", topic=topic, stamp=stamp_seconds(ns))

    def frames(self) -> list[str]:
        """Every frame named by a link, sorted."""
        return sorted({e.child for e in self._edges.values()} | {e.parent for e in self._edges.values()})

    def up(self, frame: str) -> list[str]:
        """frame, its parent, grandparent, ... up to its root."""
        chain = [frame]
        while chain[-1] in self._edges:
            chain.append(self._edges[chain[-1]].parent)
            if len(chain) > len(self._edges) + 1:
                raise TfError(self.file, f"tf has a cycle through {frame!r}")
        return chain

    def root(self, frame: str) -> str:
        """The root of frame's tree (frame itself when it has no parent)."""
        return self.up(frame)[-1]

    def _reach_text(self, frame: str) -> str:
        """'laser' reaches 'odom' via base_link / 'map' is the root of its tree."""
        chain = self.up(frame)
        if len(chain) == 1:
            return f"{frame!r} is the root of another tree"
        via = f" via {_listing(chain[1:-1])}" if len(chain) > 2 else ""
        return f"{frame!r} reaches {chain[-1]!r}{via}"

    def _no_chain_text(self, target: str, source: str) -> str:
        """Why target and source are not connected, naming the missing link."""
        known = set(self.frames())
        if source not in known and target not in known:
            why = f"neither {source!r} nor {target!r} is in tf"
        elif source not in known:
            why = f"{source!r} is not in tf"
        elif target not in known:
            why = f"{self._reach_text(source)}, {target!r} has no connection to it"
        else:
            why = f"{self._reach_text(source)}, {self._reach_text(target)}"
        missing = [f for f in (source, target) if f not in known]
        hint = did_you_mean(missing[0], known) if missing and len(known) <= CLOSE_MATCH_FRAMES else ""
        return (f"no transform chain from {target!r} to {source!r}: {why}{hint} (frames in /tf: "
                f"{_listing(sorted(known))})")

    def _path_between(self, target: str, source: str) -> tuple[list[str], list[str]]:
        """(frames from source up to the common ancestor, frames from target up to it); a
        TfError naming the missing link when the two are not in one tree."""
        up_s, up_t = self.up(source), self.up(target)
        on_t = set(up_t)  # once: a deep chain is linear, not quadratic
        common = next((f for f in up_s if f in on_t), None)
        if common is None:
            raise TfError(self.file, self._no_chain_text(target, source))
        return up_s[: up_s.index(common) + 1], up_t[: up_t.index(common) + 1]

    def _edge_at(self, edge: _Edge, ns: np.ndarray):
        """The edge's transform at stamps ns: None for an identity static link (to be skipped),
        the sample itself on an exact stamp hit, interpolated between the bracketing samples."""
        times, tr, qs = edge.arrays()
        if edge.static:
            if is_identity(tr[0], qs[0]):
                return None
            n = len(ns)
            return np.broadcast_to(tr[0], (n, 3)), np.broadcast_to(qs[0], (n, 4))
        bad = first_outside(times, ns)
        if bad is not None:
            hint = f" ({self.outside_hint})" if self.outside_hint else ""
            raise TfError(self.file, f"{self.stamp_name} {stamp_text(bad)} is outside the time span "
                                     f"{edge.span_text()} of tf {edge.parent} -> {edge.child} "
                                     f"({len(times)} samples); tf is not extrapolated{hint}",
                          topic="/tf", stamp=stamp_seconds(bad))
        hit, i, lo, hi, f = bracket(times, ns)
        if hit.all():  # every stamp on a sample (a live scan's /tf often is): the samples unchanged
            return tr[i], qs[i]
        gap = self._in_gap(times, ns, hit, lo, hi)
        if gap.any():
            k = int(np.argmax(gap))
            hint = f" ({self.outside_hint})" if self.outside_hint else ""
            wide = (times[hi[k]] - times[lo[k]]) * 1e-9
            raise TfError(self.file, f"{self.stamp_name} {stamp_text(ns[k])} falls in a gap of {wide:.3f} s "
                                     f"between samples {stamp_text(times[lo[k]])} and {stamp_text(times[hi[k]])} "
                                     f"of tf {edge.parent} -> {edge.child}, wider than {self.max_gap_ns * 1e-9:g} s "
                                     f"(tf2 keeps {self.max_gap_ns * 1e-9:g} s of history: it has no transform "
                                     f"there){hint}", topic="/tf", stamp=stamp_seconds(ns[k]))
        t = tr[lo] + (tr[hi] - tr[lo]) * f[:, None]
        q = slerp(qs[lo], qs[hi], f)
        t[hit], q[hit] = tr[i[hit]], qs[i[hit]]  # exact hits: the sample unchanged
        return t, q

    def _down(self, chain: list[str], ns: np.ndarray, static_only: bool):
        """T_ancestor_frame for chain = [frame, ..., ancestor], composed from the ancestor down;
        None when every link is an identity static transform. Identity static links are skipped,
        not multiplied, so an identity mount leaves the pose's bits unchanged. With static_only,
        a dynamic link is a TfError."""
        total = None
        for child in reversed(chain[:-1]):
            edge = self._edges[child]
            if static_only and not edge.static:
                raise TfError(self.file, f"tf {edge.parent} -> {edge.child} is on /tf: not a static chain")
            link = self._edge_at(edge, ns)
            if link is not None:
                total = link if total is None else compose(total, link)
        return total

    def _in_gap(self, times, ns, hit, lo, hi) -> np.ndarray:
        """Which stamps (within the span, located by bracket) lie in a gap wider than max_gap."""
        if self.max_gap_ns is None:
            return np.zeros(len(ns), dtype=bool)
        return ~hit & ((times[hi] - times[lo]) > self.max_gap_ns)

    def _moving(self, target: str, source: str) -> list[_Edge]:
        """The /tf links on the chain between the two frames."""
        up_s, up_t = self._path_between(target, source)
        return [self._edges[c] for chain in (up_s, up_t) for c in chain[:-1] if not self._edges[c].static]

    def span(self, target: str, source: str):
        """(first, last) stamps in whole nanoseconds at which every /tf link between the two
        frames has samples on both sides, or None when the chain has no /tf link (static: every
        stamp). first > last when the links' spans do not overlap."""
        moving = self._moving(target, source)
        if not moving:
            return None
        return (max(int(e.arrays()[0][0]) for e in moving), min(int(e.arrays()[0][-1]) for e in moving))

    def covers(self, target: str, source: str, stamps) -> np.ndarray:
        """Which stamps lie within the time span of every /tf link between the two frames
        (static links have none), and in no gap wider than max_gap: the stamps lookup answers."""
        ns = np.atleast_1d(np.asarray(stamps, dtype=np.int64))
        inside = np.ones(len(ns), dtype=bool)
        for edge in self._moving(target, source):
            times = edge.arrays()[0]
            within = (ns >= times[0]) & (ns <= times[-1])
            if within.any() and self.max_gap_ns is not None:
                hit, _, lo, hi, _ = bracket(times, ns[within])
                within[within] = ~self._in_gap(times, ns[within], hit, lo, hi)
            inside &= within
        return inside

    def waiting_for(self, target: str, source: str, ns):
        """True while a /tf link between the two frames has no sample at or after stamp ns yet:
        a live lookup then waits for it (tf is not extrapolated), as tf2's message filter does,
        without building lookup's error. False otherwise (lookup answers, or says why not).
        ns: a stamp, or an array of them (then an array of answers)."""
        try:
            moving = self._moving(target, source)
        except TfError:
            moving = []
        newest = [e.newest for e in moving if e.newest is not None]
        if np.ndim(ns) == 0:
            return bool(newest) and ns > min(newest)
        ns = np.asarray(ns, dtype=np.int64)
        return ns > min(newest) if newest else np.zeros(len(ns), dtype=bool)

    def lookup(self, target: str, source: str, stamps, static_only: bool = False):
        """T_target_source at stamps (whole nanoseconds, a number or an array of n): translations
        (n, 3) and quaternions (n, 4, x y z w), float64; a point p in source is t + q p q* in
        target. Computed as inv(T_common_target) * T_common_source through the two frames'
        common ancestor. static_only: a chain with a /tf link is a TfError."""
        ns = np.atleast_1d(np.asarray(stamps, dtype=np.int64))
        up_s, up_t = self._path_between(target, source)
        a = self._down(up_s, ns, static_only)
        b = self._down(up_t, ns, static_only)
        if a is None:
            n = len(ns)
            a = (np.zeros((n, 3)), np.tile([0.0, 0.0, 0.0, 1.0], (n, 1)))
        if b is None:
            return np.array(a[0], dtype=np.float64), np.array(a[1], dtype=np.float64)
        return compose(inverse(b), a)


def static_mount(path, tf: TfBuffer | None, base: str, frame: str) -> np.ndarray | None:
    """The laser pose (x, y, yaw) in base from static tf links only; (0, 0, 0) when the frames
    are equal; None when there is no static chain."""
    if base == frame:
        return np.zeros(3)
    if tf is None or base not in tf.frames() or frame not in tf.frames():
        return None
    try:
        t, q = tf.lookup(base, frame, np.zeros(1, dtype=np.int64), static_only=True)
    except BagError:  # no chain, or a /tf link on it (TfError)
        return None
    return planar(path, t, q, f"the laser frame {frame!r} in {base!r}")[0]


def _link_text(parent: str, child: str, ns: int, topic: str) -> str:
    return f"tf {parent} -> {child} at stamp {stamp_text(ns)} on {topic}"


def _seconds_or_none(ns: int) -> float | None:
    """The stamp in seconds; None for one that is no ROS time (beyond int64's arithmetic)."""
    return stamp_seconds(ns) if MIN_STAMP_NS <= ns <= MAX_STAMP_NS else None


def _chain_text(frames: list[str]) -> str:
    """'map -> base_link -> laser', the middle of a long chain left out."""
    if len(frames) > LISTED_FRAMES:
        half = LISTED_FRAMES // 2
        frames = frames[:half] + [f"... ({len(frames) - 2 * half} more)"] + frames[-half:]
    return " -> ".join(frames)


def _duration_ns(seconds: float | None, what: str) -> int | None:
    """A duration in whole nanoseconds, at most the span of all ROS times (a longer one means the
    same, and would overflow the int64 arithmetic on stamps); ValueError for a negative or NaN one."""
    if seconds is None:
        return None
    if not seconds >= 0:
        raise ValueError(f"{what} must be a number of seconds >= 0, not {seconds!r}")
    return int(round(min(float(seconds) * 1e9, MAX_STAMP_NS - MIN_STAMP_NS)))


def _listing(names: list[str]) -> str:
    """'a, b, c', or the first LISTED_FRAMES of the names and how many more; 'none' for none."""
    if not names:
        return "none"
    if len(names) <= LISTED_FRAMES:
        return ", ".join(names)
    return f"{', '.join(names[:LISTED_FRAMES])}, ... ({len(names) - LISTED_FRAMES} more)"
