"""The Python blocks of README.md and of docs/*.md, and the shell blocks that need the
package's console scripts (bag2map, bag2carmen, python -c), run here with the installed
package; the rest of the documents is tests/docs/readme_test.py's (ctest
ReadmeCommandsWork). Both read the documents through tests/docs/readme_blocks.py and take
each block's check from tests/docs/readme_checks.py, where the fixtures used here are
stated.

Every block runs as written, in a scratch directory: a Python block as a script would
(__name__ is "__main__"), a shell block's commands with bash. Fixtures: logs/ (the bundled
logs, as the repository root has them); bags made here from intel (bag_maker.py) where a
block names run.mcap, run.bag, run/ and pose files. Where no log2map binary is found
(VASCO_BIN, build/bin, beside this interpreter, PATH) a stand-in maps the log through the
package (load_log, Mapper, write_map).
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "tests" / "docs"
LOGS = ROOT / "logs"


def _load(name):
    spec = importlib.util.spec_from_file_location(name, DOCS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


readme_blocks = _load("readme_blocks")
readme_checks = _load("readme_checks")

vg = pytest.importorskip("vasco_gpu")

sys.path.insert(0, str(Path(__file__).resolve().parent))


DOCS = readme_blocks.doc_files(ROOT)


def python_blocks():
    """(document, block, check) of every block of the documents that this file runs."""
    out = []
    for path in DOCS:
        doc = readme_blocks.doc_name(path, ROOT)
        for b in readme_blocks.read_blocks(path):
            c = readme_checks.check_for(doc, b.key)
            if c is not None and (c.kind == "python" or (c.kind == "run" and c.python)):
                out.append(pytest.param(doc, b, c, id=f"{doc}:{b.line}"))
    return out


def test_python_blocks_are_found():
    # A table or a parser that finds no Python block would make every test below vanish.
    kinds = {(p.values[0], p.values[2].kind) for p in python_blocks()}
    assert ("README.md", "python") in kinds and ("docs/python.md", "run") in kinds, kinds


def test_the_table_knows_every_block():
    # readme_test.py fails on these too; here so that a Python-only run sees them.
    unknown, stale = [], []
    names = set()
    for path in DOCS:
        doc = readme_blocks.doc_name(path, ROOT)
        names.add(doc)
        keys = [b.key for b in readme_blocks.read_blocks(path)]
        unknown += [(doc, k) for k in keys if readme_checks.check_for(doc, k) is None]
        stale += [(doc, k) for k in readme_checks.CHECKS.get(doc, {}) if k not in keys]
    stale += [(doc, "*") for doc in readme_checks.CHECKS if doc not in names]
    assert not unknown and not stale, (unknown, stale)


# --- fixtures -----------------------------------------------------------------------------

N_SCANS = 300  # of intel's 910: enough for a map, quick to write in three bag formats


@pytest.fixture(scope="module")
def intel():
    return vg.load_log(LOGS / "intel.gfs.log.gz", overrides={"num_scans": N_SCANS})


def _stamps(n):
    # Binary fractions: whole nanoseconds, so the bag's stamps read back exactly.
    return [1000.0 + 0.125 * i for i in range(n)]


def _ranges(log):
    return [log.scans.ranges_of(i).copy() for i in range(len(log))]


def write_g2o(path, poses):
    path.write_text("".join(f"VERTEX_SE2 {i} {x!r} {y!r} {t!r}\n" for i, (x, y, t) in enumerate(poses.tolist())))


def write_tum(path, stamps, poses):
    import math

    path.write_text("".join(f"{t!r} {x!r} {y!r} 0 0 0 {math.sin(th / 2)!r} {math.cos(th / 2)!r}\n"
                            for t, (x, y, th) in zip(stamps, poses.tolist())))


def make_bags(d: Path, log):
    """run.mcap (a bare MCAP file: scans on /scan, map -> base_link on /tf, the mount on
    /tf_static), run.bag (ROS 1: scans on /front/scan, odom -> base_link on /tf, nav_msgs/
    Odometry on /odom in frame odom, the mount on /tf_static), run/ (a ROS 2 sqlite3 bag of
    the scans alone), optimized.g2o and optimized.txt (the laser's poses: g2o in scan order,
    TUM by the bag's stamps)."""
    pytest.importorskip("rosbags")
    import bag_maker

    poses = log.poses
    n = len(poses)
    stamps = _stamps(n)
    ranges = _ranges(log)
    s = log.scans
    scan = (float(s.first_angle[0]), float(s.angle_step[0]), 0.0, 81.91)
    tmp = d / "tmp"
    bag_maker.write_bag(tmp / "mcap", "mcap", stamps, ranges, *scan, tf_poses=poses, static_mount=(0.0, 0.0, 0.0))
    shutil.copy(next((tmp / "mcap").glob("*.mcap")), d / "run.mcap")
    bag_maker.write_bag(d / "run", "sqlite3", stamps, ranges, *scan)

    messages = bag_maker._Messages(ros1=True)
    with bag_maker._Writer(d / "run.bag", "rosbag1", messages) as w:
        w.connection("/front/scan", bag_maker.LASER_SCAN)
        t0 = bag_maker.stamp_ns(stamps[0])
        w.write("/tf_static", bag_maker.TF_MESSAGE, t0,
                messages.tf_message([messages.transform(stamps[0], "base_link", "laser", 0.0, 0.0, 0.0)]))
        for t, r, p in zip(stamps, ranges, poses.tolist()):
            ns = bag_maker.stamp_ns(t)
            w.write("/tf", bag_maker.TF_MESSAGE, ns,
                    messages.tf_message([messages.transform(t, "odom", "base_link", *p)]))
            w.write("/odom", bag_maker.ODOMETRY, ns, messages.odometry(t, "odom", "base_link", *p))
            w.write("/front/scan", bag_maker.LASER_SCAN, ns, messages.laser_scan(t, "laser", r, *scan))
    shutil.rmtree(tmp)
    write_g2o(d / "optimized.g2o", poses)
    write_tum(d / "optimized.txt", stamps, poses)


def fixture_bags(d, intel):
    make_bags(d, intel)


def fixture_logs(d, intel):
    """logs/: the bundled logs, as the repository root has them."""
    (d / "logs").symlink_to(LOGS, target_is_directory=True)


FIXTURES = {"bags": fixture_bags, "logs": fixture_logs}


# --- tools on PATH --------------------------------------------------------------------------

LOG2MAP_STANDIN = """\
import sys
import vasco_gpu as vg
args = [a for a in sys.argv[1:] if not a.startswith("-")]
log = vg.load_log(args[0])
m = vg.Mapper(log.params, backend="cpu_threads")
m.insert(log.scans)
finished = m.finish()
for out in args[1:]:
    vg.write_map(out, finished)
"""


def find_log2map():
    for d in (os.environ.get("VASCO_BIN"), ROOT / "build" / "bin", Path(sys.executable).parent):
        if d and (Path(d) / "log2map").is_file():
            return Path(d) / "log2map"
    found = shutil.which("log2map")
    return Path(found) if found else None


# The console scripts the blocks use, as pyproject.toml's [project.scripts] names them.
CONSOLE_SCRIPTS = {"bag2map": ("vasco_gpu.bags.cli", "bag2map_main"),
                   "bag2carmen": ("vasco_gpu.bags.cli", "bag2carmen_main"),
                   "carmen2bag": ("vasco_gpu.bags.carmen2bag", "main")}


def tool_dir(d: Path) -> Path:
    """python, python3, bag2map, bag2carmen, carmen2bag and log2map for the blocks' commands: this
    interpreter, the console scripts beside it (else their entry points under it), the
    build's log2map (else a stand-in through the package)."""
    tools = d / ".tools"
    tools.mkdir()
    for name in ("python", "python3"):
        # A script, not a link: a link to a virtual environment's python starts outside it.
        (tools / name).write_text(f"#!/bin/sh\nexec '{sys.executable}' \"$@\"\n")
        (tools / name).chmod(0o755)
    for name, (module, entry) in CONSOLE_SCRIPTS.items():
        exe = Path(sys.executable).parent / name
        script = tools / name
        if exe.exists():
            script.symlink_to(exe)
        else:
            script.write_text(f"#!/bin/sh\nexec '{sys.executable}' -c "
                              f"'import sys; from {module} import {entry}; sys.exit({entry}())' \"$@\"\n")
            script.chmod(0o755)
    log2map = find_log2map()
    if log2map is not None:
        (tools / "log2map").symlink_to(log2map)
    else:
        (tools / "log2map_standin.py").write_text(LOG2MAP_STANDIN)
        (tools / "log2map").write_text(f"#!/bin/sh\nexec '{sys.executable}' '{tools / 'log2map_standin.py'}' \"$@\"\n")
        (tools / "log2map").chmod(0o755)
    return tools


@pytest.mark.parametrize("doc,block,check", python_blocks())
def test_readme_block(doc, block, check, tmp_path, monkeypatch, intel):
    for module in check.needs:
        pytest.importorskip(module)
    if check.fixture:
        FIXTURES[check.fixture](tmp_path, intel)
    # The package as this process imports it, for the blocks' processes too (a PYTHONPATH
    # relative to the repository would not survive the chdir).
    package_root = str(Path(vg.__file__).resolve().parents[1])
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([package_root] + [
        str(Path(p).resolve()) for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
    monkeypatch.chdir(tmp_path)
    if check.kind == "run":
        env = dict(os.environ)
        env["PATH"] = f"{tool_dir(tmp_path)}{os.pathsep}{env.get('PATH', '')}"
        for offset, cmd in readme_blocks.shell_commands(block.text):
            if any(cmd.startswith(p) for p in check.skip):
                continue
            want = next((s for p, s in check.status.items() if cmd.startswith(p)), 0)
            r = subprocess.run(["bash", "-c", cmd], cwd=tmp_path, env=env,
                               capture_output=True, text=True, timeout=300)
            assert r.returncode == want, (f"{doc}:{block.content_line(offset)}: `{cmd}` exits "
                                          f"{r.returncode}, not {want}:\n{r.stderr}{r.stdout}")
    else:
        # "__main__": a block that starts worker processes guards them as a script must.
        namespace = {"__name__": "__main__"}
        exec(compile(block.text, f"{doc}:{block.line + 1}", "exec"), namespace)
        results = namespace.get("results")
        if results is not None:
            assert all(r.ok for r in results), [r.error for r in results if not r.ok]
    missing = [o for o in check.outputs if not (tmp_path / o).exists()]
    assert not missing, f"after {doc}:{block.line}, missing: {missing}"
