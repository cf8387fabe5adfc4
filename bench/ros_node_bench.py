#!/usr/bin/env python3
"""The ROS 2 node live: each log replayed as LaserScan + /tf at the sensor's rate (40 Hz) and
then faster than real time, then a nav_msgs/Path of every pose published again and again,
for each backend. Printed as a table, ratios in the same run:

  batch       the node's scan_batch_interval (s): scans posed and mapped together that often
              (0: each on arrival, every message a callback); --batch runs each backend with each
  scans       mapped / sent (a replay over reliable QoS loses none while the node keeps up)
  CPU idle    the node process's CPU time over wall time for 3 s before the replay (% of
              one core: timers, DDS threads)
  CPU 40 Hz   the node process's CPU time over wall time while scans arrive at 40 Hz (%
              of one core: callbacks, tf, conversion, DDS threads, the insert)
  CPU fast    the same at --fast-rate
  scan p50/p99  the node's own: the scan received (DDS's stamp when batched, else the callback's
              entry) -> the scan in the grid (ms): a batch waits up to its interval
  Path->/map  publish() of the serialized Path -> the new /map in this process's subscriber
              (ms, median and best of --paths), the whole loop a SLAM back end sees
  floor       what no node can go below: ROS 2's own cost for the Path and a map of this size
              (ros_floor_relay.py in the node's place: it maps nothing and answers each Path with
              a /map made beforehand, taking and publishing as the node does; p50) plus the
              node's render (its repose and finish steps, p50); a line after the table gives its
              parts and how far Path->/map is above it
  node        of that, the node's own: its Path callback's entry -> /map published (p50 ms:
              reading the Path, the render, the finish, the OccupancyGrid); the rest is DDS
              carrying the Path and the map, and the callbacks' wake-ups; its steps (batch: map
              the scans still waiting for their batch, read the Path, repose: move the scans
              and render, finish: CARMEN's finish as the OccupancyGrid's data (on the GPU for
              cuda), message: the rest of the message, publish) follow the table
  vs cpu_double  cpu_double's Path->/map (at the first --batch) over this one: against rebuilding the map from
              every scan on the CPU, as a CPU mapper does after a loop closure
  upd p50/p99 a scan batch's end -> its map_updates message in this process's subscriber (ms,
              over the whole replay), as the sum of two parts measured apart: the node's own
              (its batch timer's entry -> the update published, from its exit summary; cuda
              only: the CPU backends send updates on the publication timer instead, "-") and the
              transport (the update's source timestamp, which Fast DDS takes from the system
              clock as the publisher writes it -> this subscriber's callback entry, on the same
              clock: DDS, the wake-up, and this process's other callbacks ahead of it). The
              parts cannot be paired update by update (the node gives only its percentiles), so
              the column adds percentiles: the p50s' sum is a typical figure; the p99s' sum is
              the whole's p99 where an update slow in one part is slow in the other too, and
              whatever their correlation it bounds the whole's 98th percentile from above (the
              whole exceeds it only where a part exceeds its p99: at most 1 % + 1 %). Both
              parts, and the transport over the 40 Hz replay alone (the fast replay's publisher
              shares this process's interpreter), follow the table
  bytes/s 40 Hz  what the map topics carried per second while scans came at 40 Hz (kB/s of cell
              data: map_updates' rectangles and the full /maps of a new geometry) and how many
              times that whole maps would have been (each of those publications as the whole
              map it applied to): the bandwidth nav2's static layer with subscribe_to_updates
              saves, in the same run; the map_updates alone follow the table

The header names the ROS 2 distribution that ran (ROS_DISTRO, ros-rclpy's version), so runs on
Jazzy and Kilted can be set side by side. Every ROS process runs on Fast DDS's shared-memory
transport in a domain of its own (python/tests/ros_support.py). Needs the [ros] extra (or
[ros-jazzy]) and the message packages of ./ros (docs/ros.md).
  bench/ros_node_bench.py [--logs LOG...] [--backends B...] [--resolution 0.05 --downsample 1]
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import time
from importlib import metadata
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python" / "tests"))
import ros_support  # noqa: E402,F401  (the environment, before rclpy starts)
from ros_support import NodeProcess  # noqa: E402

import numpy as np  # noqa: E402
import rclpy  # noqa: E402
from rclpy.serialization import serialize_message  # noqa: E402

import vasco_gpu as vg  # noqa: E402
from ros_player import Player  # noqa: E402
from live_map_steps import BACKENDS, LOGS, backend_name  # noqa: E402  (beside this script)
from vasco_gpu.ros.settings import NODE_PARAMETERS  # noqa: E402

BATCH_DEFAULT = next(p.default for p in NODE_PARAMETERS if p.name == "scan_batch_interval")
RCLPY_DISTRO = {3: "humble", 7: "jazzy", 9: "kilted"}  # rclpy's major version per distribution


class TimedPlayer(Player):
    """The tests' player, also noting for each /map and map_updates message its arrival, its
    cell bytes, the bytes of the whole map it stands for, and its transport: the publisher's
    source timestamp -> this callback's entry (ns, both on the system clock)."""

    def __init__(self):
        self.events: list[tuple[float, str, int, int, int]] = []  # (monotonic s, kind, bytes, whole, transport ns)
        super().__init__()

    def _on_map(self, msg, info):
        arrived = time.time_ns()
        super()._on_map(msg, info)
        self.events.append((time.monotonic(), "map", len(msg.data), len(msg.data), arrived - info["source_timestamp"]))

    def _on_update(self, u, info):
        arrived = time.time_ns()
        base = self.latest()
        whole = base.info.width * base.info.height if base is not None else 0
        super()._on_update(u, info)
        self.events.append((time.monotonic(), "update", len(u.data), whole, arrived - info["source_timestamp"]))


def ros_distribution() -> str:
    """Which ROS 2 runs: the distribution, rclpy's version and where it comes from."""
    for dist in ("ros-rclpy", "rclpy"):
        try:
            version = metadata.version(dist)
            break
        except metadata.PackageNotFoundError:
            version = None
    major = int(re.match(r"\d+", version).group()) if version else None
    name = RCLPY_DISTRO.get(major, "unknown") if version else "unknown"
    env = os.environ.get("ROS_DISTRO") or "unset"
    return f"ROS 2 {name}: {dist if version else 'rclpy'} {version or '(version unknown)'}, ROS_DISTRO {env}"


def replay_measured(player, proc, scans, stamps, rate):
    """Replays at rate; the node's CPU share over the replay and the replay's monotonic span."""
    t0 = time.monotonic()
    share = proc.cpu_share(lambda: player.replay(scans, stamps, rate_hz=rate))
    return share, (t0, time.monotonic())


def path_latencies(player, raw: bytes, repeats: int) -> list[float]:
    out = []
    for _ in range(repeats):
        player.wait_quiet(1.0)
        n = player.map_count()
        t0 = time.monotonic()
        player.path.publish(raw)
        while player.map_count() == n:
            if time.monotonic() - t0 > 120:
                raise RuntimeError("no /map within 120 s of a Path")
            time.sleep(0.0002)
        out.append((player.maps[n][0] - t0) * 1e3)  # the subscriber callback's own clock reading
    return out


def summary_value(line: str, what: str) -> str:
    if what not in line:
        return "-"
    part = line.split(what + ": ", 1)[1].split(";")[0]
    p50 = part.split("p50 ")[1].split(" ms")[0]
    p99 = part.split("p99 ")[1].split(" ms")[0]
    return f"{p50}/{p99}"


def map_traffic(events, live_span, replay_span) -> dict:
    """The map topics' figures from the player's events: the transport of the updates over the
    whole replay and over the 40 Hz part (ms), and the 40 Hz part's bytes against whole maps."""
    def within(span):
        return [e for e in events if span[0] <= e[0] <= span[1]]

    def transport(span):
        ms = np.array([e[4] for e in within(span) if e[1] == "update"], dtype=float) / 1e6
        return (float(np.percentile(ms, 50)), float(np.percentile(ms, 99)), len(ms)) if len(ms) else None

    def traffic(kinds):  # bytes/s, and whole maps' bytes over those sent
        got = [e for e in within(live_span) if e[1] in kinds]
        sent, whole, seconds = sum(e[2] for e in got), sum(e[3] for e in got), live_span[1] - live_span[0]
        return sent / seconds if seconds > 0 else 0.0, whole / sent if sent else float("nan"), len(got)

    (rate, ratio, _), updates, maps = traffic(("map", "update")), traffic(("update",)), traffic(("map",))
    return {"wire": transport(replay_span), "wire_live": transport(live_span), "rate": rate, "ratio": ratio,
            "updates_only": updates, "live_maps": maps[2]}


def update_latency(node: str, wire) -> str:
    """The upd column: the node's batch -> published plus the transport, p50/p99 (ms)."""
    if node == "-" or wire is None:
        return "-"
    p50, p99 = (float(v) for v in node.split("/"))
    return f"{p50 + wire[0]:.2f}/{p99 + wire[1]:.2f}"


def published_counts(line: str) -> str:
    m = re.search(r"published (\d+) maps \(([\d.]+) MB\) and (\d+) map_updates \(([\d.]+) MB\)", line)
    return f"{m[1]} maps ({m[2]} MB), {m[3]} map_updates ({m[4]} MB)" if m else "-"


def bench_one(player, log, name, batch, args, stamps, raw_path):
    params = {**BACKENDS[name], "scan_qos": "reliable", "map_update_interval": 0.5, "transform_timeout": 2.0,
              "resolution": args.resolution, "vasco_downsample": args.downsample, "scan_batch_interval": batch}
    proc = NodeProcess(params)
    try:
        proc.wait_for("ready", timeout=120)
        time.sleep(1.0)  # past start-up and discovery
        cpu_idle = proc.cpu_share(lambda: time.sleep(3.0))
        first_event = len(player.events)
        live = min(args.live_scans, len(log))
        cpu_live, live_span = replay_measured(player, proc, log.scans.select(0, live), stamps[:live], args.rate)
        rest = log.scans.select(live, len(log) - live)
        cpu_fast = replay_measured(player, proc, rest, stamps[live:], args.fast_rate)[0] if len(rest) else 0.0
        player.wait_quiet(2.0)  # every scan mapped, the grid settled, the last map out
        traffic = map_traffic(player.events[first_event:], live_span, (live_span[0], time.monotonic()))
        lat = path_latencies(player, raw_path, args.paths)
        last = player.latest().info
        rc, _ = proc.interrupt(timeout=60)
        line = next((ln for ln in proc.lines if ln.startswith("/vasco_mapper: ") and " scans mapped" in ln), "")
        mapped = line.split("vasco_mapper: ", 1)[1].split(" scans mapped")[0] if line else "?"
        upd_node = summary_value(line, "batch -> map_updates published")
        return {"scans": f"{mapped}/{len(log)}", "cpu_idle": cpu_idle, "cpu_live": cpu_live, "cpu_fast": cpu_fast,
                "scan": summary_value(line, "scan -> grid"), "path_p50": float(np.median(lat)),
                "node": summary_value(line, "Path -> /map published").split("/")[0],
                "steps": line.split("Path steps p50 ms: ", 1)[1].split(";")[0] if "Path steps" in line else "-",
                "batch_steps": line.split("batch steps p50/p99 ms: ", 1)[1].split(";")[0]
                if "batch steps" in line else "-",
                "path_min": float(min(lat)), "rc": rc, "upd": update_latency(upd_node, traffic["wire"]),
                "upd_node": upd_node, "published": published_counts(line), "size": (last.width, last.height),
                "relay": relay_latencies(player, raw_path, args.paths, last.width, last.height), **traffic}
    finally:
        proc.kill()


def relay_latencies(player, raw_path: bytes, paths: int, width: int, height: int) -> list[float]:
    """Path -> /map through ros_floor_relay.py in the node's place (the node stopped): ROS 2's
    own cost for a Path and a map of the node's last size."""
    relay = NodeProcess({}, command=[sys.executable, str(ROOT / "bench" / "ros_floor_relay.py"), str(width), str(height)])
    try:
        relay.wait_for("ready", timeout=60)
        end = time.monotonic() + 30
        while player.path.get_subscription_count() == 0 and time.monotonic() < end:
            time.sleep(0.05)  # discovery: a Path published before the relay subscribed is lost
        time.sleep(1.0)  # its first (latched) /map arrives meanwhile
        return path_latencies(player, raw_path, paths)
    finally:
        relay.interrupt(timeout=30)
        relay.kill()


def step_ms(steps: str, name: str) -> float:
    """One step's p50 (ms) from the node's "batch 0.01, read 0.45, repose 1.28, ..."."""
    hit = re.search(rf"\b{name} ([\d.]+)", steps)
    return float(hit.group(1)) if hit else float("nan")


def floor_ms(r: dict) -> float:
    """ROS 2's own cost (the relay's p50) plus the node's render: what no node can go below."""
    return float(np.median(r["relay"])) + step_ms(r["steps"], "repose") + step_ms(r["steps"], "finish")


def print_rows(path: str, rows: dict, first_batch: float) -> None:
    ref = rows.get(("cpu_double", first_batch), {}).get("path_p50")
    for (name, b), r in rows.items():
        ratio = f"{ref / r['path_p50']:.1f}x" if ref else "-"
        traffic = f"{r['rate'] / 1e3:.1f} kB {r['ratio']:.1f}x" if r["rate"] else "-"
        print(f"{Path(path).name:<24} {name:<12} {b:>5g} {r['scans']:>11} {100 * r['cpu_idle']:>7.1f}% "
              f"{100 * r['cpu_live']:>8.1f}% "
              f"{100 * r['cpu_fast']:>7.1f}% {r['scan']:>16} {r['path_p50']:>13.1f} {r['path_min']:>7.1f} {floor_ms(r):>7.1f} "
              f"{r['node']:>7} "
              f"{ratio:>13} {r['upd']:>15} {traffic:>16}", flush=True)
    for (name, b), r in rows.items():
        print(f"#   {Path(path).name} {name}, batch {b:g} s: the node's Path steps, p50 ms: {r['steps']}", flush=True)
    for (name, b), r in rows.items():
        relay, floor = float(np.median(r["relay"])), floor_ms(r)
        print(f"#   {Path(path).name} {name}, batch {b:g} s: floor {floor:.2f} ms = ROS 2 alone {relay:.2f} (a relay "
              f"answering each Path with a ready {r['size'][0]} x {r['size'][1]} /map, p50, best "
              f"{min(r['relay']):.2f}) + the node's repose {step_ms(r['steps'], 'repose'):.2f} and finish "
              f"{step_ms(r['steps'], 'finish'):.2f}; Path->/map {r['path_p50']:.2f} ms is "
              f"{100 * (r['path_p50'] / floor - 1):.0f} % above it", flush=True)
    for (name, b), r in rows.items():
        wire, live = (f"{w[0]:.2f}/{w[1]:.2f} ({w[2]})" if w else "-" for w in (r["wire"], r["wire_live"]))
        u = r["updates_only"]
        print(f"#   {Path(path).name} {name}, batch {b:g} s: map_updates p50/p99 ms: node's batch -> published "
              f"{r['upd_node']}, published -> subscriber {wire}, at 40 Hz only {live}; at 40 Hz {u[2]} map_updates "
              f"({u[0] / 1e3:.1f} kB/s, whole maps {u[1]:.1f}x) and {r['live_maps']} full /maps; the node published "
              f"{r['published']}", flush=True)
    for (name, b), r in rows.items():
        print(f"#   {Path(path).name} {name}, batch {b:g} s: the node's batch steps, p50/p99 ms: {r['batch_steps']}",
              flush=True)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--logs", nargs="+", default=LOGS)
    ap.add_argument("--backends", nargs="+", default=None, help=f"of {', '.join(BACKENDS)}")
    ap.add_argument("--rate", type=float, default=40.0, help="the live replay's rate (Hz)")
    ap.add_argument("--live-scans", type=int, default=400, help="scans replayed at --rate")
    ap.add_argument("--fast-rate", type=float, default=400.0, help="the rest's rate (Hz)")
    ap.add_argument("--paths", type=int, default=5, help="Paths published, one after the other")
    ap.add_argument("--resolution", type=float, default=0.05, help="the map's cell (m): the node's resolution")
    ap.add_argument("--batch", type=float, nargs="+", default=[BATCH_DEFAULT],
                    help=f"the node's scan_batch_interval (s), each in turn (default {BATCH_DEFAULT:g}, the node's)")
    ap.add_argument("--downsample", type=int, default=1,
                    help="vasco_downsample (1: the evidence grid at --resolution too)")
    args = ap.parse_args()
    names = [backend_name(b) for b in args.backends] if args.backends else \
        [b for b in BACKENDS if vg.cuda_available() or not b.startswith("cuda")]
    rclpy.init()
    player = TimedPlayer()
    try:
        print(f"# {ros_distribution()}")
        print(f"# map cell {args.resolution:g} m (evidence grid {args.resolution / args.downsample:g} m); {args.live_scans} scans at {args.rate:g} Hz, "
              f"the rest at {args.fast_rate:g} Hz; Path -> /map over {args.paths} Paths")
        print(f"{'log':<24} {'backend':<12} {'batch':>5} {'scans':>11} {'CPU idle':>8} {'CPU 40 Hz':>9} {'CPU fast':>8} "
              f"{'scan p50/p99 ms':>16} {'Path->/map ms':>13} {'best':>7} {'floor':>7} {'node':>7} {'vs cpu_double':>13} "
              f"{'upd p50/p99 ms':>15} {'bytes/s 40 Hz':>16}")
        for path in args.logs:
            log = vg.load_log(ROOT / path)
            stamps = 10**12 + np.arange(len(log), dtype=np.int64) * int(1e9 / args.rate)
            raw = serialize_message(player.path_message(stamps, log.poses))
            rows = {(name, b): bench_one(player, log, name, b, args, stamps, raw) for name in names for b in args.batch}
            print_rows(path, rows, args.batch[0])
    finally:
        player.close()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
