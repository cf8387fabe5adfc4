"""Every command-line tool as `pip install .` installs it: the C++ tools log2map, mapdiff and
mapconvert (built into the wheel's scripts) beside the console scripts bag2map, bag2carmen,
carmen2bag and vasco_map_node, in the environment's scripts directory (its bin/, on its PATH),
each answering --version, and log2map mapping a log with nothing else on the PATH.

The tools are taken from what the installed distribution recorded (its RECORD), not from the
PATH, so that a build tree's bin/ on the PATH cannot stand in for them. Where vasco_gpu is not
installed from a wheel (an in-tree build on PYTHONPATH, or an editable install made without the
tools) the tests that need them skip and say why; VASCO_REQUIRE_INSTALLED_TOOLS=1 (CI's
installed environment) makes that a failure."""

from __future__ import annotations

import importlib.metadata
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import vasco_gpu as vg

from conftest import golden_cases, gridmap_digest

CPP_TOOLS = ("log2map", "mapdiff", "mapconvert")
CONSOLE_SCRIPTS = ("bag2map", "bag2carmen", "carmen2bag", "vasco_map_node")
REQUIRED = os.environ.get("VASCO_REQUIRE_INSTALLED_TOOLS") == "1"
INTEL_CASE = next(c for c in golden_cases() if c[0] == "intel.gfs__vasco_default_ds4")


def _distribution():
    """vasco_gpu's installed distribution and how it is installed: ("wheel", dist) when the
    imported package is the one it installed, ("editable", dist) for `pip install -e`, and
    ("in-tree", None) when the package is imported from elsewhere (PYTHONPATH)."""
    try:
        dist = importlib.metadata.distribution("vasco_gpu")
    except importlib.metadata.PackageNotFoundError:
        return "in-tree", None
    direct_url = json.loads(dist.read_text("direct_url.json") or "{}")
    if direct_url.get("dir_info", {}).get("editable"):
        return "editable", dist
    imported = Path(vg.__file__).resolve()
    installed = [Path(dist.locate_file(f)).resolve() for f in dist.files or ()
                 if f.as_posix() == "vasco_gpu/__init__.py"]
    return ("wheel", dist) if imported in installed else ("in-tree", None)


def _recorded_scripts(dist) -> dict:
    """{name: path} of the tools and console scripts the distribution installed."""
    names = set(CPP_TOOLS + CONSOLE_SCRIPTS)
    return {f.name: Path(dist.locate_file(f)).resolve() for f in dist.files or ()
            if f.name in names and f.parent.name in ("bin", "Scripts")}


@pytest.fixture(scope="module")
def scripts():
    """{name: path} of every tool, all installed; skips (fails when required) otherwise."""
    kind, dist = _distribution()
    found = _recorded_scripts(dist) if dist is not None else {}
    missing = [n for n in CPP_TOOLS if n not in found]
    if missing and kind != "wheel":
        why = (f"vasco_gpu is imported from {Path(vg.__file__).parent} ({kind}: "
               + ("an editable install made without the command-line tools" if kind == "editable" else
                  "not the installed distribution") + f"), so {', '.join(missing)} are not installed with it; "
               "`pip install .` into a virtual environment installs them")
        if REQUIRED:
            pytest.fail(f"VASCO_REQUIRE_INSTALLED_TOOLS=1 but {why}")
        pytest.skip(why)
    assert not missing, f"the installed vasco_gpu has no {', '.join(missing)} (its RECORD lists {sorted(found)})"
    return found


def _run(tool: Path, *args, cwd: Path):
    """tool run from cwd with only its own directory and the system's on the PATH."""
    env = dict(os.environ, PATH=os.pathsep.join([str(tool.parent), os.defpath]))
    return subprocess.run([str(tool), *map(str, args)], capture_output=True, text=True, cwd=cwd, env=env,
                          timeout=300)


def test_the_tools_are_installed_beside_the_console_scripts(scripts):
    assert sorted(scripts) == sorted(CPP_TOOLS + CONSOLE_SCRIPTS)
    assert {p.parent for p in scripts.values()} == {scripts["bag2map"].parent}
    for name, path in scripts.items():
        assert path.is_file() and os.access(path, os.X_OK), name


@pytest.mark.parametrize("name", CPP_TOOLS + CONSOLE_SCRIPTS)
def test_every_tool_answers_version(scripts, name, tmp_path):
    r = _run(scripts[name], "--version", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[0] == f"{name} (vasco_gpu) {vg.__version__}"


def test_installed_log2map_maps_a_log_from_another_directory(scripts, tmp_path):
    """The golden digest (CARMEN's own mapper's map) for the .map; the .pgm's pixels against
    the map's cells by map_server's trinary rule, done here by hand."""
    name, log, ini, digest = INTEL_CASE
    r = _run(scripts["log2map"], "-q", "--backend", "cpu_threads", "--param-file", ini, log, "intel.pgm",
             "intel.map", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    m = vg.read_map(tmp_path / "intel.map")
    assert gridmap_digest(m.cells, m.resolution) == digest
    data = (tmp_path / "intel.pgm").read_bytes()
    magic, w, h, maxval = data.split(maxsplit=4)[:4]
    assert (magic, int(w), int(h), int(maxval)) == (b"P5", m.size_x, m.size_y, 255)
    pixels = np.frombuffer(data[len(data) - m.size_x * m.size_y:], dtype=np.uint8).reshape(m.size_y, m.size_x)
    cells = m.image  # row 0 at the top, as the PGM
    want = np.where(cells == -1, 205, np.where(cells > 0.65, 0, np.where(cells < 0.196, 254, 205)))
    assert np.array_equal(pixels, want)


def test_carmen2bag_answers_version(capsys):
    from vasco_gpu.bags.carmen2bag import main

    assert main(["--version"]) == 0
    assert capsys.readouterr().out == f"carmen2bag (vasco_gpu) {vg.__version__}\n"


def test_vasco_map_node_answers_version_before_ros_starts(capsys):
    """--version needs no rclpy; after --ros-args it is ROS 2's, not ours."""
    from vasco_gpu import ros

    rclpy_before = "rclpy" in sys.modules
    assert ros.main(["vasco_map_node", "--version"]) == 0
    assert capsys.readouterr().out == f"vasco_map_node (vasco_gpu) {vg.__version__}\n"
    assert ("rclpy" in sys.modules) == rclpy_before
    assert ros._asks_version(["vasco_map_node", "--ros-args", "--version"]) is False
