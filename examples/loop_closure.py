#!/usr/bin/env python3
"""Re-rendering a map after a loop closure, from Python.

Loads the bundled Freiburg 079 log, whose poses are already corrected by a SLAM
back end (GMapping), and plays the story backwards: the poses are perturbed as
a drifting odometry would perturb them (a heading bias per metre travelled and a
small scale error, accumulated along the trajectory), mapped, and then a loop
closure "arrives": every pose is replaced by the corrected one and the whole map
is rendered again from the scans the session already holds. Writes
``before.png`` and ``after.png`` and ``before_after.png`` (the two side by
side, labelled "before" and "after") and prints the time of each step.

With ``--gtsam`` (and ``pip install gtsam``) the corrected poses come from a
GTSAM pose graph instead: the drifting odometry as between-factors plus
loop-closure factors between scans that the log's poses put close together.

    python examples/loop_closure.py                       # best backend here
    python examples/loop_closure.py --backend cuda --cuda-mode exact
    python examples/loop_closure.py --scans 500 --out /tmp/lc
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import vasco_gpu as vg

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_LOG = ROOT / "logs" / "fr079-complete.gfs.log.gz"


def drift(poses: np.ndarray, heading_bias: float, scale_error: float) -> np.ndarray:
    """What a drifting odometry reports for a trajectory: each step's motion, in the robot's
    frame, with a heading error of ``heading_bias`` radians per metre travelled and the
    distance off by ``scale_error``, composed from the first pose on."""
    out = np.empty_like(poses)
    out[0] = poses[0]
    for i in range(1, len(poses)):
        x0, y0, t0 = poses[i - 1]
        x1, y1, t1 = poses[i]
        c, s = math.cos(t0), math.sin(t0)
        dx, dy = c * (x1 - x0) + s * (y1 - y0), -s * (x1 - x0) + c * (y1 - y0)
        dt = math.atan2(math.sin(t1 - t0), math.cos(t1 - t0))
        dist = math.hypot(dx, dy)
        dx, dy, dt = dx * (1 + scale_error), dy * (1 + scale_error), dt + heading_bias * dist
        px, py, pt = out[i - 1]
        c, s = math.cos(pt), math.sin(pt)
        out[i] = (px + c * dx - s * dy, py + s * dx + c * dy, pt + dt)
    return out


def gtsam_correct(odometry: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Optional: corrected poses from a GTSAM pose graph (odometry between-factors, loop
    closures where the reference poses of scans far apart in time are within 1 m)."""
    import gtsam  # noqa: PLC0415 (optional dependency)

    def rel(a, b):
        return gtsam.Pose2(*a).between(gtsam.Pose2(*b))

    graph = gtsam.NonlinearFactorGraph()
    odo_noise = gtsam.noiseModel.Diagonal.Sigmas(np.array([0.05, 0.05, 0.02]))
    loop_noise = gtsam.noiseModel.Diagonal.Sigmas(np.array([0.02, 0.02, 0.01]))
    graph.add(gtsam.PriorFactorPose2(0, gtsam.Pose2(*odometry[0]), gtsam.noiseModel.Diagonal.Sigmas(np.full(3, 1e-6))))
    initial = gtsam.Values()
    for i in range(len(odometry)):
        initial.insert(i, gtsam.Pose2(*odometry[i]))
        if i:
            graph.add(gtsam.BetweenFactorPose2(i - 1, i, rel(odometry[i - 1], odometry[i]), odo_noise))
    step = max(1, len(reference) // 400)
    for i in range(0, len(reference), step):
        for j in range(i + 200, len(reference), step):
            if np.hypot(*(reference[i, :2] - reference[j, :2])) < 1.0:
                graph.add(gtsam.BetweenFactorPose2(i, j, rel(reference[i], reference[j]), loop_noise))
    result = gtsam.LevenbergMarquardtOptimizer(graph, initial).optimize()
    return np.array([[result.atPose2(i).x(), result.atPose2(i).y(), result.atPose2(i).theta()]
                     for i in range(len(odometry))])


# A 5 x 7 bitmap font ('#' ink, top row first), the letters of the two labels.
GLYPHS = {
    "A": (".###.", "#...#", "#...#", "#####", "#...#", "#...#", "#...#"),
    "B": ("####.", "#...#", "#...#", "####.", "#...#", "#...#", "####."),
    "E": ("#####", "#....", "#....", "####.", "#....", "#....", "#####"),
    "F": ("#####", "#....", "#....", "####.", "#....", "#....", "#...."),
    "O": (".###.", "#...#", "#...#", "#...#", "#...#", "#...#", ".###."),
    "R": ("####.", "#...#", "#...#", "####.", "#.#..", "#..#.", "#...#"),
    "T": ("#####", "..#..", "..#..", "..#..", "..#..", "..#..", "..#.."),
}


def label(text: str, width: int, scale: int) -> np.ndarray:
    """A strip of cells ``width`` wide: ``text`` in occupied cells (black) on free ones (white),
    each font pixel ``scale`` x ``scale`` cells; indexed [x, y] with y up, as Map.cells."""
    h = 9 * scale
    strip = np.zeros((width, h), dtype=np.float32)
    for i, ch in enumerate(text):
        for r, row in enumerate(GLYPHS[ch]):
            for c, px in enumerate(row):
                if px == "#":
                    x0, y1 = scale * (1 + 6 * i + c), h - scale * (1 + r)
                    strip[x0 : x0 + scale, y1 - scale : y1] = 1.0
    return strip


def side_by_side(a: vg.Map, b: vg.Map) -> vg.Map:
    """One map holding a and b next to each other (as images: a left, b right), labelled
    "BEFORE" and "AFTER" above them, a black column between them, unknown where one is
    shorter."""
    scale = max(1, min(a.size_x, b.size_x) // 100)
    top = 9 * scale
    h = max(a.size_y, b.size_y) + top
    gap = 4
    cells = np.full((a.size_x + gap + b.size_x, h), -1.0, dtype=np.float32)
    cells[: a.size_x, : a.size_y] = a.cells
    cells[: a.size_x, h - top :] = label("BEFORE", a.size_x, scale)
    cells[a.size_x : a.size_x + gap, :] = 1.0
    cells[a.size_x + gap :, : b.size_y] = b.cells
    cells[a.size_x + gap :, h - top :] = label("AFTER", b.size_x, scale)
    return vg.Map(cells, a.resolution)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--log", default=str(DEFAULT_LOG), help="CARMEN log (default: the bundled fr079)")
    ap.add_argument("--backend", default="auto", help="cpu_double, cpu_threads, cpu_float, cuda, auto (default)")
    ap.add_argument("--cuda-mode", default=None, choices=["float", "exact"])
    ap.add_argument("--scans", type=int, default=0, help="map only the first N scans (0: all)")
    ap.add_argument("--heading-bias", type=float, default=0.004, help="odometry heading error, rad per metre")
    ap.add_argument("--scale-error", type=float, default=0.01, help="odometry distance error (fraction)")
    ap.add_argument("--runs", type=int, default=5, help="timed re-renders (median printed)")
    ap.add_argument("--gtsam", action="store_true", help="correct the poses with a GTSAM pose graph")
    ap.add_argument("--out", default=".", help="directory for the PNGs")
    a = ap.parse_args(argv)

    t = time.perf_counter()
    overrides = {"num_scans": a.scans} if a.scans > 0 else None
    log = vg.load_log(a.log, overrides=overrides)
    print(f"loaded {len(log)} scans, {log.scans.num_beams} beams from {os.path.basename(a.log)} "
          f"in {1000 * (time.perf_counter() - t):.0f} ms")

    corrected = log.poses  # the SLAM back end's poses, as the log carries them
    odometry = drift(corrected, a.heading_bias, a.scale_error)
    if a.gtsam:
        try:
            corrected = gtsam_correct(odometry, log.poses)
            print("poses corrected by GTSAM")
        except ImportError:
            print("--gtsam: GTSAM is not installed (pip install gtsam); using the log's poses", file=sys.stderr)
    err = np.hypot(*(odometry[:, :2] - corrected[:, :2]).T)
    print(f"odometry drift: {err.mean():.2f} m on average, {err.max():.2f} m at most")

    s = log.scans
    drifted = vg.Scans(odometry, s.ranges, s.beam_counts, s.first_angle, s.angle_step)
    mapper = vg.Mapper(log.params, backend=a.backend, cuda_mode=a.cuda_mode)
    t = time.perf_counter()
    mapper.insert(drifted)
    before = mapper.finish()
    print(f"backend {mapper.backend}: drifting map (insert + finish) in {1000 * (time.perf_counter() - t):.1f} ms")

    # The loop closure: every pose moves; the session re-renders from the scans it holds.
    times = []
    for r in range(max(1, a.runs) + 1):
        poses = corrected if r % 2 == 0 else odometry
        t = time.perf_counter()
        mapper.render(poses)
        m = mapper.finish()
        times.append(1000 * (time.perf_counter() - t))
        if r % 2 == 0:
            after = m
    timed = times[1:] if len(times) > 1 else times  # the first is a warm-up
    print(f"re-render after the loop closure (render + finish): {times[0]:.1f} ms first, "
          f"median {statistics.median(timed):.1f} ms over {len(timed)} runs")

    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    vg.write_map(out / "before.png", before)
    vg.write_map(out / "after.png", after)
    vg.write_map(out / "before_after.png", side_by_side(before, after))
    cmp = vg.compare(after, before)
    print(f"before vs after: {100 * cmp.class_agreement:.2f} % of cells in the same class")
    print(f"wrote {out / 'before.png'}, {out / 'after.png'}, {out / 'before_after.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
