#!/usr/bin/env python3
"""Fuzzes the tf tree of the bag reader and the ROS node: vasco_gpu.bags.TfBuffer
(python/src/vasco_gpu/msgs/tf.py), fed TFMessages as a bag's /tf and /tf_static or a live
subscription feed them, then asked for transforms at stamps.

A random and structured fuzzer, time-bounded, with no dependency beyond NumPy (libFuzzer's
Python binding is not available everywhere, and the tree's inputs are structured: frames,
links, stamps, numbers). Each case builds a TfBuffer as the reader does (bag: max_gap,
refuse_repeats) or as the node does (live: keep), feeds it hostile TFMessages (deep chains,
cycles and self links, NaN/inf/huge translations and rotations, zero and unnormalised
quaternions, one stamp given twice with two poses, two parents, a link on both /tf and
/tf_static, huge and negative stamps, thousands of frames, odd frame names) and asks every
question the reader and the node ask (lookup, static lookup, covers, span, root, up, frames).

Invariants, each a violation when broken:
  * a call raises nothing but the package's own errors (BagError, TfError);
  * a lookup returns (n, 3) translations and (n, 4) unit quaternions, all finite;
  * an error's text stays readable (bounded, whatever the number of frames);
  * each call returns within --call-limit seconds (default 1);
  * a live buffer (keep=) holds no more samples a link than it may: those within keep of the
    link's newest stamp at some time, plus the 256 appended between two prunings, plus two.
  * the tree stays a tree: no link from a frame to itself, no loop (a self transform is
    ignored and a link that would close a loop refused as it arrives), so no lookup finds a
    cycle.

It loads the msgs subpackage by file path (no compiled extension, no rosbags needed).
Prints one summary line; exits 0 when no invariant broke, 1 on a violation (after printing
the case's seed, the violation, and a reproducer script written beside the artifacts), 2 on
a usage error.

    python3 fuzz/fuzz_bag_tf.py --seconds 60 [--seed S] [--artifact-dir DIR]
    python3 fuzz/fuzz_bag_tf.py --replay CASE_SEED      # one case again, verbosely
"""

from __future__ import annotations

import argparse
import importlib
import math
import random
import sys
import time
import traceback
import types
from bisect import bisect_left, insort
from collections import Counter
from pathlib import Path
from types import SimpleNamespace as NS

import numpy as np

BAGS = Path(__file__).resolve().parent.parent / "python" / "src" / "vasco_gpu" / "msgs"
NS_PER_S = 1_000_000_000
INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1
# An error's length at most: this, plus QUOTED_NAMES times the longest frame name of the case
# (an error quotes the frames asked for, their roots, and a listing of at most 20 frames).
MAX_ERROR_TEXT = 4000
QUOTED_NAMES = 30
SAMPLE_SLACK = 258  # samples appended between two prunings (256) and the two always kept

# ---------------------------------------------------------------------------------------------
# Loading the package under test


def load_bags(directory: Path):
    """TfBuffer and BagError of the msgs subpackage in directory, imported under a parent package
    whose __init__ is not run: they need NumPy only (vasco_gpu's __init__ would load the
    compiled extension)."""
    parent = types.ModuleType("vasco_gpu_fuzzed")
    parent.__path__ = [str(directory.parent)]
    sys.modules[parent.__name__] = parent
    tf = importlib.import_module(f"{parent.__name__}.{directory.name}.tf")
    errors = importlib.import_module(f"{parent.__name__}.{directory.name}.errors")
    return NS(TfBuffer=tf.TfBuffer, BagError=errors.BagError)


# ---------------------------------------------------------------------------------------------
# Hostile values


SPECIAL_FLOATS = (math.nan, math.inf, -math.inf, 0.0, -0.0, 1e-320, 5e-324, 1e-7, 1e154, -1e154, 1e200, 1e308,
                  -1e308, 1.7976931348623157e308, 1e12, 1e13, 1e15)
SPECIAL_SECS = (0, 1, -1, 2**31 - 1, -(2**31), 2**32 - 1, 2**32, 2**62, 2**63 - 1, -(2**63), 2**63, 2**64, 10**30,
                1_700_000_000)
SPECIAL_NSECS = (0, 1, 999_999_999, 1_000_000_000, 2**32 - 1, -1, 2**63)
ODD_NAMES = ("", "/", "//", "/map", "map/", " ", "a b", "\u00e9t\u00e9", "\x00", "tf\nnewline", "x" * 3000, "..",
             "base_link ")


class Gen:
    """Random pieces of TFMessages, hostile now and then."""

    def __init__(self, rng: random.Random, hostile: float):
        self.rng, self.hostile = rng, hostile

    def odd(self) -> bool:
        return self.rng.random() < self.hostile

    def number(self, scale: float = 10.0) -> float:
        if self.odd():
            return self.rng.choice(SPECIAL_FLOATS)
        return self.rng.uniform(-scale, scale)

    def translation(self):
        return tuple(self.number() for _ in range(3))

    def quaternion(self):
        r = self.rng
        if self.odd():
            kind = r.randrange(6)
            if kind == 0:
                return (0.0, 0.0, 0.0, 0.0)
            if kind == 1:
                return tuple(r.choice(SPECIAL_FLOATS) for _ in range(4))
            if kind == 2:  # unnormalised by a large or a tiny factor
                s = r.choice((1e-7, 1e-3, 1 + 1e-10, 1 + 1e-8, 3.0, 1e150))
                return tuple(s * v for v in self._unit())
            if kind == 3:  # w = -1: the identity's other sign
                return (0.0, 0.0, 0.0, -1.0)
            if kind == 4:  # upside down (a mirrored laser)
                return (1.0, 0.0, 0.0, 0.0)
            return tuple(r.choice((1e-320, -1e-320, 0.0)) for _ in range(3)) + (r.choice((1.0, 1e-320)),)
        return self._unit()

    def _unit(self):
        v = [self.rng.gauss(0, 1) for _ in range(4)]
        n = math.sqrt(sum(x * x for x in v)) or 1.0
        return tuple(x / n for x in v)

    def stamp(self, base: int = 1_700_000_000):
        """(sec, nanosec): mostly near base, now and then an extreme."""
        r = self.rng
        if self.odd():
            return r.choice(SPECIAL_SECS), r.choice(SPECIAL_NSECS)
        return base + r.randrange(0, 100), r.randrange(0, NS_PER_S)

    def name(self, pool: list[str]) -> str:
        if self.odd() and self.rng.random() < 0.3:
            return self.rng.choice(ODD_NAMES)
        return self.rng.choice(pool)


def transform(parent, child, sec, nanosec, t, q):
    """A TransformStamped-like message, as TfBuffer.add_transform reads one."""
    return NS(header=NS(frame_id=parent, stamp=NS(sec=sec, nanosec=nanosec)), child_frame_id=child,
              transform=NS(translation=NS(x=t[0], y=t[1], z=t[2]), rotation=NS(x=q[0], y=q[1], z=q[2], w=q[3])))


def ns_of(sec, nanosec) -> int:
    return int(sec) * NS_PER_S + int(nanosec)


def clamp64(v: int) -> int:
    return max(INT64_MIN, min(INT64_MAX, int(v)))


# ---------------------------------------------------------------------------------------------
# Cases: a buffer's constructor keywords and a list of operations
#   ("add", static, topic, [link, ...])  link = (parent, child, sec, nanosec, t, q)
#   ("lookup", target, source, [stamps], static_only) ("covers", target, source, [stamps])
#   ("span", target, source) ("root", frame) ("up", frame) ("frames",)

BUFFERS = (
    ("bag", {"file": "fuzz.bag", "stamp_name": "scan stamp", "max_gap": 10.0, "refuse_repeats": True,
             "outside_hint": "skip_unposed / --skip-unposed leaves such scans out"}),
    ("live", {"stamp_name": "scan stamp", "keep": 60.0}),
    ("plain", {}),
)


def stamps_to_ask(gen: Gen, known: list[int], count: int) -> list[int]:
    """Lookup stamps: the links' samples, between two, just outside, and int64's ends."""
    r = gen.rng
    out = []
    for _ in range(count):
        k = r.randrange(6)
        if known and k < 3:
            a = r.choice(known)
            if k == 1:
                b = r.choice(known)
                a = (a + b) // 2
            elif k == 2:
                a += r.choice((-1, 1, -NS_PER_S, NS_PER_S, 11 * NS_PER_S))
            out.append(clamp64(a))
        elif k == 3:
            out.append(r.choice((0, -1, INT64_MIN, INT64_MAX, 1_700_000_000 * NS_PER_S)))
        else:
            out.append(clamp64(ns_of(*gen.stamp())))
    return out


def questions(gen: Gen, frames: list[str], known: list[int], n: int, stamps_each: int = 8) -> list[tuple]:
    r = gen.rng
    ops = []
    pool = frames + ["nowhere"]
    for _ in range(n):
        a, b = gen.name(pool), gen.name(pool)
        k = r.randrange(10)
        if k < 5:
            ops.append(("lookup", a, b, stamps_to_ask(gen, known, r.randint(0, stamps_each)), False))
        elif k == 5:
            ops.append(("lookup", a, b, [0], True))  # a laser's or a cloud's static mount
        elif k == 6:
            ops.append(("covers", a, b, stamps_to_ask(gen, known, r.randint(0, stamps_each))))
        elif k == 7:
            ops.append(("span", a, b))
        elif k == 8:
            ops.append((r.choice(("root", "up")), a))
        else:
            ops.append(("frames",))
    return ops


def case_random_tree(gen: Gen) -> list[tuple]:
    """A random forest with static and moving links, samples at random stamps, odd values."""
    r = gen.rng
    size = r.choice((2, 3, 5, 10, 40, 200))
    frames = [f"f{k}" for k in range(size)]
    parent_of = {f: r.choice(frames[:k]) for k, f in enumerate(frames) if k and r.random() < 0.9}
    static = {f: r.random() < 0.4 for f in frames}
    ops, known = [], []
    for _ in range(r.randint(1, 60)):
        links = []
        is_static = r.random() < 0.3
        for _ in range(r.randint(1, 6)):
            child = gen.name(frames)
            parent = parent_of.get(child, r.choice(frames)) if not gen.odd() else gen.name(frames)
            sec, nsec = gen.stamp()
            known.append(clamp64(ns_of(sec, nsec)))
            links.append((parent, child, sec, nsec, gen.translation(), gen.quaternion()))
        ops.append(("add", is_static if gen.odd() else static.get(links[0][1], is_static), None, links))
        if r.random() < 0.3:
            ops += questions(gen, frames, known, r.randint(1, 4))
    return ops + questions(gen, frames, known, r.randint(1, 30))


def case_deep_chain(gen: Gen) -> list[tuple]:
    """One chain, or two branches of one root, hundreds of links deep; looked up end to end."""
    r = gen.rng
    depth = r.choice((50, 300, 1000))
    branches = r.choice((1, 2))
    moving = r.random()  # the share of links on /tf
    ops, known, frames = [], [], ["root"]
    base = 1_700_000_000
    for side in "ab"[:branches]:
        static_links, dynamic_links = [], []
        for k in range(depth):
            parent = f"{side}{k}" if k else "root"
            child = f"{side}{k + 1}"
            frames.append(child)
            if r.random() < moving:
                for s in range(2):
                    sec, nsec = (base + s, 0) if not gen.odd() else gen.stamp()
                    known.append(clamp64(ns_of(sec, nsec)))
                    dynamic_links.append((parent, child, sec, nsec, gen.translation(), gen.quaternion()))
            else:
                identity = r.random() < 0.5
                t, q = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)) if identity else (gen.translation(), gen.quaternion())
                static_links.append((parent, child, 0, 0, t, q))
        if static_links:
            ops.append(("add", True, None, static_links))
        if dynamic_links:
            ops.append(("add", False, None, dynamic_links))
    leaves = [f"{side}{depth}" for side in "ab"[:branches]]
    for _ in range(r.randint(1, 6)):
        a, b = r.choice(leaves + ["root"]), r.choice(leaves + ["root"])
        ops.append(("lookup", a, b, stamps_to_ask(gen, known + [base * NS_PER_S + NS_PER_S // 2], 4), False))
    ops.append(("covers", leaves[0], "root", [base * NS_PER_S, (base + 1) * NS_PER_S]))
    ops.append(("span", leaves[-1], "root"))
    ops.append(("lookup", leaves[0], "root", [0], True))
    return ops


def case_cycles(gen: Gen) -> list[tuple]:
    """Links that close a loop, a frame its own parent, then questions about every frame."""
    r = gen.rng
    size = r.randint(1, 12)
    frames = [f"c{k}" for k in range(size)]
    ops, known = [], []
    for _ in range(r.randint(1, 20)):
        a, b = r.choice(frames), r.choice(frames)
        sec, nsec = gen.stamp()
        known.append(clamp64(ns_of(sec, nsec)))
        ops.append(("add", r.random() < 0.5, None, [(a, b, sec, nsec, gen.translation(), gen.quaternion())]))
    return ops + questions(gen, frames, known, r.randint(5, 25))


def case_repeats(gen: Gen) -> list[tuple]:
    """One link's samples at a few stamps, each given several times with different poses."""
    r = gen.rng
    stamps = [gen.stamp() for _ in range(r.randint(1, 5))]
    ops, known = [], [clamp64(ns_of(*s)) for s in stamps]
    for _ in range(r.randint(2, 40)):
        sec, nsec = r.choice(stamps)
        ops.append(("add", False, None, [("map", "odom", sec, nsec, gen.translation(), gen.quaternion())]))
    ops.append(("add", True, None, [("odom", "base_link", 0, 0, gen.translation(), gen.quaternion())]))
    return ops + questions(gen, ["map", "odom", "base_link"], known, r.randint(3, 15))


def case_many_frames(gen: Gen) -> list[tuple]:
    """Thousands of frames in one message (a tree, a star, or unconnected pairs), then lookups
    between far frames and of frames that are not there (the error lists what is)."""
    r = gen.rng
    size = r.choice((1000, 5000, 20000))
    shape = r.randrange(3)
    name = "robot_{:06d}_laser_link".format  # alike names: a "did you mean" compares each in full
    links = []
    for k in range(1, size):
        parent = {0: name((k - 1) // 2), 1: name(0), 2: f"island{k}"}[shape]
        links.append((parent, name(k), 0, 0, (float(k % 7), 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))
    ops = [("add", True, None, links)]
    far = [name(size - 1), name(size // 2), name(1), "robot_99999_laser_lnk", name(size - 1) + "x", "q" * 200]
    for _ in range(r.randint(2, 8)):
        ops.append(("lookup", r.choice(far), r.choice(far), [0, 1], r.random() < 0.5))
    ops.append(("frames",))
    return ops


def case_live_stream(gen: Gen) -> list[tuple]:
    """A live buffer's stream: a link sampled at a steady rate for longer than keep, with stale,
    repeated, future and extreme stamps mixed in, one transform a message as the node gets them."""
    r = gen.rng
    rate = r.choice((10, 50, 200))  # samples a second
    count = r.choice((300, 1000, 3000))
    t0 = 1_700_000_000 * NS_PER_S
    ops, known = [], []
    for k in range(count):
        ns = t0 + k * NS_PER_S // rate
        if gen.odd():
            ns = r.choice((ns - 120 * NS_PER_S, ns + 3600 * NS_PER_S, known[-1] if known else ns,
                           ns_of(*gen.stamp())))
        sec, nsec = divmod(ns, NS_PER_S)
        known.append(clamp64(ns))
        ops.append(("add", False, None, [("odom", "base_link", sec, nsec, gen.translation(), gen.quaternion())]))
        if k % 97 == 0:
            ops.append(("lookup", "odom", "base_link", stamps_to_ask(gen, known[-50:], 3), False))
    ops.append(("add", True, None, [("base_link", "laser", 0, 0, (0.1, 0.0, 0.2), (0.0, 0.0, 0.0, 1.0))]))
    return ops + questions(gen, ["odom", "base_link", "laser"], known[-200:], 10)


def case_mixed(gen: Gen) -> list[tuple]:
    """A link moved between /tf and /tf_static, a frame given a second parent, frames with ROS 1's
    leading '/', messages with a bad transform among good ones."""
    r = gen.rng
    ops, known = [], []
    names = ["map", "/map", "odom", "/odom", "base_link", "laser", "/laser"]
    for _ in range(r.randint(2, 30)):
        links = []
        for _ in range(r.randint(1, 4)):
            sec, nsec = gen.stamp()
            known.append(clamp64(ns_of(sec, nsec)))
            links.append((gen.name(names), gen.name(names), sec, nsec, gen.translation(), gen.quaternion()))
        ops.append(("add", r.random() < 0.4, r.choice((None, "/tf", "/tf_static", "/robot/tf")), links))
    return ops + questions(gen, [n.lstrip("/") for n in names], known, r.randint(3, 20))


CASES = (case_random_tree, case_deep_chain, case_cycles, case_repeats, case_many_frames, case_live_stream,
         case_mixed)
WEIGHTS = (30, 6, 10, 10, 2, 4, 20)


def make_case(seed: int):
    """(case kind, buffer name, its keywords, ops) of the case with this seed, the same every time."""
    r = random.Random(seed)
    name, keywords = r.choice(BUFFERS)
    gen = Gen(r, hostile=r.choice((0.0, 0.02, 0.1, 0.4)))
    kind = r.choices(CASES, WEIGHTS)[0]
    return kind.__name__, name, dict(keywords), kind(gen)


# ---------------------------------------------------------------------------------------------
# Running a case and checking the invariants


class Violation(Exception):
    def __init__(self, kind: str, detail: str, index: int):
        super().__init__(f"{kind}: {detail}")
        self.kind, self.detail, self.index = kind, detail, index


# What an error is about, for the summary.
ERROR_KINDS = (
    ("links a frame to itself", "self link"), ("would close a cycle", "closes a cycle"),
    ("two parents", "two parents"), ("on both /tf and /tf_static", "static and moving"),
    ("invalid rotation", "bad rotation"), ("has translation", "bad translation"), ("cycle", "cycle"),
    ("no transform chain", "no chain"), ("outside the time span", "outside the span"),
    ("falls in a gap", "in a gap"), ("two different samples", "repeated stamp"),
    ("not a static chain", "not static"), ("not a ROS time", "bad stamp"),
)


def error_kind(text: str) -> str:
    return next((kind for key, kind in ERROR_KINDS if key in text), "other")


def _exception_text(e: Exception) -> str:
    """'OverflowError: ... (tf.py:162 in add_transform)': the exception and where it was raised."""
    last = traceback.extract_tb(e.__traceback__)[-1]
    return f"{type(e).__name__}: {str(e)[:1000]} ({Path(last.filename).name}:{last.lineno} in {last.name})"


class Runner:
    """Runs the ops of one case on a fresh buffer, checking each call."""

    def __init__(self, bags, call_limit: float, verbose: bool = False):
        self.bags, self.call_limit, self.verbose = bags, call_limit, verbose
        self.errors: Counter = Counter()
        self.examples: dict = {}  # the last error of each kind, kept as a caller may keep one to report
        self.calls = 0
        self.slow_once = 0  # cases with a slow call that was not slow when run again

    def run(self, keywords: dict, ops: list[tuple]) -> None:
        tf = self.bags.TfBuffer(**keywords)
        keep_ns = None if keywords.get("keep") is None else int(keywords["keep"] * NS_PER_S)
        longest = max((len(n) for op in ops if op[0] == "add" for link in op[3] for n in link[:2]), default=0)
        added: dict[str, list[int]] = {}  # a live buffer's stamps a moving link took, sorted
        most: dict[str, int] = {}  # the most of them within keep of the newest, at any time
        for index, op in enumerate(ops):
            names = [x for x in op[1:3] if isinstance(x, str)]
            start = time.perf_counter()
            try:
                result = self._call(tf, op)
            except self.bags.BagError as e:
                result = None
                self._check_error(e, max([longest] + [len(n) for n in names]), index, keywords)
            except Exception as e:  # anything else is a violation
                raise Violation("exception", _exception_text(e), index) from e
            took = time.perf_counter() - start
            self.calls += 1
            if took > self.call_limit:
                raise Violation("slow", f"{op[0]} took {took:.2f} s (limit {self.call_limit:g} s)", index)
            if op[0] == "lookup" and result is not None:
                self._check_pose(result, len(op[3]), index)
            if op[0] == "covers" and result is not None and result.shape != (len(op[3]),):
                raise Violation("bad shape", f"covers gave {result.shape} for {len(op[3])} stamps", index)
            if op[0] == "add" and keep_ns is not None and not op[1] and len(op[3]) == 1 and result is not None:
                self._check_memory(tf, op[3][0], keep_ns, added, most, index)
            if op[0] == "add":
                self._check_tree(tf, index)
            if self.verbose:
                print(f"  [{index}] {op[0]}: {'error' if result is None else 'ok'} ({took * 1e3:.1f} ms)")

    @staticmethod
    def _call(tf, op):
        kind = op[0]
        if kind == "add":
            _, static, topic, links = op
            msg = NS(transforms=[transform(*link) for link in links])
            tf.add_message(msg, static, topic)
            return True
        if kind == "lookup":
            return tf.lookup(op[1], op[2], np.array(op[3], dtype=np.int64), static_only=op[4])
        if kind == "covers":
            return tf.covers(op[1], op[2], np.array(op[3], dtype=np.int64))
        if kind == "span":
            return tf.span(op[1], op[2])
        if kind == "root":
            return tf.root(op[1])
        if kind == "up":
            return tf.up(op[1])
        return tf.frames()

    def _check_error(self, e, longest_name: int, index: int, keywords: dict) -> None:
        text = str(e)
        self.errors[error_kind(text)] += 1
        self.examples[error_kind(text)] = e
        if error_kind(text) == "cycle":  # a walk found a loop: the tree took a link it must refuse
            raise Violation("cycle stored", text[:300], index)
        if len(text) > MAX_ERROR_TEXT + QUOTED_NAMES * longest_name:
            raise Violation("long error", f"{len(text)} characters: {text[:300]}...", index)
        if e.file != keywords.get("file"):
            raise Violation("error names another file", f"file {e.file!r}: {text[:300]}", index)

    @staticmethod
    def _check_pose(result, n: int, index: int) -> None:
        t, q = result
        if t.shape != (n, 3) or q.shape != (n, 4):
            raise Violation("bad shape", f"translations {t.shape}, quaternions {q.shape} for {n} stamps", index)
        if not (np.isfinite(t).all() and np.isfinite(q).all()):
            bad = int(np.flatnonzero(~(np.isfinite(t).all(axis=1) & np.isfinite(q).all(axis=1)))[0])
            raise Violation("not finite", f"stamp {bad}: t {t[bad].tolist()}, q {q[bad].tolist()}", index)
        norm = np.linalg.norm(q, axis=1)
        if n and not (np.abs(norm - 1.0) < 1e-6).all():
            raise Violation("not a unit quaternion", f"norms {norm.min()} to {norm.max()}", index)

    @staticmethod
    def _check_tree(tf, index: int) -> None:
        """No self link and no loop among the stored links (the one other look inside): each
        frame's walk up ends at a root, each frame walked once."""
        parent = {child: edge.parent for child, edge in tf._edges.items()}
        done: set = set()
        for start in parent:
            path, seen, f = [], set(), start
            while f in parent and f not in done:
                if f in seen:
                    raise Violation("cycle stored", f"tf holds a loop through {f!r}", index)
                seen.add(f)
                path.append(f)
                f = parent[f]
            done.update(path)

    @staticmethod
    def _check_memory(tf, link, keep_ns: int, added: dict, most: dict, index: int) -> None:
        """A moving link of a live buffer holds at most the samples within keep of its newest
        stamp at some time, plus SAMPLE_SLACK (module docstring)."""
        child = link[1].lstrip("/")
        stamps = added.setdefault(child, [])
        insort(stamps, ns_of(link[2], link[3]))
        within = len(stamps) - bisect_left(stamps, stamps[-1] - keep_ns)
        most[child] = max(most.get(child, 0), within)
        edge = tf._edges.get(child)  # the one look inside: the link's stored samples
        held = 0 if edge is None else len(edge)
        if held > most[child] + SAMPLE_SLACK:
            raise Violation("memory", f"link -> {child!r} holds {held} samples, at most {most[child]} within "
                                      f"keep + {SAMPLE_SLACK} expected", index)


# ---------------------------------------------------------------------------------------------
# Reproducers


def py(v) -> str:
    """Python text of a value of an op, NaN and infinities included."""
    if isinstance(v, float):
        if math.isnan(v):
            return "math.nan"
        if math.isinf(v):
            return "math.inf" if v > 0 else "-math.inf"
        return repr(v)
    if isinstance(v, (list, tuple)):
        inner = ", ".join(py(x) for x in v)
        return f"[{inner}]" if isinstance(v, list) else f"({inner}{',' if len(v) == 1 else ''})"
    return repr(v)


def reproducer(keywords: dict, ops: list[tuple], violation: Violation, bags_dir: Path) -> str:
    """A standalone script that replays ops on a fresh buffer; the last op is the violation's."""
    lines = ["# A reproducer written by fuzz/fuzz_bag_tf.py", f"# {violation}",
             "import importlib, math, sys, types", "from types import SimpleNamespace as NS", "import numpy as np",
             f"MSGS = {str(bags_dir)!r}",
             "parent = types.ModuleType('package'); parent.__path__ = [MSGS.rsplit('/', 1)[0]]",
             "sys.modules['package'] = parent",
             "bags = NS(TfBuffer=importlib.import_module('package.msgs.tf').TfBuffer,",
             "          BagError=importlib.import_module('package.msgs.errors').BagError)",
             "def link(parent, child, sec, nanosec, t, q):",
             "    return NS(header=NS(frame_id=parent, stamp=NS(sec=sec, nanosec=nanosec)), child_frame_id=child,",
             "              transform=NS(translation=NS(x=t[0], y=t[1], z=t[2]), "
             "rotation=NS(x=q[0], y=q[1], z=q[2], w=q[3])))",
             "def quiet(call):  # the package's own errors are expected on the way",
             "    try:",
             "        return call()",
             "    except bags.BagError as e:",
             "        print('  (TfError:', str(e)[:120], ')')",
             f"tf = bags.TfBuffer(**{keywords!r})"]
    for k, op in enumerate(ops[: violation.index + 1]):
        last = k == violation.index
        if op[0] == "add":
            links = ", ".join(f"link({py(list(link))[1:-1]})" for link in op[3])
            call = f"tf.add_message(NS(transforms=[{links}]), {op[1]!r}, {op[2]!r})"
        elif op[0] == "lookup":
            call = f"tf.lookup({op[1]!r}, {op[2]!r}, np.array({op[3]!r}, dtype=np.int64), static_only={op[4]!r})"
        elif op[0] == "covers":
            call = f"tf.covers({op[1]!r}, {op[2]!r}, np.array({op[3]!r}, dtype=np.int64))"
        elif op[0] == "span":
            call = f"tf.span({op[1]!r}, {op[2]!r})"
        elif op[0] in ("root", "up"):
            call = f"tf.{op[0]}({op[1]!r})"
        else:
            call = "tf.frames()"
        lines.append(f"print({call})" if last else f"quiet(lambda: {call})")
    return "\n".join(lines) + "\n"


def signature(v: Violation) -> str:
    """What makes two violations the same while shrinking: the kind, and an exception's type."""
    return v.kind + (":" + v.detail.split(":")[0] if v.kind == "exception" else "")


def still_fails(runner_args, keywords, ops, violation: Violation) -> Violation | None:
    try:
        Runner(*runner_args).run(keywords, ops)
    except Violation as v:
        return v if signature(v) == signature(violation) else None
    return None


def minimise(runner_args, keywords: dict, ops: list[tuple], violation: Violation, budget_s: float):
    """Drops ops (and links of adds) while the same kind of violation remains, within budget_s."""
    deadline = time.monotonic() + budget_s
    ops = ops[: violation.index + 1]
    chunk = max(1, len(ops) // 2)
    while chunk >= 1 and time.monotonic() < deadline:
        k, shrunk = 0, False
        while k < len(ops) - 1 and time.monotonic() < deadline:  # never the failing op itself
            trial = ops[:k] + ops[k + chunk:]
            if len(trial) and (v := still_fails(runner_args, keywords, trial, violation)):
                ops, violation, shrunk = trial[: v.index + 1], v, True
            else:
                k += chunk
        if not shrunk:
            chunk //= 2
    for k, op in enumerate(ops):  # then the links of each add
        if op[0] != "add":
            continue
        links = list(op[3])
        j = 0
        while len(links) > 1 and j < len(links) and time.monotonic() < deadline:
            trial_links = links[:j] + links[j + 1:]
            trial = ops[:k] + [("add", op[1], op[2], trial_links)] + ops[k + 1:]
            if (v := still_fails(runner_args, keywords, trial, violation)) and v.index == violation.index:
                links, violation = trial_links, v
            else:
                j += 1
        ops[k] = ("add", op[1], op[2], links)
    return ops, violation


# ---------------------------------------------------------------------------------------------


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=60.0, help="how long to fuzz (default 60)")
    p.add_argument("--seed", type=int, default=None, help="the run's seed (default: from the clock, printed)")
    p.add_argument("--call-limit", type=float, default=1.0, help="seconds a call may take (default 1)")
    p.add_argument("--artifact-dir", default=".", help="where a reproducer is written (default: here)")
    p.add_argument("--bags", type=Path, default=BAGS, help="the vasco_gpu/msgs directory to fuzz")
    p.add_argument("--replay", type=int, default=None, metavar="CASE_SEED", help="run one case, verbosely")
    try:
        a = p.parse_args(argv)
    except SystemExit as e:
        return 0 if e.code == 0 else 2
    if not (a.bags / "tf.py").is_file():
        print(f"fuzz_bag_tf: {a.bags}: no tf.py there (--bags)", file=sys.stderr)
        return 2
    bags = load_bags(a.bags)
    np.seterr(all="ignore")  # an overflow shows as inf in the result, which is checked
    seed = a.seed if a.seed is not None else time.time_ns() % 2**32
    master = random.Random(seed)
    runner = Runner(bags, a.call_limit, verbose=a.replay is not None)
    start, cases = time.monotonic(), 0
    while True:
        case_seed = a.replay if a.replay is not None else master.getrandbits(48)
        kind, buffer, keywords, ops = make_case(case_seed)
        if a.replay is not None:
            print(f"case {case_seed}: {kind} on a {buffer} buffer, {len(ops)} calls")
        try:
            runner.run(keywords, ops)
        except Violation as v:
            if v.kind == "slow" and a.replay is None and not slow_again(runner, keywords, ops):
                runner.slow_once += 1  # a busy machine, not the code
            else:
                return report(a, bags, seed, case_seed, kind, buffer, keywords, ops, v, runner)
        cases += 1
        if a.replay is not None or time.monotonic() - start >= a.seconds:
            break
    kinds = ", ".join(f"{k} {n}" for k, n in runner.errors.most_common())
    once = f"; {runner.slow_once} slow calls not slow again" if runner.slow_once else ""
    print(f"fuzz_bag_tf: ok: {cases} cases, {runner.calls} calls in {time.monotonic() - start:.0f} s (seed {seed}); "
          f"TfErrors {sum(runner.errors.values())}: {kinds or 'none'}{once}")
    return 0


def slow_again(runner: Runner, keywords: dict, ops: list[tuple]) -> bool:
    """Whether a case whose call was slow is slow again: a timing is reported when it repeats."""
    try:
        Runner(runner.bags, runner.call_limit).run(keywords, ops)
    except Violation as v:
        return v.kind == "slow"
    return False


def report(a, bags, seed, case_seed, kind, buffer, keywords, ops, v: Violation, runner) -> int:
    print(f"fuzz_bag_tf: VIOLATION in case {case_seed} ({kind}, {buffer} buffer; run seed {seed}) at call "
          f"{v.index} ({ops[v.index][0]}): {v}", file=sys.stderr)
    if v.kind != "slow":  # a timing is not reproduced reliably enough to shrink on
        ops, v = minimise((bags, a.call_limit), keywords, ops, v, budget_s=60.0)
    script = reproducer(keywords, ops, v, a.bags.resolve())
    path = Path(a.artifact_dir) / f"fuzz_bag_tf-crash-{case_seed}.py"
    path.write_text(script)
    print(script if len(script) < 6000 else script[:3000] + "\n...\n", file=sys.stderr)
    print(f"fuzz_bag_tf: reproducer written to {path}; replay the case: {Path(sys.argv[0]).name} --replay "
          f"{case_seed}", file=sys.stderr)
    print(f"fuzz_bag_tf: FAILED after {runner.calls} calls (seed {seed})")
    return 1


if __name__ == "__main__":
    sys.exit(main())
