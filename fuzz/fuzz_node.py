#!/usr/bin/env python3
"""Fuzzes the ROS 2 node (vasco_gpu.ros: node.py and the modules beside it) in-process: its message
callbacks fed good, hostile and mutated CDR bytes of sensor_msgs LaserScan, MultiEchoLaserScan,
PointCloud2, nav_msgs Path and tf2_msgs TFMessage, with parameter changes (in range and hostile:
huge, negative, NaN, of the wrong type), service calls (reset, save_map, dynamic_map, save_session,
pause) and the node's timers interleaved.

A case is a fresh node (in an rclpy context of this process; no message crosses DDS) with some start
parameters, then operations made from the case's seed alone. Each message is serialized, maybe
mutated (bit flips, truncation, a length field set huge, a double smashed, random bytes) and given
to its subscription's callback as the executor gives it: deserialized by rclpy (bytes rclpy refuses
never reach a callback: skipped), or as bytes where the node subscribes raw (the Path).

Invariants, each a finding when broken:
  * no exception escapes a callback, a parameter change, a service, a timer or the start-up (which
    may refuse a parameter with SettingsError, as the node's main does);
  * after every case the node still maps: the case's parameters set back (atomically), mapping
    unpaused, a good scan and its /tf in a frame of their own raise ~/dynamic_map's values where
    its beams end (scale mode: round(100 p), unknown -1);
  * memory stays bounded: the resident size never exceeds its size after the first case by more
    than --rss-growth-mb (default 512 MiB; each node's session is capped by max_memory, 64 MiB);
  * no operation takes longer than --op-limit seconds (default 30).

Prints one summary line; exits 0 when nothing broke, 1 on a finding (printed with the path of its
reproducer: the start parameters and the operations as JSON, shrunk, which --replay runs again
verbosely), 2 on a usage error or without rclpy. Deterministic given --seed (node timing aside).

    python3 fuzz/fuzz_node.py --seconds 60 [--seed S] [--artifact-dir DIR] [--keep-going]
    python3 fuzz/fuzz_node.py --replay DIR/fuzz_node-finding-SEED.json
"""

from __future__ import annotations

import argparse
import faulthandler
import importlib
import json
import math
import os
import random
import struct
import sys
import tempfile
import time
import traceback
from contextlib import contextmanager
from pathlib import Path

# Before rclpy makes a participant: shared memory only, a domain of its own.
os.environ["FASTDDS_BUILTIN_TRANSPORTS"] = "SHM"
os.environ.setdefault("ROS_DOMAIN_ID", str(150 + os.getpid() % 81))
os.environ.pop("ROS_AUTOMATIC_DISCOVERY_RANGE", None)

BASE_S = 1_700_000_000
NS = 1_000_000_000
MAX_MEMORY = 64 << 20  # each node's session budget (max_memory)
CHECK_BEAMS, CHECK_RANGE = 180, 2.0  # the check's scan: a half turn of 2 m ranges
# Start parameters a case keeps: the budget, and what sizes a grid against it (a longest range of 600 m
# needs more than max_memory: every scan refused, by design); changes while running may set anything.
START_FIXED = ("max_memory", "threads", "load_session", "max_laser_range", "resolution", "scan_topic", "scan_topics",
               "multi_echo_topics", "cloud_topics", "path_topic",  # and the topics the fuzzer feeds,
               "minimum_time_interval", "throttle_scans", "param_file", "map_mode")  # the check: one scan shown
CLOUD_FRAME, LASER_FRAME = "velodyne", "laser"
TOPICS = {"scan": "/scan", "echo": "/echo", "cloud": "/cloud", "path": "/trajectory", "tf": "/tf",
          "tf_static": "/tf_static"}
SERVICES = ("reset", "save_map", "dynamic_map", "save_session", "pause")
SPECIAL_FLOATS = (math.nan, math.inf, -math.inf, 0.0, -0.0, 5e-324, 1e-9, -1.0, 1e6, 1e12, 1e13, 1e300, -1e300,
                  3.4e38, 1.7976931348623157e308)
HOSTILE_VALUES = (0, -1, 1, 0.0, -1.0, 1e-9, 9.3e9, 1e10, 1e12, 1e300, -1e300, math.nan, math.inf, -math.inf,
                  2**63 - 1, -(2**63), "", "x", "a b", True, False, [], [1.0], [1.0, 2.0], [2.0, 1.0], ["x"],
                  [math.nan, 1.0], None)
FILE_NAMES = ("map", "m.map.gz", "m.map", "m.pgm", "m.png", "m.yaml", "sub/none/m.pgm", ".", "x" * 300,
              "m.unknown", "s.session")
ODD_FRAMES = ("", "/", "map", "base_link", "/laser", "laser ", "x" * 3000, "\u00e9", "odom", "velodyne")

# -- Messages: good ones, hostile fields, mutated bytes ---------------------------------------------


def ros() -> dict:
    """The message classes by name, and rclpy's (de)serialization (imported once rclpy is known there)."""
    from rclpy.serialization import deserialize_message, serialize_message

    m = {name: getattr(importlib.import_module(f"{package}.msg"), name) for package, names in (
        ("geometry_msgs", "PoseStamped TransformStamped"), ("nav_msgs", "Path"), ("tf2_msgs", "TFMessage"),
        ("sensor_msgs", "LaserEcho LaserScan MultiEchoLaserScan PointCloud2 PointField")) for name in names.split()}
    return {**m, "serialize": serialize_message, "deserialize": deserialize_message}


class Gen:
    """Random messages and values of one case, hostile now and then (share hostile)."""

    def __init__(self, rng: random.Random, m: dict, hostile: float):
        self.r, self.m, self.hostile = rng, m, hostile

    def odd(self) -> bool:
        return self.r.random() < self.hostile

    def num(self, lo: float, hi: float) -> float:
        return self.r.choice(SPECIAL_FLOATS) if self.odd() else self.r.uniform(lo, hi)

    def f32(self, lo: float, hi: float) -> float:
        """num for a float32 field: rclpy refuses a finite value beyond float32's range, a sender's
        float32 would have been inf."""
        v = self.num(lo, hi)
        return math.copysign(math.inf, v) if math.isfinite(v) and abs(v) > 3.4e38 else v

    def stamp(self, header, ns: int) -> None:
        if self.odd():
            header.stamp.sec = self.r.choice((0, -1, 2**31 - 1, -(2**31), BASE_S - 10**6, BASE_S + 10**6))
            header.stamp.nanosec = self.r.choice((0, 999_999_999, 10**9, 2**32 - 1))
        else:
            header.stamp.sec, header.stamp.nanosec = divmod(ns, NS)

    def frame(self, good: str) -> str:
        return self.r.choice(ODD_FRAMES) if self.odd() else good

    def ranges(self, n: int) -> list:
        return [self.f32(0.2, 25.0) if self.odd() else self.r.uniform(0.2, 25.0) for _ in range(n)]

    def _beams(self, msg, n: int) -> None:
        r = self.r
        msg.angle_min = self.f32(-3.1, -0.5)
        msg.angle_increment = self.f32(0.001, min(0.05, 6.2 / max(n - 1, 1))) if n > 1 else 0.0  # within a turn
        top = msg.angle_min + msg.angle_increment * (n - 1)
        msg.angle_max = float(top) if math.isfinite(top) and abs(top) < 3e38 else self.f32(-4, 4)
        msg.range_min, msg.range_max = self.f32(0.0, 0.2), self.f32(20.0, 40.0)
        msg.time_increment, msg.scan_time = r.choice((0.0, 1e-5, -1.0)), r.choice((0.0, 0.1))

    def count(self) -> int:
        return self.r.choice((0, 1, 2, 5000, 20000)) if self.odd() else self.r.randrange(10, 400)

    def scan(self, ns: int, frame: str = LASER_FRAME):
        msg, n = self.m["LaserScan"](), self.count()
        self.stamp(msg.header, ns)
        msg.header.frame_id = self.frame(frame)
        self._beams(msg, n)
        msg.ranges = self.ranges(n)
        msg.intensities = [1.0] * (self.r.choice((0, n, n + 1, 3)) if self.odd() else self.r.choice((0, n)))
        return msg

    def echo(self, ns: int, frame: str = LASER_FRAME):
        msg, n = self.m["MultiEchoLaserScan"](), self.count()
        self.stamp(msg.header, ns)
        msg.header.frame_id = self.frame(frame)
        self._beams(msg, n)
        msg.ranges = [self._echoes() for _ in range(n)]
        msg.intensities = [self._echoes() for _ in range(self.r.choice((0, n)))]
        return msg

    def _echoes(self):
        return self.m["LaserEcho"](echoes=self.ranges(self.r.choice((0, 1, 1, 2, 3)) if self.odd() else 1))

    def cloud(self, ns: int, frame: str = CLOUD_FRAME):
        r, m = self.r, self.m
        msg, n = m["PointCloud2"](), self.count()
        self.stamp(msg.header, ns)
        msg.header.frame_id = self.frame(frame)
        kind, size = (8, 8) if r.random() < 0.2 else (7, 4)
        step = 3 * size + r.choice((0, 0, 4))
        fields = [m["PointField"](name=name, offset=k * size, datatype=kind, count=1) for k, name in enumerate("xyz")]
        if self.odd():
            f = r.choice(fields)
            f.offset, f.datatype, f.count = r.choice((f.offset, 2**32 - 1, step)), r.randrange(0, 12), r.randrange(3)
            if r.random() < 0.3:
                fields.remove(f)
        msg.fields = fields
        pts = [(r.uniform(-20, 20), r.uniform(-20, 20), r.uniform(0.0, 2.0)) for _ in range(n)]
        raw = b"".join(struct.pack("<ddd" if size == 8 else "<fff", *p) + bytes(step - 3 * size) for p in pts)
        msg.height, msg.width, msg.point_step, msg.row_step = 1, n, step, step * n
        if self.odd():
            msg.height, msg.width = r.choice((0, 1, 2, 2**32 - 1)), r.choice((0, n, n + 1, 2**32 - 1))
            msg.point_step, msg.row_step = r.choice((0, step, 2**32 - 1)), r.choice((0, step * n, 2**32 - 1))
            msg.is_bigendian = r.random() < 0.5
        msg.data = raw[: r.randrange(len(raw) + 1)] if self.odd() else raw
        msg.is_dense = r.random() < 0.5
        return msg

    def link(self, parent: str, child: str, ns: int, x: float, y: float, yaw: float):
        t = self.m["TransformStamped"]()
        self.stamp(t.header, ns)
        t.header.frame_id, t.child_frame_id = self.frame(parent), self.frame(child)
        v = t.transform.translation
        v.x, v.y, v.z = (self.num(-1e6, 1e6) if self.odd() else x), (self.num(-1e6, 1e6) if self.odd() else y), 0.0
        q, turn = t.transform.rotation, (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
        q.x, q.y, q.z, q.w = [self.r.choice(SPECIAL_FLOATS) for _ in range(4)] if self.odd() else turn
        return t

    def path(self, stamps: list, poses: list, frame: str = "map"):
        msg = self.m["Path"]()
        msg.header.frame_id = self.frame(frame)
        self.stamp(msg.header, stamps[-1] if stamps else BASE_S * NS)
        for ns, (x, y, yaw) in zip(stamps, poses):
            p = self.m["PoseStamped"]()
            self.stamp(p.header, ns)
            p.header.frame_id = self.frame(frame) if self.r.random() < 0.1 else frame
            p.pose.position.x, p.pose.position.y = self.num(x - 1, x + 1), self.num(y - 1, y + 1)
            p.pose.orientation.z, p.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
            msg.poses.append(p)
        if self.odd() and msg.poses:
            self.r.shuffle(msg.poses)
        return msg


def mutate(rng: random.Random, data: bytes) -> bytes:
    """data with one of: bit flips, a truncation, a length field set huge, a double smashed, a
    chunk cut or doubled, random bytes (the CDR header kept or not)."""
    b, kind = bytearray(data), rng.randrange(7)
    if kind == 0 and b:
        for _ in range(rng.randrange(1, 9)):
            b[rng.randrange(len(b))] ^= 1 << rng.randrange(8)
    elif kind == 1:
        b = b[: rng.randrange(len(b) + 1)]
    elif kind == 2 and len(b) >= 12:  # a uint32 that looks like a length or a count
        at = [o for o in range(4, len(b) - 3, 4) if 0 < struct.unpack_from("<I", b, o)[0] < 10**6] or [4]
        value = rng.choice((0xFFFFFFFF, 0x7FFFFFFF, 0x80000000, 1 << 28, 1 << 20, 0))
        struct.pack_into("<I", b, rng.choice(at), value)
    elif kind == 3 and len(b) >= 12:  # a float64 where one may be
        struct.pack_into("<d", b, 4 + 4 * rng.randrange((len(b) - 12) // 4 + 1), rng.choice(SPECIAL_FLOATS))
    elif kind == 4 and b:
        i, j = sorted(rng.randrange(len(b) + 1) for _ in range(2))
        b = b[:i] + b[j:] if rng.random() < 0.5 else b[:j] + b[i:j] + b[j:]
    elif kind == 5:
        b = bytearray(rng.getrandbits(8) for _ in range(rng.randrange(300)))
    else:
        b = b[:4] + bytearray(rng.getrandbits(8) for _ in range(rng.randrange(300)))
    return bytes(b)


# -- Parameters and cases ---------------------------------------------------------------------------


def parameter_rows():
    """(name, check or None) of every parameter the node declares: its own rows and the mapper's keys."""
    from vasco_gpu.ros.settings import NODE_PARAMETERS, mapper_parameter_names

    return [(p.name, p.check) for p in NODE_PARAMETERS] + [(n, None) for n in mapper_parameter_names()]


def in_range(rng: random.Random, name: str, check):
    """A value the parameter's check may take (a mapper key: a plausible number)."""
    kind = type(check).__name__
    if name in ("save_map_path", "session_path", "load_session", "param_file"):  # relative: in the working dir
        files = [rng.choice(FILE_NAMES) for _ in range(rng.randrange(1, 3))]
        return files if kind == "Names" else files[0]
    if kind == "Number":
        lo = check.lo if check.lo is not None else -10.0
        hi = check.hi if check.hi is not None else lo + rng.choice((1.0, 10.0, 1000.0))
        if check.whole:
            return rng.randint(int(lo), int(min(hi, lo + 1000)))
        return rng.uniform(lo, hi)
    a = rng.uniform(-2, 2)
    pick = {"Choice": lambda: rng.choice(check.names), "Flag": lambda: rng.random() < 0.5,
            "Band": lambda: [a, a + rng.uniform(0.1, 5)],
            "Pair": lambda: [a, a + rng.uniform(0.1, 5)][: rng.choice((0, 2))],
            "Names": lambda: [rng.choice(("scan", "echo", "cloud", "/x"))],
            "Text": lambda: rng.choice(("map", "base_link", "odom", "trajectory", "laser"))}
    if kind in pick:
        return pick[kind]()
    return rng.choice((0.01, 0.05, 0.1, 0.5, 0.6, 0.9, 1, 2, 10, 50.0))  # a mapper key


def good_parameters(start: dict) -> list:
    """[name, value] of every parameter a running node may change, as the case started it: the start
    value, else the default (a mapper key: unset)."""
    from vasco_gpu.ros.settings import NODE_PARAMETERS, mapper_parameter_names

    rows = [[p.name, start.get(p.name, p.default)] for p in NODE_PARAMETERS if p.dynamic]
    return rows + [[n, start.get(n)] for n in mapper_parameter_names()]


def param_value(rng: random.Random, name: str, check):
    return rng.choice(HOSTILE_VALUES) if rng.random() < 0.4 else in_range(rng, name, check)


def start_parameters(rng: random.Random, rows) -> dict:
    """The node's start parameters: the topics fed, a CPU backend, a bounded session; now and then
    one more of the node's own, in range or hostile."""
    p = {"scan_topics": ["scan"], "multi_echo_topics": ["echo"], "cloud_topics": ["cloud"],
         "path_topic": "trajectory", "backend": rng.choice(("cpu_double", "cpu_float", "cpu_threads")),
         "threads": 1, "max_memory": MAX_MEMORY, "map_mode": "scale", "save_map_path": ["map"],
         "session_path": "s.session", "scan_batch_interval": rng.choice((0.0, 0.1)),
         "on_time_jump": rng.choice(("reset", "keep")), "resolution": rng.choice((0.05, 0.1))}
    if rng.random() < 0.3:
        name, check = rng.choice([r for r in rows if r[1] is not None and r[0] not in START_FIXED])
        p[name] = param_value(rng, name, check)
    return p


class Case:
    """The operations of one case, made from its seed alone: a robot driving in a circle that
    publishes tf and scans, Paths over recent stamps, and hostile traffic and calls among them."""

    def __init__(self, seed: int, m: dict, rows):
        self.rng = rng = random.Random(seed)
        self.g = Gen(rng, m, hostile=rng.choice((0.02, 0.1, 0.3)))
        self.m, self.rows, self.ops = m, rows, []
        self.start = start_parameters(rng, rows)
        self.ns, self.trail = BASE_S * NS + rng.randrange(NS), []
        self._make(rng.randrange(20, 160))

    def msg(self, topic: str, msg) -> None:
        data = bytes(self.m["serialize"](msg))
        if self.rng.random() < self.g.hostile:
            data = mutate(self.rng, data)
        self.ops.append(["msg", topic, data.hex()])

    def _make(self, steps: int) -> None:
        g, r = self.g, self.rng
        for child, x in ((LASER_FRAME, 0.2), (CLOUD_FRAME, 0.0)):  # the mounts
            self.msg("tf_static", self.m["TFMessage"](transforms=[g.link("base_link", child, self.ns, x, 0.0, 0.0)]))
        for _ in range(steps):
            self._step(r.random())
        # beyond the case's scans (a 5 m circle, ranges to 30 m): saturated cells show no hit gained
        self.ops.append(["check", r.uniform(45, 55), r.uniform(-10, 10), r.uniform(-3, 3)])

    def _step(self, u: float) -> None:
        g, r = self.g, self.rng
        if u < 0.55:  # the robot moves; tf, then a scan of one kind
            self.ns += r.choice((20_000_000, 50_000_000, 100_000_000))
            a = len(self.trail) * 0.05
            pose = (5 * math.cos(a), 5 * math.sin(a), a + math.pi / 2)
            self.trail.append((self.ns, pose))
            self.msg("tf", self.m["TFMessage"](transforms=[g.link("map", "base_link", self.ns, *pose)]))
            kind = r.choice(("scan", "scan", "echo", "cloud"))
            self.msg(kind, getattr(g, kind)(self.ns))
        elif u < 0.65 and self.trail:
            tail = self.trail[-r.randrange(1, min(len(self.trail), 200) + 1):]
            self.msg("path", g.path([t for t, _ in tail], [p for _, p in tail], "map"))
        elif u < 0.72:
            self.msg(r.choice(("tf", "tf_static")), self.m["TFMessage"](transforms=self._hostile_links()))
        elif u < 0.80:
            self.ops.append(["timers"])
        elif u < 0.90:
            self.ops.append(["params", r.random() < 0.3, self._param_change()])
        else:
            service = r.choice(SERVICES)
            self.ops.append(["service", service, r.random() < 0.5])

    def _hostile_links(self) -> list:
        g, r = self.g, self.rng
        frames = ("map", "base_link", "odom", LASER_FRAME, CLOUD_FRAME, "a", "b")
        return [g.link(r.choice(frames), r.choice(frames), self.ns + r.randrange(-10 * NS, 10 * NS),
                       r.uniform(-5, 5), r.uniform(-5, 5), r.uniform(-3, 3)) for _ in range(r.randrange(1, 6))]

    def _param_change(self) -> list:
        picked = [self.rng.choice(self.rows) for _ in range(self.rng.choice((1, 1, 2, 3)))]
        return [[name, param_value(self.rng, name, check)] for name, check in picked]


# -- Running a case on a node -----------------------------------------------------------------------


class Finding(Exception):
    """An invariant broken at operation index (-1: the start-up)."""

    def __init__(self, kind: str, index: int, text: str, where: str = ""):
        super().__init__(text)
        self.kind, self.index, self.text, self.where = kind, index, text, where

    def signature(self) -> str:
        return f"{self.kind}:{self.text.split(':')[0]}:{self.where}"


def node_frame(tb) -> str:
    """The innermost frame of a traceback in the package (file:line function), else the innermost."""
    frames = traceback.extract_tb(tb)
    ours = [f for f in frames if f"{os.sep}vasco_gpu{os.sep}" in f.filename] or frames
    f = ours[-1]
    return f"{Path(f.filename).parent.name}/{Path(f.filename).name}:{f.lineno} {f.name}" if f else "?"


@contextmanager
def quiet_stderr(on: bool):
    """rclpy's deserialization prints to fd 2 for each message it refuses; the node logs each refusal."""
    saved = os.dup(2) if on else None
    if on:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
    try:
        yield
    finally:
        if on:
            os.dup2(saved, 2)
            os.close(saved)


class Runner:
    """Runs cases, each on a fresh MappingNode of one rclpy context."""

    def __init__(self, m: dict, verbose: bool, op_limit: float):
        import rclpy

        self.rclpy, self.m, self.verbose, self.op_limit = rclpy, m, verbose, op_limit
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.ops_run = self.undeliverable = self.refused_starts = 0

    def run(self, start: dict, ops: list) -> None:
        """Raises Finding for the first invariant broken."""
        from rclpy.parameter import Parameter
        from vasco_gpu.ros.node import MappingNode
        from vasco_gpu.ros.settings import SettingsError

        try:
            node = MappingNode(context=self.context, enable_rosout=False,
                               parameter_overrides=[Parameter(k, value=v) for k, v in start.items()])
        except SettingsError:
            self.refused_starts += 1
            return
        except Exception as e:
            raise Finding("exception", -1, f"{type(e).__name__}: {e}", node_frame(e.__traceback__)) from e
        try:
            if not self.verbose:
                self.rclpy.logging.set_logger_level(node.get_logger().name, self.rclpy.logging.LoggingSeverity.FATAL)
            self._guard(-1, node.start)
            if node.live is None:
                self.refused_starts += 1  # configure refused (configure_error): no mapping to fuzz
                return
            for k, op in enumerate(ops):
                self._guard(k, lambda: self.do(node, op, k, start))
        finally:
            node.destroy_node()

    def _guard(self, index: int, call):
        t = time.monotonic()
        try:
            call()
        except Finding:
            raise
        except Exception as e:
            raise Finding("exception", index, f"{type(e).__name__}: {e}", node_frame(e.__traceback__)) from e
        took = time.monotonic() - t
        if took > self.op_limit:
            raise Finding("slow", index, f"took {took:.1f} s (--op-limit {self.op_limit:g})")
        self.ops_run += 1

    def do(self, node, op: list, index: int, start: dict) -> None:
        if self.verbose:
            print(f"[{index}] {op[0]} {str(op[1:])[:160]}", flush=True)
        kind = op[0]
        if kind == "msg":
            self.deliver(node, TOPICS[op[1]], bytes.fromhex(op[2]))
        elif kind == "timers":
            self.fire_timers(node)
        elif kind == "params":
            self.set_params(node, op[1], op[2])
        elif kind == "service":
            self.call(node, op[1], op[2])
        elif kind == "check":
            self.check(node, index, start, *op[1:])

    @staticmethod
    def fire_timers(node) -> None:
        """Each timer of the node that runs fires once, as the executor would when it is due."""
        for timer in list(node.timers):
            if not timer.is_canceled():
                timer.callback()

    def deliver(self, node, topic: str, data: bytes) -> None:
        """The bytes to the subscription of topic, as the executor gives them: deserialized, or raw."""
        sub = next((s for s in node.subscriptions if s.topic_name == topic), None)
        if sub is None:
            return
        if sub.raw:
            sub.callback(data)
            return
        try:
            with quiet_stderr(not self.verbose):
                msg = self.m["deserialize"](data, sub.msg_type)
        except Exception:  # rclpy refuses it: DDS would never deliver it
            self.undeliverable += 1
            return
        sub.callback(msg)

    def set_params(self, node, atomic: bool, pairs: list) -> list:
        from rcl_interfaces.msg import SetParametersResult
        from rclpy.exceptions import ParameterNotDeclaredException
        from rclpy.parameter import Parameter

        params = [Parameter(name, value=value) for name, value in pairs]
        try:
            got = node.set_parameters_atomically(params) if atomic else node.set_parameters(params)
        except ParameterNotDeclaredException as e:  # as rclpy's parameter service answers it
            got = SetParametersResult(successful=False, reason=str(e))
        results = got if isinstance(got, list) else [got]
        if self.verbose:
            print("    " + "; ".join(f"{r.successful} {r.reason}" for r in results))
        return results

    def call(self, node, name: str, flag: bool):
        service = next(s for s in node.services if s.srv_name.endswith("/" + name))
        request = service.srv_type.Request()
        if name == "pause":
            request.data = flag
        response = service.callback(request, service.srv_type.Response())
        if self.verbose and hasattr(response, "message"):
            print(f"    {response.success} {response.message}")
        return response

    def endpoint_evidence(self, node, x: float, y: float, yaw: float) -> int:
        """The sum of ~/dynamic_map's values (scale: 0-100, unknown -1, outside the grid -1) at the
        cells where the check scan's beams end: a hit raises it, wherever earlier scans left it."""
        grid = self.call(node, "dynamic_map", False).map
        info, total = grid.info, 0
        for k in range(CHECK_BEAMS):
            a = yaw - math.pi / 2 + k * math.pi / 180
            col = math.floor((x + CHECK_RANGE * math.cos(a) - info.origin.position.x) / (info.resolution or 1))
            row = math.floor((y + CHECK_RANGE * math.sin(a) - info.origin.position.y) / (info.resolution or 1))
            inside = 0 <= col < info.width and 0 <= row < info.height
            total += grid.data[row * info.width + col] if inside else -1
        return total

    def check(self, node, index: int, start: dict, x: float, y: float, yaw: float) -> None:
        """The case's parameters back and mapping on; then a scan in a frame of its own and its /tf
        must raise ~/dynamic_map's values where its beams end. A scan refused for max_memory (a pose
        far away made the grid too large for the budget: by design) is tried again on a new map."""
        good = [[name, value] for name, value in good_parameters(start) if node.has_parameter(name)]
        results = self.set_params(node, True, good)
        if not all(r.successful for r in results):
            self.call(node, "reset", False)  # a remap of the stored scans may exceed max_memory
            results = self.set_params(node, True, good)
            if not all(r.successful for r in results):
                raise Finding("check", index, f"the start parameters set back refused: {results[0].reason}")
        self.call(node, "pause", False)
        ns = (BASE_S + 3600) * NS + index * 10**7
        counted = dict(getattr(node, "refused", {}))  # the node's own count of what it did not map
        before, after = self.map_good_scan(node, f"check_{index}", ns, x, y, yaw)
        grew = {k for k, n in getattr(node, "refused", {}).items() if counted.get(k) != n}
        if after <= before and grew and all("max_memory" in cause for _, cause in grew):
            self.call(node, "reset", False)
            before, after = self.map_good_scan(node, f"check_{index}_again", ns + 1, x, y, yaw)
        if after <= before:
            counted = getattr(node, "refused", "?")
            raise Finding("check", index, f"a good scan and its /tf were not mapped: evidence at its beams' ends "
                                          f"{before} before, {after} after (the node's refusals: {counted})")

    def map_good_scan(self, node, frame: str, ns: int, x: float, y: float, yaw: float) -> tuple[int, int]:
        """A half-turn scan of 2 m ranges in frame at stamp ns, then its /tf map -> frame (so that a
        time jump the scan causes does not clear it), then the timers: (evidence before, after)."""
        scan = self.m["LaserScan"](angle_min=-math.pi / 2, angle_increment=math.pi / 180, range_max=30.0,
                                   angle_max=-math.pi / 2 + (CHECK_BEAMS - 1) * math.pi / 180,
                                   ranges=[CHECK_RANGE] * CHECK_BEAMS)
        scan.header.frame_id, (scan.header.stamp.sec, scan.header.stamp.nanosec) = frame, divmod(ns, NS)
        self.deliver(node, TOPICS["scan"], bytes(self.m["serialize"](scan)))
        before = self.endpoint_evidence(node, x, y, yaw)
        g = Gen(random.Random(0), self.m, hostile=0.0)
        fixed = node.settings.map_frame  # a start value the case may have changed (read-only)
        tf = self.m["TFMessage"](transforms=[g.link(fixed, frame, ns, x, y, yaw)])
        self.deliver(node, TOPICS["tf"], bytes(self.m["serialize"](tf)))
        self.fire_timers(node)
        return before, self.endpoint_evidence(node, x, y, yaw)


# -- Reproducers, shrinking -----------------------------------------------------------------


def shrink(runner: Runner, start: dict, ops: list, finding: Finding, budget_s: float):
    """Drops chunks of operations while the same finding remains (never the failing one itself)."""
    deadline = time.monotonic() + budget_s
    ops = ops[: finding.index + 1]
    chunk = max(1, len(ops) // 2)
    while chunk >= 1 and time.monotonic() < deadline:
        k, shrunk = 0, False
        while k < len(ops) - 1 and time.monotonic() < deadline:
            trial = ops[:k] + ops[k + chunk:]
            try:
                runner.run(start, trial)
                found = None
            except Finding as f:
                found = f if f.signature() == finding.signature() and f.index >= 0 else None
            if found is not None:
                ops, finding, shrunk = trial[: found.index + 1], found, True
            else:
                k += chunk
        if not shrunk:
            chunk //= 2
    return ops, finding


def save_case(path: Path, seed: int, start: dict, ops: list, finding: Finding | None = None) -> None:
    doc = {"case_seed": seed, "start": start, "ops": ops}
    if finding is not None:
        doc["finding"] = {"kind": finding.kind, "index": finding.index, "text": finding.text, "where": finding.where}
    path.write_text(json.dumps(doc, indent=0))


def report(a, run_seed: int, case_seed: int, start: dict, ops: list, f: Finding, runner: Runner) -> Path:
    print(f"fuzz_node: FINDING in case {case_seed} (run seed {run_seed}) at operation {f.index}"
          f"{' (start-up)' if f.index < 0 else ' (' + ops[f.index][0] + ')'}: {f.kind}: {f.text}"
          f"{' [in ' + f.where + ']' if f.where else ''}", flush=True)
    if f.__cause__ is not None:
        print("".join(traceback.format_exception(f.__cause__)).rstrip()[-3000:], flush=True)
    if f.kind != "slow" and f.index >= 0:
        with quiet_stderr(True):
            ops, f = shrink(runner, start, ops, f, budget_s=a.shrink_seconds)
    path = Path(a.artifact_dir) / f"fuzz_node-finding-{case_seed}.json"
    save_case(path, case_seed, start, ops[: f.index + 1] if f.index >= 0 else [], f)
    print(f"fuzz_node: reproducer ({min(len(ops), f.index + 1)} operations) written to {path}; replay: "
          f"{Path(sys.argv[0]).name} --replay {path}", flush=True)
    return path


def parse(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=60.0, help="how long to fuzz (default 60)")
    p.add_argument("--seed", type=int, default=None, help="the run's seed (default: from the clock, printed)")
    p.add_argument("--artifact-dir", default=".", help="where reproducers are written (default: here)")
    p.add_argument("--op-limit", type=float, default=30.0, help="seconds an operation may take (default 30)")
    p.add_argument("--rss-growth-mb", type=float, default=512.0,
                   help="MiB the resident size may grow past its size after the first case (default 512)")
    p.add_argument("--shrink-seconds", type=float, default=60.0, help="time to shrink a reproducer (default 60)")
    p.add_argument("--keep-going", action="store_true", help="after a finding, go on (each reported once)")
    p.add_argument("--replay", type=Path, default=None, metavar="JSON", help="run a reproducer again, verbosely")
    return p.parse_args(argv)


def replay(runner: Runner, path: Path) -> int:
    doc = json.loads(path.read_text())
    print(f"case {doc['case_seed']}: start parameters {doc['start']}, {len(doc['ops'])} operations")
    try:
        runner.run(doc["start"], doc["ops"])
    except Finding as f:
        if f.__cause__ is not None:
            traceback.print_exception(f.__cause__)
        print(f"fuzz_node: reproduced at operation {f.index}: {f.kind}: {f.text} [{f.where}]")
        return 1
    print("fuzz_node: not reproduced")
    return 0


def fuzz(a, runner: Runner, m: dict) -> int:
    seed = a.seed if a.seed is not None else time.time_ns() % 2**32
    master, rows = random.Random(seed), parameter_rows()
    begin, cases, baseline, peak, seen = time.monotonic(), 0, None, 0.0, {}
    last = Path(a.artifact_dir) / "fuzz_node-last-case.json"
    print(f"fuzz_node: seed {seed}, {a.seconds:g} s, ROS_DOMAIN_ID {os.environ['ROS_DOMAIN_ID']}", flush=True)
    while time.monotonic() - begin < a.seconds:
        case_seed = master.getrandbits(48)
        case = Case(case_seed, m, rows)
        save_case(last, case_seed, case.start, case.ops)  # for a crash that kills the process
        try:
            with quiet_stderr(True):
                runner.run(case.start, case.ops)
        except Finding as f:
            if f.signature() not in seen:
                seen[f.signature()] = report(a, seed, case_seed, case.start, case.ops, f, runner)
            if not a.keep_going:
                break
        cases += 1
        rss = int(Path("/proc/self/statm").read_text().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
        baseline = rss if baseline is None else baseline
        peak = max(peak, rss)
        if rss - baseline > a.rss_growth_mb:
            print(f"fuzz_node: FINDING: memory: resident size {rss:.0f} MiB after {cases} cases, {baseline:.0f} "
                  f"after the first (--rss-growth-mb {a.rss_growth_mb:g}); run again: --seed {seed} --seconds "
                  f"{time.monotonic() - begin:.0f}", flush=True)
            seen["memory"] = None
            break
    last.unlink(missing_ok=True)
    took = time.monotonic() - begin
    counts = (f"{cases} cases, {runner.ops_run} operations in {took:.0f} s (seed {seed}); {runner.undeliverable} "
              f"messages rclpy could not deserialize, {runner.refused_starts} start-ups refused; resident "
              f"{baseline or 0:.0f} -> {peak:.0f} MiB")
    if seen:
        print(f"fuzz_node: FAILED: {len(seen)} distinct findings; {counts}", *(
            f"  reproducer: {path}" for path in seen.values() if path is not None), sep="\n")
        return 1
    print(f"fuzz_node: ok: {counts}")
    return 0


def main(argv=None) -> int:
    try:
        a = parse(argv)
    except SystemExit as e:
        return 0 if e.code == 0 else 2
    try:
        m = ros()
        importlib.import_module("vasco_gpu.ros.node")
    except ImportError as e:
        print(f"fuzz_node: ROS 2's Python packages do not import ({e}): run it with a Python that has rclpy and "
              f"the node's messages (pip install '.[ros]' ./ros)", file=sys.stderr)
        return 2
    Path(a.artifact_dir).mkdir(parents=True, exist_ok=True)
    a.artifact_dir = str(Path(a.artifact_dir).resolve())
    replay_path = a.replay.resolve() if a.replay else None
    faulthandler.enable(file=sys.stdout)  # a hard crash: fuzz_node-last-case.json holds its case
    here = os.getcwd()
    with tempfile.TemporaryDirectory(prefix="fuzz_node-") as workdir:
        os.chdir(workdir)  # the file parameters (save_map_path, session_path) are relative: here
        runner = Runner(m, verbose=replay_path is not None, op_limit=a.op_limit)
        try:
            return replay(runner, replay_path) if replay_path else fuzz(a, runner, m)
        finally:
            runner.rclpy.try_shutdown(context=runner.context)
            os.chdir(here)


if __name__ == "__main__":
    sys.exit(main())
