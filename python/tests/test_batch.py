"""map_logs: many logs to files, in this process, through a Dask cluster and a process pool;
the maps are log2map's, a failed log is reported and leaves nothing behind; and
Mapper.start_over, which lets one mapper serve many logs."""

from __future__ import annotations

import errno
import multiprocessing
import os
import shutil
import subprocess
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import vasco_gpu as vg
from conftest import GOLDEN, ROOT, cuda_or_skip

INTEL = ROOT / "logs" / "intel.gfs.log.gz"
FR079 = ROOT / "logs" / "fr079-complete.gfs.log.gz"


def _find_log2map():
    """log2map of a build of this checkout: $VASCO_LOG2MAP, else the newest build*/bin/log2map."""
    if os.environ.get("VASCO_LOG2MAP"):
        return os.environ["VASCO_LOG2MAP"]
    found = [p for p in ROOT.glob("build*/bin/log2map") if os.access(p, os.X_OK)]
    return str(max(found, key=lambda p: p.stat().st_mtime)) if found else None


LOG2MAP = _find_log2map()
_REFERENCES = {}


def _golden(log):
    """The golden digest of a bundled log with vasco's defaults (what log2map writes for it)."""
    name = Path(log).name[: -len(".log.gz")] + "__vasco_default_ds4"
    for line in (GOLDEN / "SHA256SUMS").read_text().splitlines():
        if line.strip() and not line.startswith("#") and line.split()[1] == name:
            return line.split()[0]
    raise KeyError(name)


def reference(log, backend, tmp_path):
    """The GRIDMAP digest of one log2map run of ``log`` (a bundled one) with ``backend``; the
    golden digest where no log2map was built (it is what log2map writes: `make golden`)."""
    key = (Path(log).name, backend)
    if key not in _REFERENCES:
        if LOG2MAP is None:
            _REFERENCES[key] = _golden(log)
        else:
            out = tmp_path / f"log2map-{backend}.map.gz"
            subprocess.run([LOG2MAP, "--backend", backend, "--quiet", str(log), str(out)], check=True, timeout=120)
            _REFERENCES[key] = vg.gridmap_sha256(vg.read_map(out))
    return _REFERENCES[key]


def _copies(folder, *pairs):
    """Copies of bundled logs under new names: pairs of (source, name); their paths."""
    folder.mkdir(exist_ok=True)
    paths = []
    for src, name in pairs:
        shutil.copyfile(src, folder / name)
        paths.append(folder / name)
    return paths


def _check_maps(results, sources, out_dir, backend, tmp_path, formats=("map.gz",)):
    for r, src in zip(results, sources):
        assert r.ok, r.error
        assert r.error is None
        stem = vg.output_stem(r.path)
        assert r.outputs == [os.path.join(str(out_dir), f"{stem}.{f}") for f in formats]
        assert all(os.path.isfile(o) for o in r.outputs)
        assert r.scans > 0 and set(r.seconds) == {"read", "map", "write"}
        assert r.backend == backend
        assert vg.gridmap_sha256(vg.read_map(r.outputs[0])) == reference(src, backend, tmp_path), r.path


def _no_temporaries(out_dir, expected):
    assert sorted(os.listdir(out_dir)) == sorted(expected)


# --- Mapper.start_over --------------------------------------------------------------------


def test_start_over_is_a_new_session_on_the_same_backend():
    log = vg.load_log(INTEL)
    fresh = vg.Mapper(log.params, backend="cpu_threads", threads=2)
    fresh.insert(log.scans)
    want = fresh.finish().sha256()

    mp = vg.Mapper(vg.Params(downsample=1, resolution=0.05), backend="cpu_threads", threads=2)
    mp.insert(log.scans.select(0, 300))
    mp.start_over(log.params)
    assert len(mp) == 0 and mp.frame.size_x == 0
    assert mp.params == log.params
    mp.insert(log.scans)
    assert mp.finish().sha256() == want  # finish's defaults are the new params'
    assert mp.renders == 2 and mp.backend == "cpu_threads"

    bad = vg.Params()
    bad.p_occ = 1.5
    with pytest.raises(ValueError, match="p_occ"):
        mp.start_over(bad)
    assert len(mp) == len(log) and mp.finish().sha256() == want  # a refusal changes nothing


def test_start_over_keeps_a_fixed_frame():
    log = vg.load_log(INTEL)
    frame = vg.Frame(400, 400, log.params.resolution)
    mp = vg.Mapper(log.params, backend="cpu_double", frame=frame)
    mp.insert(log.scans.select(0, 100))
    mp.start_over(log.params)
    mp.insert(log.scans)
    ref = vg.Mapper(log.params, backend="cpu_double", frame=frame)
    ref.insert(log.scans)
    assert mp.frame.size_x == 400
    np.testing.assert_array_equal(mp.read(), ref.read())
    with pytest.raises(ValueError):
        mp.start_over(vg.Params(resolution=2 * log.params.resolution))


# --- map_logs -----------------------------------------------------------------------------


def test_output_names_are_log2maps():
    stem = vg.output_stem
    assert stem("logs/fr079-complete.gfs.log.gz") == "fr079-complete.gfs"
    assert stem("a/b.clf") == "b"
    assert stem("x.gz") == "x"
    assert stem("noext") == "noext"
    assert stem(".hidden") == ".hidden"
    assert stem("bag_dir/") == "bag_dir"


@pytest.mark.parametrize("backend", ["cpu_threads", "cpu_double"])
def test_in_process_maps_are_log2maps(tmp_path, backend):
    sources = [INTEL, INTEL, FR079] if backend == "cpu_threads" else [INTEL, INTEL]
    paths = _copies(tmp_path / "in", *zip(sources, ["intel.gfs.log.gz", "intel-again.gfs.log.gz",
                                                     "fr079-complete.gfs.log.gz"]))
    out = tmp_path / "maps" / "deeper"  # made, parents too
    formats = ("map.gz", "pgm", "png", "map")
    results = vg.map_logs(paths, out, formats=formats, backend=backend, threads=2)
    assert [r.path for r in results] == [str(p) for p in paths]
    _check_maps(results, sources, out, backend, tmp_path, formats)
    # One mapper in this process for every log, reused.
    assert {r.worker.rsplit(":", 1)[1] for r in results} == {str(os.getpid())}
    counts = [r.mapper_logs for r in results]
    assert counts == list(range(counts[0], counts[0] + len(results)))
    stems = [vg.output_stem(p) for p in paths]
    _no_temporaries(out, [f"{s}.{f}" for s in stems for f in formats + ("yaml",)])
    if LOG2MAP is not None:  # the images are log2map's bytes too
        ref = tmp_path / "ref"
        ref.mkdir()
        subprocess.run([LOG2MAP, "--backend", backend, "--quiet", str(paths[0]), str(ref / "intel.gfs.png"),
                        str(ref / "intel.gfs.pgm")], check=True, timeout=120)
        for ext in ("png", "pgm", "yaml"):
            assert (ref / f"intel.gfs.{ext}").read_bytes() == (out / f"intel.gfs.{ext}").read_bytes(), ext


def test_outputs_replace_old_ones_and_paths_may_be_strings(tmp_path):
    (path,) = _copies(tmp_path, (INTEL, "intel.gfs.log.gz"))
    out = tmp_path / "out"
    out.mkdir()
    (out / "intel.gfs.map.gz").write_bytes(b"an old map")
    (r,) = vg.map_logs([str(path)], str(out), formats="map.gz", backend="cpu_threads", threads=2)
    assert r.ok and r.outputs == [str(out / "intel.gfs.map.gz")]
    assert vg.gridmap_sha256(vg.read_map(r.outputs[0])) == reference(INTEL, "cpu_threads", tmp_path)
    _no_temporaries(out, ["intel.gfs.map.gz"])


def test_load_options_reach_load_log(tmp_path):
    (path,) = _copies(tmp_path, (INTEL, "intel.gfs.log.gz"))
    (r,) = vg.map_logs([path], tmp_path / "out", backend="cpu_threads", threads=2,
                       overrides={"downsample": 1}, param_file=GOLDEN / "params" / "vasco_default_raw.ini")
    assert r.ok, r.error
    log = vg.load_log(INTEL, param_file=GOLDEN / "params" / "vasco_default_raw.ini", overrides={"downsample": 1})
    mp = vg.Mapper(log.params, backend="cpu_double")
    mp.insert(log.scans)
    assert vg.read_map(r.outputs[0]).sha256() == mp.finish().sha256()


def test_dask_cluster_of_processes(tmp_path):
    distributed = pytest.importorskip("distributed")
    sources = [INTEL] * 4
    paths = _copies(tmp_path / "in", *zip(sources, ["a.gfs.log.gz", "b.gfs.log.gz", "c.gfs.log.gz", "d.gfs.log.gz"]))
    out = tmp_path / "out"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            results = vg.map_logs(paths, out, backend="cpu_threads", threads=1, executor=client.get_executor())
    assert [r.path for r in results] == [str(p) for p in paths]
    _check_maps(results, sources, out, "cpu_threads", tmp_path)
    _check_reuse(results)
    _no_temporaries(out, ["a.gfs.map.gz", "b.gfs.map.gz", "c.gfs.map.gz", "d.gfs.map.gz"])


def _check_reuse(results, workers=2):
    """More logs than worker processes (at most ``workers``): some process mapped several, each
    on its one mapper (its count of logs rising by one per log it mapped)."""
    by_worker = {}
    for r in results:
        by_worker.setdefault(r.worker, []).append(r.mapper_logs)
    assert str(os.getpid()) not in {w.rsplit(":", 1)[1] for w in by_worker}
    assert len(by_worker) <= workers < len(results)
    for counts in by_worker.values():
        assert sorted(counts) == list(range(1, len(counts) + 1)), by_worker
    assert max(r.mapper_logs for r in results) >= 2


def _spawning_pool(n):
    return ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("spawn"))


def test_process_pool(tmp_path):
    sources = [INTEL, INTEL, INTEL]
    paths = _copies(tmp_path / "in", *zip(sources, ["a.gfs.log.gz", "b.gfs.log.gz", "c.gfs.log.gz"]))
    out = tmp_path / "out"
    with _spawning_pool(2) as pool:
        results = vg.map_logs(paths, out, formats=("map.gz", "png"), backend="cpu_threads", threads=1,
                              executor=pool)
    _check_maps(results, sources, out, "cpu_threads", tmp_path, ("map.gz", "png"))
    _check_reuse(results)


def _with_bad_logs(tmp_path):
    good = _copies(tmp_path / "in", (INTEL, "good-a.gfs.log.gz"), (INTEL, "good-b.gfs.log.gz"))
    garbage = tmp_path / "in" / "garbage.log"
    garbage.write_text("this is not\na CARMEN log\nat all 1 2 3\n")
    missing = tmp_path / "in" / "missing.log.gz"
    out = tmp_path / "out"
    out.mkdir()
    (out / "garbage.map.gz").write_bytes(b"an earlier map of garbage.log")
    return [good[0], garbage, good[1], missing], out


@pytest.mark.parametrize("where", ["here", "pool"])
def test_bad_logs_are_reported(tmp_path, where):
    paths, out = _with_bad_logs(tmp_path)
    if where == "here":
        results = vg.map_logs(paths, out, formats=("map.gz", "png"), backend="cpu_threads", threads=2)
    else:
        with _spawning_pool(2) as pool:
            results = vg.map_logs(paths, out, formats=("map.gz", "png"), backend="cpu_threads", threads=1,
                                  executor=pool)
    assert [r.ok for r in results] == [True, False, True, False]
    _check_maps([results[0], results[2]], [INTEL, INTEL], out, "cpu_threads", tmp_path, ("map.gz", "png"))
    for r, name in ((results[1], "garbage.log"), (results[3], "missing.log.gz")):
        assert name in r.error
        assert r.scans == 0
    assert "no FLASER" in results[1].error and "cannot open" in results[3].error
    assert (out / "garbage.map.gz").read_bytes() == b"an earlier map of garbage.log"
    _no_temporaries(out, ["good-a.gfs.map.gz", "good-a.gfs.png", "good-b.gfs.map.gz", "good-b.gfs.png",
                          "garbage.map.gz"])


def test_an_output_that_cannot_be_replaced(tmp_path):
    """A target that is a directory is refused before any output is renamed."""
    (path,) = _copies(tmp_path, (INTEL, "intel.gfs.log.gz"))
    out = tmp_path / "out"
    (out / "intel.gfs.png").mkdir(parents=True)
    (out / "intel.gfs.map.gz").write_bytes(b"old")
    (r,) = vg.map_logs([path], out, formats=("map.gz", "png"), backend="cpu_threads", threads=2)
    # The transaction's words (carmen_compat's OutputTransaction, as log2map's).
    assert not r.ok and "intel.gfs.log.gz" in r.error and "intel.gfs.png: is a directory" in r.error
    assert (out / "intel.gfs.map.gz").read_bytes() == b"old"
    assert (out / "intel.gfs.png").is_dir() and not os.listdir(out / "intel.gfs.png")
    _no_temporaries(out, ["intel.gfs.map.gz", "intel.gfs.png"])
    (out / "intel.gfs.png").rmdir()
    (r,) = vg.map_logs([path], out, formats=("map.gz", "png"), backend="cpu_threads", threads=2)
    assert r.ok, r.error


def test_a_failed_rename_puts_the_old_outputs_back(tmp_path):
    """The second rename of a log's three outputs fails: the first target gets its old file
    back, the one that did not exist stays absent, no temporary is left."""
    (path,) = _copies(tmp_path, (INTEL, "intel.gfs.log.gz"))
    out = tmp_path / "out"
    out.mkdir()
    (out / "intel.gfs.map").write_bytes(b"old map")
    (out / "intel.gfs.png").write_bytes(b"old png")
    vg._core._fail_rename_for_testing(2, errno.ENOSPC)  # the transaction's hook (atomic_file.h)
    try:
        (r,) = vg.map_logs([path], out, formats=("map", "map.gz", "png"), backend="cpu_threads", threads=2)
    finally:
        vg._core._fail_rename_for_testing(0, 0)
    assert not r.ok and "No space left" in r.error and "intel.gfs.map.gz: " in r.error
    assert "have their old files back" in r.error
    assert (out / "intel.gfs.map").read_bytes() == b"old map"
    assert (out / "intel.gfs.png").read_bytes() == b"old png"
    _no_temporaries(out, ["intel.gfs.map", "intel.gfs.png"])


@pytest.mark.parametrize("where", ["here", "pool"])
def test_fail_fast(tmp_path, where):
    paths, out = _with_bad_logs(tmp_path)
    paths = [paths[1]] + [p for p in paths if p != paths[1]]  # the garbage first
    if where == "here":
        with pytest.raises(vg.BatchError, match="garbage.log") as info:
            vg.map_logs(paths, out, backend="cpu_threads", threads=2, fail_fast=True)
        assert [r.ok for r in info.value.results] == [False, False, False, False]
        assert "not mapped" in info.value.results[1].error
    else:
        with _spawning_pool(1) as pool:
            with pytest.raises(vg.BatchError, match="garbage.log") as info:
                vg.map_logs(paths, out, backend="cpu_threads", threads=1, executor=pool, fail_fast=True)
        assert len(info.value.results) == 4
    e = info.value
    assert e.result.path == str(paths[0]) and not e.result.ok
    assert isinstance(e.__cause__, vg.FileError) and e.__cause__.file.endswith("garbage.log")
    assert (out / "garbage.map.gz").read_bytes() == b"an earlier map of garbage.log"
    assert not [n for n in os.listdir(out) if n.startswith(".")]


def test_argument_errors(tmp_path):
    (path,) = _copies(tmp_path, (INTEL, "intel.gfs.log.gz"))
    out = tmp_path / "never"
    other = tmp_path / "elsewhere"
    other.mkdir()
    shutil.copyfile(INTEL, other / "intel.gfs.log")
    cases = [
        (ValueError, "'jpg' is none of", dict(formats=("map.gz", "jpg"))),
        (ValueError, "named twice", dict(formats=("png", "png"))),
        (ValueError, "at least one", dict(formats=())),
        (ValueError, "backend 'gpu9000'", dict(backend="gpu9000")),
        (ValueError, "cuda_mode", dict(cuda_mode="fast")),
        (ValueError, "threads", dict(threads=-1)),
        (TypeError, "bogus", dict(bogus=1)),
        (vg.FileError, "no-such.ini", dict(param_file=tmp_path / "no-such.ini")),
    ]
    for exc, match, kw in cases:
        with pytest.raises(exc, match=match):
            vg.map_logs([path], out, **kw)
    with pytest.raises(ValueError, match="would both write"):
        vg.map_logs([path, other / "intel.gfs.log"], out)
    with pytest.raises(TypeError, match="not one path"):
        vg.map_logs(path, out)
    assert not out.exists()  # refused before any work
    assert vg.map_logs([], out) == [] and out.is_dir()


def test_exported_and_documented():
    for name in ("map_logs", "LogResult", "BatchError"):
        assert name in vg.__all__ and getattr(vg, name).__doc__
    doc = vg.map_logs.__doc__
    for word in ("executor", "Dask", "fail_fast", "transaction", "start_over"):
        assert word in doc
    assert vg.Mapper.start_over.__doc__ and "CUDA" in vg.Mapper.start_over.__doc__


def test_cuda_exact_batch(tmp_path):
    cuda_or_skip()
    sources = [INTEL, FR079]
    paths = _copies(tmp_path, (INTEL, "intel.gfs.log.gz"), (FR079, "fr079-complete.gfs.log.gz"))
    results = vg.map_logs(paths, tmp_path / "out", backend="cuda", cuda_mode="exact")
    for r, src in zip(results, sources):
        assert r.ok, r.error
        assert r.backend == "cuda_exact"
        assert vg.read_map(r.outputs[0]).sha256() == _golden(src)
    assert results[1].mapper_logs == results[0].mapper_logs + 1
