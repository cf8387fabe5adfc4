"""The ROS 2 node's side of bench/large_site_bench.py (its docstring says what is measured): the node
on a site's session, a bare node (no session), and a latched map's floor: a process that does
nothing but publish one latched OccupancyGrid of a /map's cells, the memory any node that serves
/map as map_server and slam_toolbox do (transient local) holds for it. ROS processes run on Fast
DDS's shared memory in a domain of this run's own."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCAN_PERIOD_NS = 25_000_000


def proc_bytes(pid, key: str) -> float:
    """A kB figure of /proc/PID/status in bytes (-1 when it cannot be read)."""
    try:
        for line in open(f"/proc/{pid}/status"):
            if line.startswith(key + ":"):
                return float(line.split()[1]) * 1024
    except OSError:
        pass
    return -1.0


def ros_modules():
    """ros_support (the environment, before rclpy starts), in a domain of this run's own, and the
    player's class; imported only when the node is benched."""
    sys.path.insert(0, str(ROOT / "python" / "tests"))
    import ros_support

    domain = str(150 + os.getpid() % 81)  # 150-230: apart from the tests' 100-149
    ros_support.ROS_ENV["ROS_DOMAIN_ID"] = domain
    os.environ["ROS_DOMAIN_ID"] = domain
    import rclpy
    from ros_player import Player

    return ros_support, rclpy, Player


def listener_class(Player):
    class Listener(Player):
        """The tests' player keeping no map: for each /map and map_updates message its arrival
        (monotonic s), its data's bytes and its transport (source timestamp -> callback, ns)."""

        def __init__(self):
            self.events: list[tuple[float, str, int, int]] = []
            super().__init__()

        def _on_map(self, msg, info):
            arrived = time.time_ns()
            with self.lock:
                self.maps.append((time.monotonic(), None))
                self.events.append((time.monotonic(), "map", len(msg.data), arrived - info["source_timestamp"]))

        def _on_update(self, u, info):
            arrived = time.time_ns()
            with self.lock:
                self.events.append((time.monotonic(), "update", len(u.data), arrived - info["source_timestamp"]))

    return Listener


def node_memory(pid: int) -> dict:
    """The node's resident figures (bytes) and its largest mappings (/proc/PID/smaps: size, Rss, name)."""
    out = {k: proc_bytes(pid, k) for k in ("VmRSS", "VmHWM", "RssAnon", "RssFile", "RssShmem")}
    maps, head = [], None
    try:
        for line in open(f"/proc/{pid}/smaps"):
            if not line.split(None, 1)[0].endswith(":"):  # a mapping's first line, not one of its fields
                head = line.split()
            elif line.startswith("Rss:") and head is not None:
                lo, hi = (int(v, 16) for v in head[0].split("-"))
                maps.append((hi - lo, float(line.split()[1]) * 1024, head[5] if len(head) > 5 else "[anon]"))
    except OSError:
        pass
    out["mappings"] = sorted(maps, key=lambda m: -m[1])[:8]
    return out


def wait_for_maps(listener, count: int, timeout: float) -> bool:
    end = time.monotonic() + timeout
    while listener.map_count() < count:
        if time.monotonic() > end:
            return False
        time.sleep(0.01)
    return True


def path_to_map(listener, saved, poses: np.ndarray, timeout: float) -> dict:
    """A Path of every pose at `poses` (moved) -> the node's re-rendered /map: publish -> callback (ms)."""
    from rclpy.serialization import serialize_message

    raw = serialize_message(listener.path_message(saved.stamps, poses))
    listener.wait_quiet(1.0)
    n = listener.map_count()
    t0 = time.monotonic()
    listener.path.publish(raw)
    if not wait_for_maps(listener, n + 1, timeout):
        return {"error": f"no /map within {timeout:.0f} s of a Path"}
    with listener.lock:
        at, kind, nbytes, wire = [e for e in listener.events if e[1] == "map"][-1]
    return {"path_ms": (at - t0) * 1e3, "wire_ms": wire / 1e6, "bytes": nbytes}


def replay_updates(listener, saved, scans: int) -> list:
    """scans of the site again (new stamps, after the session's) at 40 Hz; the map_updates events."""
    first = len(listener.events)
    start = int(saved.stamps[-1]) + 10**9
    stamps = start + np.arange(scans, dtype=np.int64) * SCAN_PERIOD_NS
    first_scans = replace(saved, stamps=stamps, poses=saved.poses[:scans], mounts=saved.mounts[:scans],
                          first_angle=saved.first_angle[:scans], angle_step=saved.angle_step[:scans],
                          beam_counts=saved.beam_counts[:scans], ranges=saved.ranges[:int(saved.beam_counts[:scans].sum())])
    listener.replay(first_scans, stamps, rate_hz=40.0)
    end, seen, since = time.monotonic() + 180, len(listener.events), time.monotonic()
    while time.monotonic() - since < 10 and time.monotonic() < end:  # each update costs a whole finish
        time.sleep(0.1)
        if len(listener.events) != seen:
            seen, since = len(listener.events), time.monotonic()
    with listener.lock:
        return [e for e in listener.events[first:] if e[1] == "update"]


def node_params(site: Path, backend: tuple) -> dict:
    name, mode = backend
    return {"backend": name, "cuda_mode": mode, "load_session": str(site), "max_memory": 0, "scan_qos": "reliable",
            "map_update_interval": 0.5, "transform_timeout": 60.0}


def run_node(modules, site: Path, saved, moved_poses: np.ndarray, backend: tuple, replay: int) -> dict:
    """The node on the site (the bench's docstring: node), its mapper backend (name, cuda mode);
    its figures."""
    ros_support, rclpy, Player = modules
    listener = listener_class(Player)()
    proc = ros_support.NodeProcess(node_params(site, backend))
    try:
        t0 = time.monotonic()
        proc.wait_for("ready", timeout=900)
        if not wait_for_maps(listener, 1, 600):
            return {"error": "no first /map within 600 s"}
        row = {"load_s": time.monotonic() - t0, "first": listener.events[0]}
        time.sleep(1.0)
        row["mem_first"] = node_memory(proc.proc.pid)
        row["path"] = path_to_map(listener, saved, moved_poses, 600)
        time.sleep(1.0)
        row["mem_path"] = node_memory(proc.proc.pid)
        row["updates"] = replay_updates(listener, saved, replay)
        row["mem_end"] = node_memory(proc.proc.pid)
        rc, _ = proc.interrupt(timeout=120)
        line = next((ln for ln in proc.lines if ln.startswith("/vasco_mapper: ") and " scans mapped" in ln), "")
        row.update(rc=rc, summary=line.split("vasco_mapper: ", 1)[-1])
        return row
    except AssertionError as e:
        return {"error": str(e).splitlines()[0] + " | " + " / ".join(proc.lines[-3:])}
    finally:
        proc.kill()
        listener.close()


def run_bare_node(modules, backend: tuple) -> dict:
    """The node with no session (the same backend, no map yet): its resident memory once ready, the
    fixed part every size's node holds before its first cell (interpreter, rclpy, Fast DDS, the
    library): the node target's floor for a size's own figure."""
    ros_support = modules[0]
    name, mode = backend
    proc = ros_support.NodeProcess({"backend": name, "cuda_mode": mode, "max_memory": 0})
    try:
        proc.wait_for("ready", timeout=120)
        time.sleep(1.0)
        return node_memory(proc.proc.pid)
    except AssertionError as e:
        return {"error": str(e).splitlines()[0]}
    finally:
        try:
            proc.interrupt(timeout=30)
        except subprocess.TimeoutExpired:
            pass  # killed below
        proc.kill()


def latched_floor(modules, cells: int) -> dict:
    """A latched map's floor: another process publishes one OccupancyGrid of `cells` cells on a
    topic of its own with /map's QoS (the node's), lets the message go, and reads its resident
    memory before and after: the bytes the DDS writer keeps for the map (its latched sample)
    beside a bare rclpy process's."""
    env = {**os.environ, **modules[0].ROS_ENV, "PYTHONPATH": os.pathsep.join(sys.path)}
    try:
        out = subprocess.run([sys.executable, __file__, "--latched-child", str(cells)], capture_output=True,
                             text=True, env=env, timeout=300)
    except subprocess.TimeoutExpired:
        return {"error": "the latched map's process took over 300 s"}
    if out.returncode != 0:
        return {"error": (out.stderr.strip().splitlines() or ["no output"])[-1]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def latched_child(cells: int) -> dict:
    import gc
    from array import array

    import rclpy
    from nav_msgs.msg import OccupancyGrid

    from vasco_gpu.ros.grid import array_keeping_message
    from vasco_gpu.ros.publication import LATCHED

    rclpy.init()
    node = rclpy.create_node("latched_floor")
    pub = node.create_publisher(OccupancyGrid, "latched_floor_map", LATCHED)
    time.sleep(0.5)
    before = proc_bytes("self", "VmRSS")
    msg = array_keeping_message(OccupancyGrid)
    msg.info.width, msg.info.height = cells, 1
    msg.data = array("b", b"\xff") * cells
    pub.publish(msg)
    msg.data = array("b")
    gc.collect()
    time.sleep(1.0)
    after = proc_bytes("self", "VmRSS")
    node.destroy_node()
    rclpy.try_shutdown()
    return {"cells": cells, "before": before, "after": after, "latched": after - before}


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--latched-child":
        print(json.dumps(latched_child(int(sys.argv[2]))))
