"""cuda_available() answers with its truth value (a pair was always true) and says why not in
a user's words; code that unpacked the old pair keeps working."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path

import pytest

import vasco_gpu as vg
from vasco_gpu import _cuda


def test_the_answer_is_its_truth_value():
    status = vg.cuda_available()
    assert isinstance(status, vg.CudaStatus)
    assert bool(status) is status.available
    assert isinstance(status.available, bool) and isinstance(status.reason, str)
    assert (status.reason == "") == status.available
    if not vg.has_cuda:  # a CPU-only build: never available, and it says why
        assert not status
        assert "this build has no CUDA backend" in status.reason


def test_it_unpacks_and_indexes_as_the_old_pair():
    status = vg.cuda_available()
    ok, why = status
    assert (ok, why) == (status.available, status.reason) == (status[0], status[1]) == tuple(status)
    assert status == (ok, why) and status == vg.CudaStatus(ok, why)
    assert status != vg.CudaStatus(not ok, why) and status != "x"
    assert hash(status) == hash(vg.CudaStatus(ok, why))


@pytest.mark.parametrize("available, reason", [(True, ""), (False, "no GPU found (no CUDA-capable device is detected)")])
def test_both_answers(available, reason):
    status = vg.CudaStatus(available, reason)
    assert bool(status) is available
    assert (1 if status else 0) == int(available)
    assert repr(status) == f"CudaStatus(available={available!r}, reason={reason!r})"
    assert pickle.loads(pickle.dumps(status)) == status
    with pytest.raises(AttributeError):
        status.available = not available


@pytest.mark.parametrize("engine, available", [((True, ""), True), ((False, "no CUDA device (no CUDA-capable device is detected)"), False)])
def test_cuda_available_passes_the_engines_answer_on(monkeypatch, engine, available):
    monkeypatch.setattr(vg._core, "_cuda_available", lambda: engine)
    status = vg.cuda_available()
    assert bool(status) is available
    if not available:
        assert status.reason == "no GPU found (no CUDA-capable device is detected)"


@pytest.mark.parametrize("engine, user", [
    ("no CUDA device (no CUDA-capable device is detected)", "no GPU found (no CUDA-capable device is detected)"),
    ("no CUDA device (CUDA driver version is insufficient for CUDA runtime version)",
     "no GPU found (no NVIDIA driver, or one too old for this build's CUDA runtime: "
     "CUDA driver version is insufficient for CUDA runtime version)"),
    ("no CUDA device (OS call failed or operation not supported on this OS)",
     "no GPU found (the CUDA runtime says: OS call failed or operation not supported on this OS)"),
    ("CUDA device 0 does not exist (0 present)", "no GPU found (the CUDA runtime lists no device)"),
    # a GPU that is there but cannot run this build, and a build without CUDA: said as they are
    ("CUDA device 0 is not usable (all CUDA-capable devices are busy or unavailable)",
     "CUDA device 0 is not usable (all CUDA-capable devices are busy or unavailable)"),
    ("this build has no CUDA backend (no CUDA toolkit when it was built)",
     "this build has no CUDA backend (no CUDA toolkit when it was built)"),
])
def test_the_runtimes_no_gpu_texts_say_no_gpu_found(engine, user):
    assert _cuda._user_reason(engine) == user


def test_no_visible_gpu_says_no_gpu_found():
    """A CUDA build shown no GPU (CUDA_VISIBLE_DEVICES empty) answers false, "no GPU found"."""
    env = dict(os.environ, CUDA_VISIBLE_DEVICES="")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(vg.__file__).resolve().parents[1])] +
                                        ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    code = "import vasco_gpu as vg; s = vg.cuda_available(); print(bool(s)); print(s.reason)"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env)
    assert r.returncode == 0, r.stderr
    truth, reason = r.stdout.splitlines()
    assert truth == "False"
    if vg.has_cuda:
        assert reason.startswith("no GPU found ("), reason
    else:
        assert reason.startswith("this build has no CUDA backend"), reason


def test_a_cuda_mapper_without_a_usable_gpu_is_a_clear_error():
    status = vg.cuda_available()
    if status:
        pytest.skip("a GPU is usable here")
    with pytest.raises(vg.NoGpuError):
        vg.Mapper(backend="cuda")
