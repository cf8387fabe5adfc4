#!/usr/bin/env python3
"""Large sites through log2map and the ROS 2 node: a synthetic site of --scans scans at 0.05 m whose
grid grows to each of --cells cells, mapped by log2map, re-rendered by a Mapper session, and
loaded into the node, which publishes it on /map and map_updates. Printed as tables, then each
of issue 59's targets met or missed.

The site (mapping_bench --large's layout, bench/large_site.h, made here in NumPy): a robot drives
once around a square loop of 4 m corridor (walls on both sides) filling a site of side x side
metres, starting in a corner, its 180 deg laser (361 beams, pi/360 apart) ray-cast against the
walls, a beam meeting no wall within 50 m reading 50 (out of range). Deterministic: no randomness.
The PROTOCOL frame is centred on the first pose, in the corner, so the grid is about twice the
site a side: side = sqrt(cells) x resolution / 2 - 6 m (the 10 m range_max and its margin). The
finished map (/map) is CARMEN's crop to the known cells: about a quarter of the grid. The scans are
written once per size as a session file (vasco_gpu/ros/session_file.py: a CARMEN log that
log2map maps as it is and the node's load_session restores), resolution 0.05 m, downsample 1
(the map's cell is the grid's), vasco's other defaults; laser mount (0, 0, 0), stamps 25 ms apart.

Steps (every size's site is made first; the sizes are timed in turn where a ratio between them
is the target, so that a drift of a shared machine's speed falls on every size alike):
  log2map       per size: log2map --backend B --max-memory 0 FILE OUT.pgm: its wall time and peak
                resident memory (the child's ru_maxrss, os.wait4); the map phase from its --json
  re-render     one process (another than this) with a Mapper session per size, each inserting
                every scan and rendering once (the session's resident bytes), then --renders rounds
                of every session rendering every scan at moved poses, the sizes in turn (the
                trajectory turned about its first pose by a few mrad, as a loop closure moves it):
                median seconds, Mapper.last_stats()'s cell_updates, ns per cell update; and every
                100th scan rendered in the same frame (the same area, a hundredth of the updates):
                the line through the two renders splits the time into ns per update (the slope)
                and a part that does not grow with the updates (the grid's passes over the area
                reached); the process's peak
  floor         update_floor_bench on the sites' logs, in turn: every used beam's cells walked in
                the log's order, adding 1 a cell over the box they reach, nothing else: the
                linearity target's floor experiment (how much the time per update grows with the
                site when nothing but the updates' memory does)
  node          vasco_map_node (cpu_float here) with load_session:=FILE, max_memory:=0: its first
                /map; then a Path of every pose (moved) -> the re-rendered /map; then --replay
                scans as LaserScan + /tf at 40 Hz -> map_updates. Its resident memory (VmRSS,
                VmHWM, /proc) minus the evidence grid's bytes, per /map cell and per grid cell:
                the grid's bytes measured (the re-render's session: grid, renderer scratch,
                stored scans, resident), and as the renderer's host bytes a cell (4 grid floats,
                + 4 for cpu_float's float sums over the cells reached, host_renderer.h: a bound,
                which its incremental inserts use); the slope of the resident memory between the two
                sizes per cell (the same scans: what grows with the cells only); the bytes of each
                /map and map_updates message's data; a bare node's (no session, once ready): the
                fixed part; and one latched OccupancyGrid of each size's /map cells published by
                a process that does nothing else (large_site_node.latched_floor): with the bare
                node's, the floor printed beside each size's figure; publish -> a subscriber's callback (the
                message's source timestamp, which Fast DDS takes as the publisher writes it, ->
                this process's callback entry, one system clock); the node's largest mappings
                (/proc/PID/smaps: each buffer above glibc's mmap threshold is a mapping of its own),
                named by their size in bytes per grid or /map cell.

Targets (issue 59): re-render time grows linearly with the cell updates: ns per update of the
largest size within 10 % of the smallest's, the median of the rounds' ratios (beside it the floor's growth: above the target, the
target stands missed where the render is within 10 % of the floor); the node holds at most 2 bytes per /map cell beyond the
evidence grid (its resident memory after the Path's /map minus the grid's bytes; and the
slope; where a size's floor is above the target, a figure within 10 % of it stands missed).
Each printed met or missed.

Default for this 2-core CPU machine: --scans 100000 --cells 1e8 4e8 --backends cpu_float (about
7 minutes). GPU rows: --backends cuda_float cuda_exact (log2map and the re-render; the node runs
with --node-backend). ROS processes run on Fast DDS's shared memory in a domain of their own.
  bench/large_site_bench.py [--bin BUILD/bin] [--scans N] [--cells C ...] [--backends B ...]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from large_site_node import latched_floor, proc_bytes, ros_modules, run_bare_node, run_node

ROOT = Path(__file__).resolve().parents[1]
RESOLUTION = 0.05
CORRIDOR = 4.0
BEAMS = 361
LASER_MAX = 50.0
FRAME_MARGIN_M = 6.0  # range_max (10 m) and the frame's margin past the site, per side, at 0.05 m
SCAN_PERIOD_NS = 25_000_000
FIRST_STAMP_NS = 10**12
# The renderer's host bytes per grid cell (RendererTraits::host_bytes_per_cell, host_renderer.h):
# a float grid, and cpu_float's float sums; a grid on a GPU holds none on the host.
HOST_BYTES_PER_CELL = {"cpu_double": 4, "cpu_threads": 4, "cpu_float": 8, "cuda": 0}
LOG2MAP_BACKEND = {"cuda_float": ["--backend", "cuda", "--cuda-mode", "float"],
                   "cuda_exact": ["--backend", "cuda", "--cuda-mode", "exact"]}
MAPPER_BACKEND = {"cuda_float": ("cuda", "float"), "cuda_exact": ("cuda", "exact")}
LINEAR_TOLERANCE = 0.10
SPARSE = 100  # the sparse render's scans: every SPARSE-th
NODE_TARGET_BYTES = 2.0


# -- the site ----------------------------------------------------------------------------------
def site_side(cells: float) -> float:
    """The site's side (m) whose grid has about `cells` cells at RESOLUTION (see the docstring)."""
    return math.sqrt(cells) * RESOLUTION / 2 - FRAME_MARGIN_M


def site_walls(side: float) -> np.ndarray:
    """(8, 4) walls x0, y0, x1, y1: the outer square and the inner one the corridor runs around."""
    a, b, c, d = 0.0, side, CORRIDOR, side - CORRIDOR
    return np.array([[a, a, b, a], [b, a, b, b], [b, b, a, b], [a, b, a, a],
                     [c, c, d, c], [d, c, d, d], [d, d, c, d], [c, d, c, c]])


def site_poses(side: float, n: int) -> np.ndarray:
    """(n, 3) laser poses of one lap, counter-clockwise from (corridor/2, corridor/2)."""
    c, leg = CORRIDOR / 2, side - CORRIDOR
    u = 4 * leg * np.arange(n) / n
    k = np.minimum(3, (u // leg).astype(int))  # which leg
    along = u - k * leg
    x = np.select([k == 0, k == 1, k == 2], [c + along, c + leg, c + leg - along], c)
    y = np.select([k == 0, k == 1, k == 2], [c, c + along, c + leg], c + leg - along)
    return np.stack([x, y, k * np.pi / 2], axis=1)


def cast(walls: np.ndarray, px, py, dx, dy) -> np.ndarray:
    """Distance along (dx, dy) to the nearest wall, LASER_MAX where none is nearer (large_site.h)."""
    best = np.full(dx.shape, LASER_MAX)
    with np.errstate(divide="ignore", invalid="ignore"):
        for x0, y0, x1, y1 in walls:
            if y0 == y1:  # horizontal
                t = (y0 - py) / dy
                q, lo, hi = px + t * dx, min(x0, x1), max(x0, x1)
            else:
                t = (x0 - px) / dx
                q, lo, hi = py + t * dy, min(y0, y1), max(y0, y1)
            best = np.where((t > 0) & (t < best) & (q >= lo) & (q <= hi), t, best)
    return best


def site_scans(side: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The lap's poses (n, 3) and ranges (n, BEAMS) float32, in chunks of 4096 scans."""
    poses, walls = site_poses(side, n), site_walls(side)
    step, ranges = math.pi / (BEAMS - 1), np.empty((n, BEAMS), np.float32)
    for s in range(0, n, 4096):
        p = poses[s:s + 4096]
        a = p[:, 2:3] - math.pi / 2 + np.arange(BEAMS) * step
        ranges[s:s + 4096] = cast(walls, p[:, :1], p[:, 1:2], np.cos(a), np.sin(a))
    return poses, ranges


def site_params():
    import vasco_gpu as vg

    values = vg.Params().to_dict()
    values.update(resolution=RESOLUTION, downsample=1)
    return vg.Params(**values)


def write_site(directory: Path, cells: float, n: int):
    """The site for `cells` as a session file and an .npz of its arrays; (file, npz, SavedSession, side)."""
    from vasco_gpu.ros.session_file import SavedSession, write_session

    side = site_side(cells)
    poses, ranges = site_scans(side, n)
    saved = SavedSession(stamps=FIRST_STAMP_NS + np.arange(n, dtype=np.int64) * SCAN_PERIOD_NS, poses=poses,
                         mounts=np.zeros((n, 3)), first_angle=np.full(n, -math.pi / 2),
                         angle_step=np.full(n, math.pi / (BEAMS - 1)), beam_counts=np.full(n, BEAMS, np.int64),
                         ranges=ranges.ravel(), params=site_params(),
                         options={"backend": "cpu_float", "cuda_mode": "float", "device": 0, "threads": 0,
                                  "max_memory": 0})
    path = directory / f"site-{cells:.0e}.session.log"
    write_session(saved, path)
    npz = directory / f"site-{cells:.0e}.npz"
    np.savez(npz, poses=poses, ranges=ranges)
    return path, npz, saved, side


def moved(poses: np.ndarray, k: int) -> np.ndarray:
    """The trajectory turned about its first pose by 2 (k + 1) mrad: a loop closure's move."""
    a = 0.002 * (k + 1)
    c, s = math.cos(a), math.sin(a)
    out = poses.copy()
    dx, dy = poses[:, 0] - poses[0, 0], poses[:, 1] - poses[0, 1]
    out[:, 0], out[:, 1] = poses[0, 0] + c * dx - s * dy, poses[0, 1] + s * dx + c * dy
    out[:, 2] += a
    return out


# -- log2map and the re-render ----------------------------------------------------------------
def run_log2map(binary: Path, site: Path, backend: str, workdir: Path) -> dict:
    """log2map's wall time, its peak resident memory (os.wait4's ru_maxrss) and --json's figures."""
    out = workdir / "site.pgm"
    args = [str(binary), *LOG2MAP_BACKEND.get(backend, ["--backend", backend]), "--max-memory", "0", "--json",
            str(site), str(out)]
    with tempfile.TemporaryFile() as stdout, tempfile.TemporaryFile() as stderr:
        t0 = time.monotonic()
        proc = subprocess.Popen(args, stdout=stdout, stderr=stderr)
        _, status, usage = os.wait4(proc.pid, 0)  # this child's own rusage (ru_maxrss: its peak)
        seconds = time.monotonic() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        stdout.seek(0), stderr.seek(0)
        out_text, err_text = stdout.read().decode(errors="replace"), stderr.read().decode(errors="replace")
    out.unlink(missing_ok=True)
    if proc.returncode != 0:
        return {"error": (err_text.strip().splitlines() or ["failed"])[-1]}
    return {"seconds": seconds, "peak": usage.ru_maxrss * 1024.0, "json": json.loads(out_text or "{}")}


def run_floor(binary: Path, sites: list) -> list:
    """update_floor_bench on the sites' logs, walked in turn run after run: the same beams' cells
    walked in the log's order, adding 1 a cell and nothing else (its JSON a site), or why not."""
    if not binary.exists():
        return [{"error": f"{binary} not built (make benchmarks)"}] * len(sites)
    proc = subprocess.run([str(binary), *map(str, sites), "--runs", "3"], capture_output=True, text=True)
    if proc.returncode != 0:
        return [{"error": (proc.stderr.strip().splitlines() or ["failed"])[-1]}] * len(sites)
    return [json.loads(line) for line in proc.stdout.strip().splitlines()]


def render_child(npzs: list, backend: str, renders: int) -> dict:
    """In its own process (--render-child): a Mapper session per site, each inserting every scan
    and rendering once at moved poses (its resident bytes: VmRSS then, less before it was made:
    the grid, the renderer's scratch, the stored scans); then `renders` rounds, each re-rendering
    every site's session once at poses moved further (the trajectory turned about its first pose
    by a few mrad more each round, as a loop closure moves it: the frame grows by a few cells a
    render), the sites in turn, so that a drift of the machine's speed over the run
    falls on every size alike; then the same with every SPARSE-th scan in each session's frame (the
    same area reached, a hundredth of the updates), which splits a render's time into a part per
    cell update and a part that does not grow with them."""
    import vasco_gpu as vg

    name, mode = MAPPER_BACKEND.get(backend, (backend, None))
    sites = []
    for npz in npzs:
        data = np.load(npz)
        poses, ranges = data["poses"], data["ranges"]
        before = proc_bytes("self", "VmRSS")
        m = vg.Mapper(site_params(), backend=name, cuda_mode=mode, max_memory_bytes=0, expected_renders=renders + 1)
        t0 = time.perf_counter()
        m.insert(scans_of(poses, ranges))
        insert_s = time.perf_counter() - t0
        m.render(moved(poses, 0))  # untimed: every buffer a render uses resident before the bytes are read
        frame = m.frame
        sites.append({"mapper": m, "poses": poses, "ranges": ranges, "out": {
            "insert_s": insert_s, "render_s": [], "cells": frame.size_x * frame.size_y,
            "grid": [frame.size_x, frame.size_y], "session_rss": proc_bytes("self", "VmRSS") - before}})
    del m  # the sessions are the sites' alone
    # Each round turns the trajectory further (2 mrad for the untimed render, then 4, 6, ...), as
    # a loop closure moves it: the frame grows by a few cells a render, as it does in use.
    for k in range(1, renders + 1):
        for site in sites:
            site["out"]["render_s"].append(timed_render(site["mapper"], moved(site["poses"], k)))
            stats = site["mapper"].last_stats
            site["out"].update(updates=stats["cell_updates"], map_s=stats["map_s"])
            site["out"].setdefault("updates_each", []).append(stats["cell_updates"])
    frames = [site.pop("mapper").frame for site in sites]  # the full sessions freed before the sparse ones
    for site, frame in zip(sites, frames):
        site["sparse"] = vg.Mapper(site_params(), backend=name, cuda_mode=mode, max_memory_bytes=0, frame=frame,
                                   frame_centre=(frame.x0, frame.y0))
        site["sparse"].insert(scans_of(site["poses"][::SPARSE], site["ranges"][::SPARSE]))
        site["sparse"].render(moved(site["poses"][::SPARSE], 0))  # untimed, as the full sessions' first
        site["out"]["sparse_s"] = []
    for k in range(1, renders + 1):
        for site in sites:
            site["out"]["sparse_s"].append(timed_render(site["sparse"], moved(site["poses"][::SPARSE], k)))
    for site in sites:
        site["out"]["sparse_updates"] = site["sparse"].last_stats["cell_updates"]
        site["out"]["sparse_s"] = float(np.median(site["out"]["sparse_s"]))
    return {"sites": [site["out"] for site in sites], "peak": proc_bytes("self", "VmHWM")}


def scans_of(poses: np.ndarray, ranges: np.ndarray):
    import vasco_gpu as vg

    return vg.Scans(poses, ranges.ravel(), np.full(len(poses), BEAMS), -math.pi / 2, math.pi / (BEAMS - 1))


def timed_render(mapper, poses: np.ndarray) -> float:
    t0 = time.perf_counter()
    mapper.render(poses)
    return time.perf_counter() - t0


def per_update(m: dict) -> tuple[float, float]:
    """(seconds per cell update, seconds that do not grow with the updates) of a size's renders:
    the line through the full render and the sparse one."""
    full = float(np.median(m["render_s"]))
    slope = (full - m["sparse_s"]) / (m["updates"] - m["sparse_updates"])
    return slope, full - slope * m["updates"]


def run_renders(npzs: list, backend: str, renders: int) -> dict:
    """render_child's figures: {"sites": one dict a site, "peak": the process's VmHWM}, or an error."""
    args = [sys.executable, __file__, "--render-child", backend, str(renders), *map(str, npzs)]
    done = subprocess.run(args, capture_output=True, text=True)
    if done.returncode != 0:
        return {"error": (done.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(done.stdout.strip().splitlines()[-1])


# -- the printout ------------------------------------------------------------------------------
def mb(b: float) -> str:
    return "-" if b is None or b < 0 else f"{b / 1e6:,.0f} MB"


def print_tools(rows: list) -> None:
    print("\nlog2map and the re-render (a Mapper session): seconds; ns per cell update of the median render; the")
    print("line through it and the sparse render (every 100th scan, same frame): ns/upd slope, and the seconds that")
    print("do not grow with the updates (rest s); session: the Mapper's resident bytes. The sizes' sessions")
    print("re-render in one process, in turn (the render columns are of one time); log2map's peak is its own")
    head = (f"{'cells':>8} {'backend':<11} {'grid':>13} {'log2map s':>9} {'map s':>6} {'peak':>9} {'insert s':>8} "
            f"{'render s':>8} {'updates':>14} {'ns/upd':>7} {'sparse s':>8} {'ns/upd slope':>12} {'rest s':>6} "
            f"{'session':>9}")
    print(head + "\n" + "-" * len(head))
    for r in rows:
        l, m = r["log2map"], r["render"]
        if "error" in l or "error" in m:
            print(f"{r['target']:>8.0e} {r['backend']:<11} error: {l.get('error') or m.get('error')}")
            continue
        med, (slope, rest) = float(np.median(m["render_s"])), per_update(m)
        print(f"{r['target']:>8.0e} {r['backend']:<11} {m['grid'][0]:>6}x{m['grid'][1]:<6} {l['seconds']:>9.2f} "
              f"{l['json']['seconds']['map']:>6.2f} {mb(l['peak']):>9} {m['insert_s']:>8.2f} {med:>8.2f} "
              f"{m['updates']:>14,} {med / m['updates'] * 1e9:>7.3f} {m['sparse_s']:>8.3f} {slope * 1e9:>12.3f} "
              f"{rest:>6.2f} {mb(m['session_rss']):>9}")
    peaks = {r["backend"]: r["render_peak"] for r in rows if r.get("render_peak") is not None}
    for backend, peak in peaks.items():
        print(f"#   the re-render process's peak ({backend}, every size's session in it): {mb(peak)}")


def beyond_grid(mem: dict, row: dict, key: str = "VmRSS") -> float:
    """The node's resident bytes beyond the evidence grid: less the re-render session's own."""
    return mem[key] - row["render"]["session_rss"]


def beyond_traits(mem: dict, backend: str, grid_cells: int) -> float:
    name = MAPPER_BACKEND.get(backend, (backend,))[0]
    return mem["VmRSS"] - HOST_BYTES_PER_CELL[name] * grid_cells


def print_node(rows: list, backend: str) -> None:
    per = HOST_BYTES_PER_CELL[MAPPER_BACKEND.get(backend, (backend,))[0]]
    print(f"\nThe node ({backend}, load_session): VmRSS after the Path's /map, VmHWM the peak over the run; beyond = "
          f"VmRSS less the re-render session's resident bytes\n(grid, sums, stored scans), per /map and per grid cell; "
          f"traits: VmRSS less {per} bytes a grid cell; peak: VmHWM less the session; /map and map_updates:\n"
          "data bytes a message, publish -> subscriber callback (ms; the first /map's includes discovery of the latched topic)")
    head = (f"{'cells':>8} {'/map cells':>11} {'load s':>7} {'VmRSS':>9} {'VmHWM':>9} {'beyond':>9} {'B/map cell':>10} "
            f"{'B/grid cell':>11} {'traits B/map':>12} {'peak B/map':>10} {'first ms':>9} {'Path->/map ms':>13} "
            f"{'wire ms':>8} {'updates':>7} {'upd bytes p50/max':>18} {'upd wire p50/p99 ms':>20}")
    print(head + "\n" + "-" * len(head))
    for r in rows:
        n = r["node"]
        if "error" in n or "error" in n.get("path", {}):
            print(f"{r['target']:>8.0e} error: {n.get('error') or n['path']['error']}")
            continue
        mem, cells, grid = n["mem_path"], n["path"]["bytes"], r["render"]["cells"]
        extra, hwm = beyond_grid(mem, r), beyond_grid(n["mem_end"], r, "VmHWM")
        u = n["updates"]
        ub, uw = np.array([e[2] for e in u], dtype=float), np.array([e[3] for e in u], dtype=float) / 1e6
        upd = f"{np.median(ub):,.0f}/{ub.max():,.0f}" if len(u) else "-"
        wire = f"{np.median(uw):.2f}/{np.percentile(uw, 99):.2f}" if len(u) else "-"
        print(f"{r['target']:>8.0e} {cells:>11,} {n['load_s']:>7.1f} {mb(mem['VmRSS']):>9} "
              f"{mb(n['mem_end']['VmHWM']):>9} {mb(extra):>9} {extra / cells:>10.2f} {extra / grid:>11.2f} "
              f"{beyond_traits(mem, backend, grid) / cells:>12.2f} {hwm / cells:>10.2f} {n['first'][3] / 1e6:>9.1f} "
              f"{n['path']['path_ms']:>13.1f} {n['path']['wire_ms']:>8.1f} {len(u):>7} {upd:>18} {wire:>20}")
    for r in rows:
        n = r["node"]
        if "mem_path" not in n:
            continue
        grid, cells, m = r["render"]["cells"], n["path"]["bytes"], n["mem_path"]
        parts = ", ".join(f"{mb(rss)} ({rss / grid:.2f} B/grid cell, {rss / cells:.2f} B/map cell)"
                          for size, rss, name in m["mappings"][:6])
        print(f"#   {r['target']:.0e}: RssAnon {mb(m['RssAnon'])}, RssFile {mb(m['RssFile'])}, RssShmem "
              f"{mb(m['RssShmem'])}; the re-render session {mb(r['render']['session_rss'])}; largest resident mappings "
              f"(adjacent anonymous ones merge): {parts}")
        print(f"#   {r['target']:.0e}: the node's summary: {n.get('summary', '-')}")


def slope(rows: list):
    """(bytes per /map cell, per grid cell) of the node's resident memory beyond the grid between the
    smallest and the largest size: the same scans, so what grows with the cells alone."""
    ok = [r for r in rows if "mem_path" in r["node"]]
    if len(ok) < 2:
        return None
    a, b = ok[0], ok[-1]
    extra = [beyond_grid(r["node"]["mem_path"], r) for r in (a, b)]
    d_map = b["node"]["path"]["bytes"] - a["node"]["path"]["bytes"]
    d_grid = b["render"]["cells"] - a["render"]["cells"]
    return (extra[1] - extra[0]) / d_map, (extra[1] - extra[0]) / d_grid


def print_floor(rows: list, ratio: float) -> None:
    """The linearity target's floor experiment: how much update_floor_bench's time per update grows
    from the smallest site to the largest. A render updates the same cells in the same order and
    does more per update, none of it growing with the site, so a growth of the floor above the target
    is one no such render can go below; a floor that does not grow says the render's growth is its own."""
    floors = [r.get("floor", {}) for r in (rows[0], rows[-1])]
    if any("ns_per_update" not in f for f in floors):
        why = next((f.get("error", "not run") for f in floors if "ns_per_update" not in f), "not run")
        print(f"    floor: not measured ({why})")
        return
    f0, f1 = (f["ns_per_update"] for f in floors)
    floor_ratio = f1 / f0
    if floor_ratio > 1 + LINEAR_TOLERANCE:
        within = ratio <= floor_ratio * (1 + LINEAR_TOLERANCE)
        verdict = (f"above the target; the render within {LINEAR_TOLERANCE:.0%} of it: the target stands missed"
                   if within else f"above the target, but the render is more than {LINEAR_TOLERANCE:.0%} above it")
    elif ratio <= 1 + LINEAR_TOLERANCE:
        verdict = "within the target, as the render is"
    else:
        verdict = "within the target: a render's growth past it is its own (no floor excuses the miss)"
    print(f"    floor (update_floor_bench: the same beams' cells walked in the log's order, adding 1 a cell, "
          f"nothing else): ns per update {f0:.3f} and {f1:.3f} (updates {floors[0]['updates']:.3g} and "
          f"{floors[1]['updates']:.3g}): ratio {floor_ratio:.3f}, {verdict}")


def round_ratios(a: dict, z: dict) -> list:
    """Each round's ns per update at the largest size over the smallest's: a round renders the sizes
    one after the other, so a drift of the machine's speed between rounds cancels in its ratio
    (it would not in a ratio of the sizes' medians, each of other rounds)."""
    return [(tz / nz) / (ta / na)
            for ta, na, tz, nz in zip(a["render_s"], a["updates_each"], z["render_s"], z["updates_each"])]


def print_targets(rows: list, backends: list, node_backend: str | None) -> None:
    print("\nTargets")
    for b in backends:
        done = [r["render"] for r in rows if r["backend"] == b and "updates" in r["render"]]
        if len(done) < 2:
            print(f"  re-render linear in cell updates ({b}): not measured (two sizes needed)")
            continue
        a, z = done[0], done[-1]
        per = [float(np.median(m["render_s"])) / m["updates"] for m in (a, z)]
        slopes = [per_update(m)[0] for m in (a, z)]
        rounds = round_ratios(a, z)
        ratio = float(np.median(rounds))
        verdict = "met" if abs(ratio - 1) <= LINEAR_TOLERANCE else "MISSED"
        print(f"  re-render linear in cell updates ({b}): ns per update {per[0] * 1e9:.3f} at {a['cells']:.3g} cells, "
              f"{per[1] * 1e9:.3f} at {z['cells']:.3g} cells (medians; updates {a['updates']:.3g} and {z['updates']:.3g}): "
              f"ratio {ratio:.3f}, the median of the rounds' ({' '.join(f'{r:.3f}' for r in rounds)}) "
              f"(linear: 1; target within {LINEAR_TOLERANCE:.0%}): {verdict}; the per-update slope "
              f"alone (the sparse render's line) {slopes[0] * 1e9:.3f} and {slopes[1] * 1e9:.3f} ns: ratio "
              f"{slopes[1] / slopes[0]:.3f}")
        print_floor([r for r in rows if r["backend"] == b], ratio)
    if node_backend is None:
        return
    node_rows = [r for r in rows if r["backend"] == backends[0] and "mem_path" in r["node"]]
    bare_node = node_rows[0]["node"].get("bare", {}) if node_rows else {}
    bare = bare_node.get("VmRSS", -1)
    if "error" in bare_node:
        print(f"  a bare node (no session): error: {bare_node['error']}")
    for r in node_rows:
        extra, cells, grid = beyond_grid(r["node"]["mem_path"], r), r["node"]["path"]["bytes"], r["render"]["cells"]
        latched = r["node"].get("latched", {}).get("latched", -1)
        floor = bare + latched if bare > 0 and latched > 0 else None
        print(f"  node beyond the evidence grid ({node_backend}, {r['target']:.0e} cells): {extra / cells:.2f} bytes per /map "
              f"cell, {extra / grid:.2f} per grid cell (target <= {NODE_TARGET_BYTES:g} per /map cell): "
              f"{node_verdict(extra / cells, None if floor is None else floor / cells)}")
        if floor is None:
            print(f"    floor: not measured ({r['node'].get('latched', {}).get('error', 'no bare node')})")
            continue
        print(f"    floor: a bare node's own ({mb(bare)}, no session) and one latched /map of its cells ({mb(latched)}: "
              f"a process publishing nothing else, large_site_node.latched_floor): {floor / cells:.2f} per /map cell; "
              f"the node less the bare node's: {(extra - bare) / cells:.2f} per /map cell, {(extra - bare) / grid:.2f} "
              "per grid cell")
    s = slope(node_rows)
    if s is not None:
        verdict = node_verdict(s[0], None)
        print(f"  node beyond the evidence grid, slope between the sizes (the fixed costs, scans and interpreter, "
              f"cancel): {s[0]:.2f} bytes per /map cell, {s[1]:.2f} per grid cell: {verdict}")


def node_verdict(per_cell: float, floor: float | None) -> str:
    """The node target's verdict: met at most NODE_TARGET_BYTES a /map cell; where the floor
    (bytes a /map cell no node that latches /map goes below) is above it, a figure within
    LINEAR_TOLERANCE of the floor stands missed."""
    if per_cell <= NODE_TARGET_BYTES:
        return "met"
    if floor is not None and floor > NODE_TARGET_BYTES and per_cell <= floor * (1 + LINEAR_TOLERANCE):
        return (f"the floor ({floor:.2f}) is above the target and the node within {LINEAR_TOLERANCE:.0%} of it "
                f"({per_cell / floor - 1:+.1%}): stands missed")
    return "MISSED"


def bench_sites(args, workdir: Path, modules) -> list:
    """Every size's site made, then log2map on each; the re-renders and the floor of every size in
    one process each (the sizes in turn); the node on each; one row a (size, backend)."""
    t0 = time.monotonic()
    sites = []
    for target in args.cells:
        site, npz, saved, side = write_site(workdir, target, args.scans)
        print(f"# {target:.0e} cells: a {side:.1f} m site, {args.scans} scans, session file "
              f"{site.stat().st_size / 1e6:.0f} MB, made in {time.monotonic() - t0:.1f} s", flush=True)
        sites.append((target, site, npz, saved))
    rows = {}
    for target, site, _, _ in sites:
        for b in args.backends:
            rows[target, b] = {"target": target, "backend": b, "node": {},
                               "log2map": run_log2map(args.bin / "log2map", site, b, workdir)}
        print(f"#   {target:.0e}: log2map done ({time.monotonic() - t0:.0f} s)", flush=True)
    for b in args.backends:
        renders = run_renders([npz for _, _, npz, _ in sites], b, args.renders)
        for i, (target, _, _, _) in enumerate(sites):
            rows[target, b]["render"] = renders["sites"][i] if "sites" in renders else renders
            rows[target, b]["render_peak"] = renders.get("peak")
        print(f"#   {b}: the re-renders, the sizes in turn, done ({time.monotonic() - t0:.0f} s)", flush=True)
    floors = run_floor(args.bin / "update_floor_bench", [site for _, site, _, _ in sites])
    print(f"#   the updates' floor, the sizes in turn, done ({time.monotonic() - t0:.0f} s)", flush=True)
    for (target, _, _, _), floor in zip(sites, floors):
        for b in args.backends:
            rows[target, b]["floor"] = floor
    backend = MAPPER_BACKEND.get(args.node_backend, (args.node_backend, "float"))
    bare = run_bare_node(modules, backend) if modules is not None else {}
    for target, site, npz, saved in sites:
        if modules is not None:
            node = run_node(modules, site, saved, moved(saved.poses, 0), backend, args.replay)
            node["bare"] = bare
            if "bytes" in node.get("path", {}):
                node["latched"] = latched_floor(modules, node["path"]["bytes"])
            rows[target, args.backends[0]]["node"] = node
            print(f"#   {target:.0e}: node ({args.node_backend}) done ({time.monotonic() - t0:.0f} s)", flush=True)
        site.unlink()
        npz.unlink()
    return [rows[target, b] for target in args.cells for b in args.backends]


def main() -> int:
    if len(sys.argv) >= 5 and sys.argv[1] == "--render-child":
        print(json.dumps(render_child(sys.argv[4:], sys.argv[2], int(sys.argv[3]))))
        return 0
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", type=Path, default=ROOT / "build" / "bin", help="where log2map is")
    ap.add_argument("--scans", type=int, default=100_000)
    ap.add_argument("--cells", type=float, nargs="+", default=[1e8, 4e8], help="the grid's cells, about (one site each)")
    ap.add_argument("--backends", nargs="+", default=["cpu_float"],
                    help="log2map's and the re-render's: cpu_double, cpu_threads, cpu_float, cuda_float, cuda_exact")
    ap.add_argument("--node-backend", default="cpu_float", help="the node's backend (as --backends); none: no node")
    ap.add_argument("--renders", type=int, default=5,
                    help="rounds of re-renders, the sizes in turn (the medians are printed, the target's ratio the rounds')")
    ap.add_argument("--replay", type=int, default=200, help="scans sent to the node as LaserScan for map_updates")
    ap.add_argument("--workdir", type=Path, default=None, help="for the site files (default: a temporary folder)")
    args = ap.parse_args()
    node = None if args.node_backend == "none" else args.node_backend
    print(f"# large_site_bench: {os.cpu_count()} cores, "
          f"{os.sysconf('SC_PHYS_PAGES') * os.sysconf('SC_PAGE_SIZE') / 2**30:.0f} GiB, {platform.processor() or platform.machine()}; "
          f"--scans {args.scans} --cells {' '.join(f'{c:.0e}' for c in args.cells)} --backends {' '.join(args.backends)} "
          f"--node-backend {args.node_backend} --renders {args.renders} --replay {args.replay}", flush=True)
    modules = ros_modules() if node else None
    if modules:
        modules[1].init()
    rows = []
    try:
        with tempfile.TemporaryDirectory(dir=args.workdir) as tmp:
            rows = bench_sites(args, Path(tmp), modules)
    finally:
        if modules:
            modules[1].try_shutdown()
    print_tools(rows)
    if node:
        print_node([r for r in rows if r["backend"] == args.backends[0]], node)
    print_targets(rows, args.backends, node)
    return 0


if __name__ == "__main__":
    sys.exit(main())
