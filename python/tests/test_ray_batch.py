"""map_logs on Ray actors (vasco_gpu.RayExecutor), on a local Ray instance of this host's CPUs:
the maps are log2map's, each actor keeps one mapper for its logs, fail_fast cancels the logs
not started, and the executor's futures behave as concurrent.futures' (cancel, exceptions, a
dead actor, shutdown killing the actors)."""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import operator
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

import vasco_gpu as vg
from test_batch import INTEL, _check_maps, _check_reuse, _copies, _no_temporaries, _with_bad_logs

ray = pytest.importorskip("ray", reason="Ray is not installed (pip install '.[ray]')")
from vasco_gpu.ray_executor import RayExecutor, actor_count  # noqa: E402


def _descendants(pid):
    """The live (not zombie) processes below pid, read from /proc."""
    children = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
        except OSError:
            continue
        fields = text[text.rindex(")") + 2:].split()  # after "(comm) ": state, ppid, ...
        if fields[0] != "Z":
            children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    found, todo = set(), [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.add(child)
            todo.append(child)
    return found


def _wait_gone(pids, seconds=20.0):
    """pids that are still alive after waiting up to seconds for them to go."""
    deadline = time.monotonic() + seconds
    while True:
        alive = {p for p in pids if _state(p) not in ("gone", "Z")}
        if not alive or time.monotonic() > deadline:
            return alive
        time.sleep(0.2)


def _state(pid):
    """The process's state letter (Z: a zombie, exited), or "gone"."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return "gone"
    return text[text.rindex(")") + 2:].split()[0]


@contextlib.contextmanager
def ray_instance(**resources):
    """A new local Ray instance of these resources for the block; none of its processes left after."""
    saved = os.environ.pop("RAY_ADDRESS", None)  # a new instance, never a cluster the caller has
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    # processes of earlier tests that outlive them (multiprocessing's resource tracker) are not Ray's
    before = _descendants(os.getpid())
    ray.init(address="local", include_dashboard=False, _node_ip_address="127.0.0.1", log_to_driver=False,
             **resources)
    try:
        yield ray
    finally:
        started = _descendants(os.getpid()) - before
        ray.shutdown()
        if saved is not None:
            os.environ["RAY_ADDRESS"] = saved
    assert not _wait_gone(started), "Ray processes left after ray.shutdown()"


@pytest.fixture(scope="module")
def local_ray():
    """One Ray instance of two CPUs on this host for the module."""
    with ray_instance(num_cpus=2) as instance:
        yield instance


def _pids(workers):
    return {int(w.rsplit(":", 1)[1]) for w in workers}


def test_actor_count():
    assert actor_count({"CPU": 2.0}) == 2
    assert actor_count({"CPU": 16.0, "GPU": 2.0}, num_cpus=1, num_gpus=1 / 3) == 6  # GPUs bound it
    assert actor_count({"CPU": 4.0, "GPU": 2.0}, num_cpus=1, num_gpus=1 / 3) == 4  # CPUs bound it
    assert actor_count({"CPU": 3.0, "GPU": 1.0}, num_cpus=2, num_gpus=0.5) == 1
    assert actor_count({"CPU": 8.0}, num_cpus=0.5) == 16
    assert actor_count({"CPU": 8.0, "disk": 3.0}, custom={"disk": 1}) == 3
    assert actor_count({"CPU": 8.0}, num_gpus=1) == 1  # none fit: one, held until one does
    assert actor_count({"CPU": 5.0}, num_cpus=0, num_gpus=0) == 5


def test_futures(local_ray):
    """Cancel of a queued call, an exception raised in the actor, a dead actor replaced, and
    shutdown killing the actors; the default size fills the instance's two CPUs."""
    ex = RayExecutor()
    assert ex.actors == 2
    first = _pids(ex.where())
    assert len(first) == 2 and os.getpid() not in first
    busy = [ex.submit(time.sleep, 1.0) for _ in range(2)]  # both actors taken
    queued = ex.submit(os.getpid)
    assert queued.cancel() and queued.cancelled()
    raised = ex.submit(operator.truediv, 1, 0)
    with pytest.raises(ZeroDivisionError):
        raised.result(timeout=60)
    assert isinstance(raised.exception().__cause__, ray.exceptions.RayTaskError)
    assert [f.result(timeout=60) for f in busy] == [None, None]
    died = ex.submit(os._exit, 3)
    assert isinstance(died.exception(timeout=60), ray.exceptions.RayActorError)
    assert ex.actors == 2
    pids = {ex.submit(os.getpid).result(timeout=60) for _ in range(4)}
    now = _pids(ex.where())
    assert pids <= now and len(now) == 2 and len(now & first) == 1  # one new actor
    late = [ex.submit(time.sleep, 0.5) for _ in range(3)] + [ex.submit(os.getpid) for _ in range(3)]
    ex.shutdown(wait=True, cancel_futures=True)
    assert all(f.done() for f in late) and [f.cancelled() for f in late] == [False, False] + [True] * 4
    with pytest.raises(RuntimeError):
        ex.submit(os.getpid)
    assert not _wait_gone(first | now), "actors alive after shutdown"


def test_maps_on_actors(tmp_path, local_ray):
    """Four logs on two actors: log2map's maps, each actor's one mapper reused, the actors
    killed when the executor closes."""
    sources = [INTEL] * 4
    paths = _copies(tmp_path / "in", *zip(sources, ["a.gfs.log.gz", "b.gfs.log.gz", "c.gfs.log.gz", "d.gfs.log.gz"]))
    out = tmp_path / "out"
    with RayExecutor(actors=2) as ex:
        actors = _pids(ex.where())
        results = vg.map_logs(paths, out, backend="cpu_threads", threads=1, executor=ex)
    assert [r.path for r in results] == [str(p) for p in paths]
    assert _pids(r.worker for r in results) <= actors
    _check_maps(results, sources, out, "cpu_threads", tmp_path)
    _check_reuse(results)
    _no_temporaries(out, ["a.gfs.map.gz", "b.gfs.map.gz", "c.gfs.map.gz", "d.gfs.map.gz"])
    assert not _wait_gone(actors), "actors alive after the with block"


def test_fail_fast(tmp_path, local_ray):
    """The garbage log first on one actor: BatchError, the logs not started cancelled and
    reported not mapped (the one the actor took as the failure came back may finish)."""
    paths, out = _with_bad_logs(tmp_path)
    paths = [paths[1]] + [p for p in paths if p != paths[1]]  # garbage, good-a, good-b, missing
    with RayExecutor(actors=1) as ex:
        with pytest.raises(vg.BatchError, match="garbage.log") as info:
            vg.map_logs(paths, out, backend="cpu_threads", threads=1, executor=ex, fail_fast=True)
    e = info.value
    assert e.result.path == str(paths[0]) and not e.result.ok
    assert isinstance(e.__cause__, vg.FileError) and e.__cause__.file.endswith("garbage.log")
    results = e.results
    assert [r.path for r in results] == [str(p) for p in paths]
    assert results[1].ok or "not mapped" in results[1].error
    for r in results[2:]:
        assert not r.ok and "not mapped" in r.error, r.error
    assert (out / "garbage.map.gz").read_bytes() == b"an earlier map of garbage.log"
    assert not [n for n in os.listdir(out) if n.startswith(".")]


def test_a_failed_constructor_leaves_no_actor(local_ray, monkeypatch):
    """The third actor cannot be made: the constructor raises, and the two made before are
    killed (their handles, still held here, answer no more)."""
    made = []
    real = RayExecutor._new_actor

    def third_fails(self):
        if len(made) == 2:
            raise RuntimeError("no room for a third actor")
        made.append(real(self))
        return made[-1]

    monkeypatch.setattr(RayExecutor, "_new_actor", third_fails)
    with pytest.raises(RuntimeError, match="no room"):
        RayExecutor(actors=3)
    assert len(made) == 2
    for actor in made:
        with pytest.raises(ray.exceptions.RayActorError):
            ray.get(actor.where.remote(), timeout=60)


def test_lazy_import():
    """vasco_gpu names RayExecutor without importing Ray until it is asked for."""
    code = "import sys, vasco_gpu as vg; assert 'ray' not in sys.modules; vg.RayExecutor; " \
           "assert 'ray' not in sys.modules; print(vg.RayExecutor.__name__)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.strip() == "RayExecutor", done.stderr
    assert "RayExecutor" in vg.__all__ and cf.Executor in vg.RayExecutor.__mro__
