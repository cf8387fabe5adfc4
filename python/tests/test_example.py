"""examples/loop_closure.py runs (on a few hundred scans, to stay short)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conftest import ROOT


def test_loop_closure_example(tmp_path):
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "loop_closure.py"), "--scans", "300",
                        "--backend", "cpu_threads", "--runs", "2", "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "re-render" in r.stdout and "median" in r.stdout
    for name in ("before.png", "after.png", "before_after.png"):
        data = (tmp_path / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n", name


def test_bench_render_script():
    r = subprocess.run([sys.executable, str(ROOT / "python" / "bench_render.py"), "--backend", "cpu_threads",
                        "--runs", "2", "--warmup", "1", "--scans", "300"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "median" in r.stdout


def test_loop_closure_example_with_gtsam(tmp_path):
    pytest.importorskip("gtsam", reason="GTSAM is optional (pip install gtsam)")
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "loop_closure.py"), "--scans", "600", "--gtsam",
                        "--backend", "cpu_threads", "--runs", "1", "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "corrected by GTSAM" in r.stdout
