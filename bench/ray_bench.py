#!/usr/bin/env python3
"""ray_bench: logs a second through vasco_gpu.map_logs on one host, by executor, in one run:
here (executor=None: one mapper, the logs in order), a pool of spawned processes, and
RayExecutor on a local Ray instance, with a third of a GPU per actor (three mappers) and a
whole GPU per actor (one). Each row's time is the whole `with executor:` block (its workers
or actors started, their first mapper made, every map written to .map.gz), best of --repeat.

    python3 bench/ray_bench.py [--copies 60] [--repeat 2] [--backend cuda] [--cuda-mode exact]

The batch is --copies copies (symbolic links under distinct names) of the bundled fr079.
Without Ray the Ray rows are left out; without a usable CUDA backend, --backend cuda stops
with a message (pass --backend cpu_threads to run the rows on CPUs).
"""
from __future__ import annotations

import argparse
import multiprocessing
import os
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FR079 = os.path.join(ROOT, "logs", "fr079-complete.gfs.log.gz")


def run(paths, backend, cuda_mode, make_executor):
    """Seconds of one batch through map_logs with the executor make_executor() gives (None: here)."""
    import vasco_gpu as vg

    with tempfile.TemporaryDirectory() as out:
        t = time.perf_counter()
        ex = make_executor()
        try:
            results = vg.map_logs(paths, out, backend=backend, executor=ex, cuda_mode=cuda_mode)
        finally:
            if ex is not None:
                ex.shutdown(wait=True)
        seconds = time.perf_counter() - t
    bad = [r for r in results if not r.ok]
    if bad:
        sys.exit(f"ray_bench: {bad[0].path}: {bad[0].error}")
    return seconds


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--copies", type=int, default=60)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--backend", default="cuda")
    ap.add_argument("--cuda-mode", default="exact")
    args = ap.parse_args()
    import vasco_gpu as vg

    cuda_mode = args.cuda_mode if args.backend == "cuda" else None
    if args.backend == "cuda" and not vg.cuda_available():
        sys.exit(f"ray_bench: --backend cuda: {vg.cuda_available().reason}")
    try:
        import ray
        from vasco_gpu.ray_executor import RayExecutor
    except ImportError:
        ray = None
    cores = os.cpu_count() or 1
    rows = [("here (executor=None)", 1, lambda: None),
            ("processes (spawn)", 3, lambda: ProcessPoolExecutor(3, mp_context=multiprocessing.get_context("spawn")))]
    gpu = args.backend == "cuda"
    if ray is not None:
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
        ray.init(address="local", num_cpus=cores, num_gpus=1 if gpu else 0, include_dashboard=False,
                 _node_ip_address="127.0.0.1", log_to_driver=False)
        if gpu:
            rows += [("Ray, num_gpus=1/3", 3, lambda: RayExecutor(num_gpus=1 / 3)),
                     ("Ray, num_gpus=1", 1, lambda: RayExecutor(num_gpus=1))]
        else:
            n = min(3, cores)  # an actor that does not fit would wait for ever: its log with it
            rows += [("Ray, num_cpus=1", n, lambda: RayExecutor(actors=n))]
    with tempfile.TemporaryDirectory() as src:
        paths = []
        for i in range(args.copies):
            p = os.path.join(src, f"c{i:04d}.gfs.log.gz")
            os.symlink(FR079, p)
            paths.append(p)
        mode = f" ({cuda_mode} mode)" if cuda_mode else ""
        print(f"ray_bench: {args.copies} copies of fr079-complete.gfs.log.gz to .map.gz, --backend "
              f"{args.backend}{mode}, {cores} cores, best of {args.repeat}; Ray "
              f"{ray.__version__ if ray else 'not installed'}")
        print(f"{'executor':<24} {'workers':>7} {'s':>8} {'logs/s':>8} {'/ here':>7}")
        here = None
        for name, workers, make in rows:
            s = min(run(paths, args.backend, cuda_mode, make) for _ in range(args.repeat))
            here = here or s
            print(f"{name:<24} {workers:>7} {s:>8.2f} {args.copies / s:>8.1f} {here / s:>6.2f}x", flush=True)
    if ray is not None:
        ray.shutdown()


if __name__ == "__main__":
    main()
