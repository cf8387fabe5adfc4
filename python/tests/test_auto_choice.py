"""One "auto": Mapper(backend="auto") and log2map --backend auto choose by one rule
(vasco_gpu/backend_choice.h), and the session's options come from one table."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import vasco_gpu as vg
from vasco_gpu import _core

from conftest import ROOT

INTEL = ROOT / "logs" / "intel.gfs.log.gz"
TYPES = {"flag", "whole", "real", "bytes", "choice", "text", "whole_list"}


def built_log2map():
    """log2map of a build of this checkout (VASCO_BIN, build/bin), else the one `pip install .`
    put beside this interpreter (a virtual environment's bin/, not on the PATH when its python
    runs without activating it), else the PATH's, or None."""
    for d in (os.environ.get("VASCO_BIN"), ROOT / "build" / "bin", Path(sys.executable).parent):
        if d and (Path(d) / "log2map").is_file():
            return Path(d) / "log2map"
    found = shutil.which("log2map")
    return Path(found) if found else None


def _estimate(why: str) -> str:
    """'1.9e+07 cell updates: about 0.068 s on 4 cores' of a note."""
    return why[: why.index(" cores") + len(" cores")]


def test_mapper_auto_and_log2map_choose_alike(tmp_path):
    log2map = built_log2map()
    if log2map is None:
        pytest.skip("no log2map built (set VASCO_BIN)")
    run = subprocess.run([str(log2map), "--backend", "auto", "--threads", "4", str(INTEL), str(tmp_path / "a.map")],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    note = re.search(r"--backend auto: (.*)", run.stderr).group(1)

    log = vg.load_log(INTEL)
    mapper = vg.Mapper(log.params, backend="auto", threads=4)
    assert mapper.backend == "auto" and mapper.auto_choice is None  # undecided until it has scans
    mapper.insert(log.scans)
    choice = mapper.auto_choice
    assert choice["cell_updates"] == vg.estimated_cell_updates(log.scans, log.params)
    assert (choice["cores"], choice["expected_renders"]) == (4, 1)
    assert note.startswith(_estimate(choice["why"])), (note, choice["why"])
    log2map_gpu = note.endswith(": using cuda")
    assert log2map_gpu or note.endswith(": using cpu_threads"), note
    assert log2map_gpu == (choice["backend"] == "cuda"), (note, choice)
    assert mapper.backend.startswith(choice["backend"])  # cuda: cuda_float
    if not choice["gpu_usable"]:  # no GPU here: both on the CPU, and no GPU time said
        assert not log2map_gpu and mapper.backend == "cpu_threads"
        assert "on the GPU" not in choice["why"]


def test_the_rule_by_its_arguments():
    # The same estimate whether a GPU is usable or not; only the backend and the note differ.
    with_gpu = vg.auto_choice(1e7, threads=4, gpu_usable=True)
    without = vg.auto_choice(1e7, threads=4, gpu_usable=False)
    for key in ("cell_updates", "cores", "cpu_s", "gpu_s", "gpu_faster"):
        assert with_gpu[key] == without[key], key
    assert without["backend"] == "cpu_threads" and "on the GPU" not in without["why"]
    assert _estimate(with_gpu["why"]) == _estimate(without["why"])
    # A large workload goes to a usable GPU; a small one stays on the CPU unless it is
    # rendered often enough to pay for the GPU's start-up.
    assert vg.auto_choice(1e12, threads=4, gpu_usable=True)["backend"] == "cuda"
    small = vg.auto_choice(1e6, threads=4, gpu_usable=True)
    assert small["backend"] == "cpu_threads" and small["cpu_s"] < small["gpu_s"]
    assert vg.auto_choice(1e6, threads=4, expected_renders=10**6, gpu_usable=True)["backend"] == "cuda"
    endless = vg.auto_choice(0, threads=4, expected_renders=0, gpu_usable=True)
    assert endless["backend"] == "cuda" and endless["expected_renders"] == 0


def test_a_workload_without_end_chooses_when_the_mapper_is_made():
    mapper = vg.Mapper(backend="auto", expected_renders=0)
    assert mapper.auto_choice is not None and mapper.auto_choice["expected_renders"] == 0
    assert mapper.backend == ("cpu_threads" if not mapper.auto_choice["gpu_usable"] else mapper.backend)
    assert mapper.backend != "auto"
    assert vg.Mapper(backend="cpu_double").auto_choice is None
    with pytest.raises(ValueError, match="expected_renders"):
        vg.Mapper(backend="auto", expected_renders=-1)


def test_map_logs_auto_is_the_batch_rule(tmp_path):
    [result] = vg.map_logs([INTEL], tmp_path, backend="auto")
    assert result.ok, result.error
    usable = vg.cuda_available()
    assert result.backend == ("cuda_float" if usable else "cpu_threads")


def test_session_option_schema():
    rows = {r["name"]: r for r in vg.option_schema("session")}
    for name in ("backend", "cuda_mode", "threads", "cuda_device", "split_devices", "max_memory",
                 "expected_renders"):
        assert set(rows[name]) >= {"name", "type", "default", "help", "choices", "lo", "hi"}, name
    assert rows["backend"]["choices"] == vg.backend_names()
    assert rows["backend"]["default"] == "auto"
    assert rows["cuda_mode"]["choices"] == ["float", "exact"]
    assert (rows["threads"]["lo"], rows["threads"]["hi"]) == (0, 1024)
    assert rows["max_memory"]["type"] == "bytes" and rows["max_memory"]["default"] == 2 << 30
    assert rows["max_memory"]["flag"] == "--max-memory"
    assert rows["expected_renders"]["default"] == 1
    # The Mapper's keywords are checked by these rows.
    with pytest.raises(ValueError, match="cuda_mode 'fast': expected one of: float, exact"):
        vg.Mapper(backend="cpu_double", cuda_mode="fast")
    with pytest.raises(ValueError, match=r"threads 1025: expected a whole number in \[0, 1024\]"):
        vg.Mapper(backend="cpu_threads", threads=1025)


@pytest.mark.parametrize("component", ["session", "pose_source", "map_output"])
def test_every_component_has_a_schema(component):
    rows = vg.option_schema(component)
    assert rows and all(r["help"] and r["type"] in TYPES for r in rows)
    for r in rows:
        if r["type"] == "choice":
            assert r["choices"], r["name"]


def test_an_unknown_component_is_refused():
    with pytest.raises(ValueError, match="no component 'nodes'"):
        _core.option_schema("nodes")
