"""map_logs on Ray actors that share one GPU (RayExecutor(num_gpus=1/3): three actors, each with
its one mapper and CUDA context), on a local Ray instance given this host's first GPU. Skipped
without Ray or a usable CUDA backend (CI has no GPU: it runs on the GPU machine)."""
from __future__ import annotations

import os

import pytest

import vasco_gpu as vg
from conftest import cuda_or_skip
from test_batch import FR079, INTEL, _check_reuse, _copies, _golden, _no_temporaries

ray = pytest.importorskip("ray")
from test_ray_batch import _pids, _wait_gone, ray_instance  # noqa: E402
from vasco_gpu.ray_executor import RayExecutor  # noqa: E402


@pytest.fixture(scope="module")
def gpu_ray():
    """A Ray instance of four CPUs and one GPU on this host for the module."""
    cuda_or_skip()
    with ray_instance(num_cpus=4, num_gpus=1) as instance:
        yield instance


def test_three_actors_share_the_gpu_and_write_carmens_maps(tmp_path, gpu_ray):
    """Six logs on three actors of a third of the GPU each: every map CARMEN's bytes (the golden
    digests), every actor on the GPU with its one mapper reused, the actors gone after."""
    sources = [FR079, INTEL] * 3
    names = [f"{i}-{s.name}" for i, s in enumerate(sources)]
    paths = _copies(tmp_path / "in", *zip(sources, names))
    out = tmp_path / "out"
    with RayExecutor(num_gpus=1 / 3) as ex:
        assert ex.actors == 3  # the GPU bounds it: 3 x 1/3, of 4 CPUs
        actors = _pids(ex.where())
        on_gpu = [ex.submit(lambda: os.environ.get("CUDA_VISIBLE_DEVICES")) for _ in range(3)]
        assert {f.result(timeout=60) for f in on_gpu} == {"0"}  # Ray gave each actor the GPU
        results = vg.map_logs(paths, out, backend="cuda", cuda_mode="exact", executor=ex)
    for r, src in zip(results, sources):
        assert r.ok, r.error
        assert r.backend == "cuda_exact"
        assert vg.read_map(r.outputs[0]).sha256() == _golden(src), r.path
    assert _pids(r.worker for r in results) <= actors
    _check_reuse(results, workers=3)  # one mapper per actor, its count rising by one per log
    _no_temporaries(out, [n[: -len(".log.gz")] + ".map.gz" for n in names])
    assert not _wait_gone(actors), "actors alive after the with block"
