#!/usr/bin/env python3
"""The ROS 2 node's Path steps without ROS: the node's session (LiveMap) fed every scan of a log
one at a time, as the node is, then timed on a Path of every pose at the scans' stamps, warm
(median of --runs), per backend. Printed as a table:

  repose    LiveMap.repose: the Path's poses to every scan's laser pose, and the render
  render    of that, Mapper.render alone (the backend's re-render from the stored scans)
  idle      LiveMap.repose again, each run after IDLE_S of sleep (median of 3), as the node
            applies a Path after a quiet spell: what the wake-up of the device and caches costs
  finish    LiveMap.finish: CARMEN's finish of the grid, the map in host memory
  data      the OccupancyGrid's int8 data of that map (grid.grid_values), trinary
  grid      LiveMap.finish_grid: the finish as that data at once, written into the last map's
            array (what the node does; on the GPU for cuda, where only the bytes come back):
            the work of finish + data

What the node adds to these (reading the Path, building and publishing the message, DDS) is
ros_node_bench.py's; run cold in the node, each step takes longer than here.
  bench/live_map_steps.py [--logs LOG...] [--backends B...] [--runs 7]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import vasco_gpu as vg
from vasco_gpu.ros.grid import grid_values
from vasco_gpu.ros.live_map import LiveMap

ROOT = Path(__file__).resolve().parents[1]
BACKENDS = {"cuda float": {"backend": "cuda", "cuda_mode": "float"},
            "cuda exact": {"backend": "cuda", "cuda_mode": "exact"},
            "cpu_threads": {"backend": "cpu_threads"}, "cpu_double": {"backend": "cpu_double"}}
LOGS = ["logs/fr079-complete.gfs.log.gz", "logs/fr101.carmen.log.gz"]
SCAN_PERIOD_NS = 25_000_000  # 40 Hz
IDLE_S = 1.0  # the ROS bench's quiet spell before each Path


def backend_name(name: str) -> str:
    """A --backends name: "cuda float" or, for a shell variable split on spaces, cuda_float."""
    for n in (name, name.replace("_", " ")):
        if n in BACKENDS:
            return n
    raise SystemExit(f"--backends {name!r}: not one of {', '.join(BACKENDS)}")


def median_ms(step, runs: int) -> float:
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        step()
        times.append(time.perf_counter() - t)
    return float(np.median(times)) * 1e3


def idle_ms(step) -> float:
    times = []
    for _ in range(3):
        time.sleep(IDLE_S)
        t = time.perf_counter()
        step()
        times.append(time.perf_counter() - t)
    return float(np.median(times)) * 1e3


def phases(stats: dict) -> str:
    return ", ".join(f"{k[:-2]} {stats[k] * 1e3:.2f}" for k in ("prep_s", "upload_s", "map_s", "download_s"))


def fed_session(log, name: str) -> LiveMap:
    """A LiveMap at 0.05 m (the evidence grid too, as the bench's node) fed scan by scan."""
    live = LiveMap(vg.Params(resolution=0.05, downsample=1), **BACKENDS[name])
    s = log.scans
    for i in range(len(log)):
        live.add(10**12 + i * SCAN_PERIOD_NS, s.poses[i], s.ranges_of(i), s.first_angle[i], s.angle_step[i],
                 (0.0, 0.0, 0.0))
    return live


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--logs", nargs="+", default=LOGS)
    ap.add_argument("--backends", nargs="+", default=None, help=f"of {', '.join(BACKENDS)}")
    ap.add_argument("--runs", type=int, default=7, help="timed runs a step (median); the CPU backends' render: 3")
    args = ap.parse_args()
    names = [backend_name(b) for b in args.backends] if args.backends else \
        [b for b in BACKENDS if vg.cuda_available() or not b.startswith("cuda")]
    print(f"# map cell 0.05 m (evidence grid 0.05 m); a Path of every pose at the scans' stamps; median of "
          f"{args.runs} warm runs (CPU backends' repose and render: 3)")
    print(f"{'log':<26} {'backend':<12} {'map':>11} {'repose ms':>9} {'idle ms':>8} {'render ms':>9} {'finish ms':>9} {'data ms':>8} {'grid ms':>8}")
    for path in args.logs:
        log = vg.load_log(ROOT / path)
        stamps = 10**12 + np.arange(len(log), dtype=np.int64) * SCAN_PERIOD_NS
        base = np.asarray(log.poses, dtype=np.float64)[:, :3].copy()
        for name in names:
            live = fed_session(log, name)
            slow = 3 if name.startswith("cpu") else args.runs
            poses = live._pose_array().copy()
            repose = median_ms(lambda: live.repose(stamps, base, 10**9), slow)
            idle = idle_ms(lambda: live.repose(stamps, base, 10**9))
            render = median_ms(lambda: live.mapper.render(poses), slow)
            stats = phases(live.mapper.last_stats)
            m = live.finish()
            finish = median_ms(live.finish, args.runs)
            data = median_ms(lambda: grid_values(m, "trinary"), args.runs)
            out = bytearray(m.size_x * m.size_y)
            grid = median_ms(lambda: live.finish_grid("trinary", 0.196, 0.65, out=out), args.runs)
            print(f"{Path(path).name:<26} {name:<12} {f'{m.size_x}x{m.size_y}':>11} {repose:>9.2f} {idle:>8.2f} {render:>9.2f} "
                  f"{finish:>9.2f} {data:>8.2f} {grid:>8.2f}", flush=True)
            print(f"#   {Path(path).name} {name}: the last render's phases, ms: {stats}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
