#!/usr/bin/env python3
"""What a loop-closure re-render costs from Python, to set beside session_bench's C++ number.

The same measurement as bench/session_bench.cc's "re-render" column: a session holding all
of fr079's scans (vasco's defaults), poses changed by a loop-closure correction (the second
half of the trajectory rotated by 2 degrees about the middle pose), then Mapper.render +
Mapper.finish timed from new poses in host memory (a NumPy array) to the finished map in
host memory (Map.cells), alternately corrected and original poses so that every run really
moves them; the median over --runs after --warmup runs. Prints one line.

    python python/bench_render.py --backend cuda                    # cuda float
    python python/bench_render.py --backend cuda --cuda-mode exact
    python python/bench_render.py --backend cpu_threads --runs 3
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import vasco_gpu as vg

LOG = Path(__file__).resolve().parents[1] / "logs" / "fr079-complete.gfs.log.gz"


def corrected(poses: np.ndarray) -> np.ndarray:
    """session_bench's correction: scans from the middle on rotated by 2 degrees about the
    middle scan's pose (the same expressions, in the same order)."""
    out = poses.copy()
    mid = len(poses) // 2
    a = 2.0 * math.pi / 180.0
    c, s = math.cos(a), math.sin(a)
    dx = poses[mid:, 0] - poses[mid, 0]
    dy = poses[mid:, 1] - poses[mid, 1]
    out[mid:, 0] = poses[mid, 0] + c * dx - s * dy
    out[mid:, 1] = poses[mid, 1] + s * dx + c * dy
    out[mid:, 2] = poses[mid:, 2] + a
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--backend", default="cpu_double", help="cpu_double (default), cpu_threads, cpu_float, cuda")
    ap.add_argument("--cuda-mode", default=None, choices=["float", "exact"])
    ap.add_argument("--threads", type=int, default=0, help="cpu_threads' threads (0: all cores)")
    ap.add_argument("--runs", type=int, default=20, help="timed runs (default 20)")
    ap.add_argument("--warmup", type=int, default=1, help="untimed runs first (default 1)")
    ap.add_argument("--log", default=str(LOG), help="the log (default: the bundled fr079)")
    ap.add_argument("--scans", type=int, default=0, help="only the first N scans (0: all; for quick checks)")
    a = ap.parse_args(argv)

    log = vg.load_log(a.log, overrides={"num_scans": a.scans} if a.scans > 0 else None)
    mapper = vg.Mapper(log.params, backend=a.backend, cuda_mode=a.cuda_mode, threads=a.threads)
    mapper.insert(log.scans)
    original = mapper.poses
    moved = corrected(original)
    for _ in range(max(0, a.warmup)):
        mapper.render(moved)
        mapper.finish()
    times = []
    for r in range(max(1, a.runs)):
        poses = moved if r % 2 else original
        t0 = time.perf_counter()
        mapper.render(poses)
        m = mapper.finish()
        times.append(1000.0 * (time.perf_counter() - t0))
        if m.cells.size == 0:
            print("bench_render: an empty map", file=sys.stderr)
    print(f"bench_render: {Path(a.log).name.split('.')[0]} {mapper.backend} {len(log)} scans: re-render "
          f"(render + finish) median {statistics.median(times):.3f} ms over {len(times)} runs "
          f"(min {min(times):.3f}, max {max(times):.3f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
