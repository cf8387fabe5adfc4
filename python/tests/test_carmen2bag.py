"""carmen2bag (vasco_gpu.bags.carmen2bag): the bundled intel log as a bag in each format, mapped
by bag2map and compared with log2map's map of the log; the --cloud bag's structure; errors and
the atomic output; the walkthrough of docs/walkthrough-bag.md run as written.

How close the bag's map is to the log's: the bag carries the log's ranges bit for bit (those
CARMEN's mapper skips, 50 m and beyond, as +inf, which bag2map skips as well), the laser poses
through a quaternion (a few ulps in the heading) and the beam angles as float32, LaserScan's
field type. That is the situation test_bags.py's module docstring argues about for bags that
bag_maker.py writes from the same log: every beam turns by less than 2.4e-7 rad, a beam end
under 50 m moves by less than 12 um, so a map cell changes only where a beam ends that close
to a cell border, at most ~0.4 % of intel's map cells. The same bound holds here
(ANGLE_BOUND = 0.5 % of the cells); intel's bag has differed in 5 cells, by about 6e-8 in p.
"""

from __future__ import annotations

import gzip
import importlib.util
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")

import vasco_gpu as vg  # noqa: E402
from vasco_gpu.bags import bag_writer as c2b  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
INTEL = ROOT / "logs" / "intel.gfs.log.gz"
WALKTHROUGH = ROOT / "docs" / "walkthrough-bag.md"
EXTENSIONS = (".bag", ".mcap", ".db3")
# The share of map cells the bag's map may differ in from the log's (module docstring).
ANGLE_BOUND = 0.005

ENTRIES = {"carmen2bag": "vasco_gpu.bags.carmen2bag:main", "bag2map": "vasco_gpu.bags.cli:bag2map_main",
           "bag2carmen": "vasco_gpu.bags.cli:bag2carmen_main"}


def script_command(name):
    """The console script as pip installs it, else its entry point under this interpreter."""
    exe = Path(sys.executable).parent / name
    if exe.exists():
        return [str(exe)]
    module, func = ENTRIES[name].split(":")
    return [sys.executable, "-c", f"import sys; from {module} import {func}; sys.exit({func}())"]


def run_script(name, *args, cwd=None):
    return subprocess.run(script_command(name) + [str(a) for a in args], capture_output=True, text=True,
                          timeout=300, cwd=cwd)


def tool_bin():
    """The build's directory of log2map and mapdiff (VASCO_BIN, build/bin, PATH), or None."""
    for d in (os.environ.get("VASCO_BIN"), ROOT / "build" / "bin", Path(sys.executable).parent):
        if d and (Path(d) / "log2map").is_file() and (Path(d) / "mapdiff").is_file():
            return Path(d).resolve()
    found = shutil.which("log2map")
    return Path(found).parent if found and shutil.which("mapdiff") else None


# A bag's default map cell (bag2map's --resolution): ROS's 0.05 m, where the log's keys give 0.1.
BAG_CELL = 0.05


@pytest.fixture(scope="module")
def intel():
    return vg.load_log(INTEL)


@pytest.fixture(scope="module")
def log_map(tmp_path_factory):
    """log2map's map of intel at a bag's default cell: the program's when built, else the same
    engine through the package (what log2map writes on an exact backend)."""
    bin_dir = tool_bin()
    if bin_dir is not None:
        out = tmp_path_factory.mktemp("log2map") / "intel.map.gz"
        subprocess.run([str(bin_dir / "log2map"), "-q", "--backend", "cpu_threads", "--resolution", str(BAG_CELL),
                        str(INTEL), str(out)], check=True, capture_output=True, timeout=300)
        return vg.read_map(out)
    log = vg.load_log(INTEL, map_resolution=BAG_CELL)
    m = vg.Mapper(log.params, backend="cpu_double")
    m.insert(log.scans)
    return m.finish()


def assert_within_angle_bound(want, got):
    assert got.shape == want.shape
    c = vg.compare(want, got)
    assert c.differing_cells <= ANGLE_BOUND * c.cells, (c.differing_cells, c.cells)
    return c


def bag_messages(path):
    """{topic: [(msgtype, message)]} of a bag, read with rosbags."""
    from rosbags.highlevel import AnyReader

    out = {}
    with AnyReader([Path(path)]) as reader:
        for conn, _, raw in reader.messages():
            out.setdefault(conn.topic, []).append((conn.msgtype, reader.deserialize(raw, conn.msgtype)))
    return out


@pytest.mark.parametrize("ext", EXTENSIONS)
def test_each_format_maps_as_the_log(tmp_path, intel, log_map, ext):
    bag = tmp_path / f"intel{ext}"
    r = run_script("carmen2bag", INTEL, bag)
    assert r.returncode == 0, r.stderr
    assert f"910 scans -> {bag}" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [bag.name]  # no temporary left
    r = run_script("bag2map", "-q", bag, tmp_path / "bag.map.gz")
    assert r.returncode == 0, r.stderr
    assert_within_angle_bound(log_map, vg.read_map(tmp_path / "bag.map.gz"))


def test_the_bag_holds_the_logs_scans(tmp_path, intel):
    bag = tmp_path / "intel.mcap"
    c2b.write_bag(intel, bag)
    read = vg.load_bag(bag)
    assert len(read) == len(intel)
    # The bag is in time order, the log in line order (intel's stamps go back now and then).
    order = np.argsort(intel.stamps, kind="stable")
    assert not np.array_equal(order, np.arange(len(intel)))
    want = np.concatenate([intel.scans.ranges_of(int(s)) for s in order])
    skipped = ~(want < 50)
    got = read.ranges
    assert np.array_equal(got[~skipped], want[~skipped])  # every reading CARMEN uses, bit for bit
    assert skipped.sum() > 0 and np.all(np.isinf(got[skipped]))  # the rest +inf: skipped too
    d = read.poses - intel.poses[order]
    d[:, 2] = (d[:, 2] + np.pi) % (2 * np.pi) - np.pi
    assert np.abs(d).max() < 1e-12
    msgs = bag_messages(bag)
    assert sorted(msgs) == ["/scan", "/tf", "/tf_static"]
    msgtype, scan = msgs["/scan"][0]
    assert msgtype == "sensor_msgs/msg/LaserScan" and scan.header.frame_id == "laser"
    assert scan.angle_min == float(np.float32(intel.scans.first_angle[0]))
    assert scan.angle_increment == float(np.float32(intel.scans.angle_step[0]))
    assert scan.range_min == 0.0 and scan.range_max == c2b.RANGE_MAX and np.float32(scan.range_max) < 50
    (static,) = msgs["/tf_static"]
    t = static[1].transforms[0]
    assert (t.header.frame_id, t.child_frame_id) == ("base_link", "laser")
    assert (t.transform.translation.x, t.transform.rotation.w) == (0.0, 1.0)
    assert {m.transforms[0].header.frame_id + ">" + m.transforms[0].child_frame_id for _, m in msgs["/tf"]} == {
        "map>base_link"}
    # Stamps: the log's, in time order (intel's go back now and then).
    stamps = [s.header.stamp.sec + s.header.stamp.nanosec * 1e-9 for _, s in msgs["/scan"]]
    assert stamps == sorted(stamps)
    assert np.allclose(sorted(stamps), np.sort(intel.stamps), atol=1e-9, rtol=0)


def test_cloud_has_walls_floor_and_ceiling(tmp_path, intel):
    bag = tmp_path / "cloud.bag"
    r = run_script("carmen2bag", "--cloud", INTEL, bag)
    assert r.returncode == 0, r.stderr
    assert "PointCloud2 on /points" in r.stderr
    msgs = bag_messages(bag)
    assert sorted(msgs) == ["/points", "/tf", "/tf_static"]
    clouds = msgs["/points"]
    assert len(clouds) == len(intel)
    order = np.argsort(intel.stamps, kind="stable")
    for k in (0, 1, len(clouds) // 2, len(clouds) - 1):
        msgtype, c = clouds[k]
        s = int(order[k])
        assert msgtype == "sensor_msgs/msg/PointCloud2" and c.header.frame_id == "laser"
        assert [(f.name, f.offset, f.datatype, f.count) for f in c.fields] == [
            ("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 8, 7, 1)]
        assert (c.height, c.point_step, c.row_step, c.is_bigendian) == (1, 12, 12 * c.width, False)
        pts = np.frombuffer(bytes(c.data), dtype="<f4").reshape(-1, 3)
        r_ = intel.scans.ranges_of(s)
        used = np.isfinite(r_) & (r_ < 50)
        assert c.width == len(pts) == 3 * used.sum()
        z = pts[:, 2]
        assert np.array_equal(z[0::3], np.full(used.sum(), 0.5, np.float32))  # beam ends
        assert np.array_equal(z[1::3], np.zeros(used.sum(), np.float32))  # floor
        assert np.array_equal(z[2::3], np.full(used.sum(), 2.5, np.float32))  # ceiling
        a = intel.scans.first_angle[s] + np.arange(len(r_)) * intel.scans.angle_step[s]
        ends = pts[0::3, :2].astype(np.float64)
        assert np.allclose(np.hypot(ends[:, 0], ends[:, 1]), r_[used], atol=1e-5, rtol=0)
        assert np.allclose(np.arctan2(ends[:, 1], ends[:, 0]), np.arctan2(np.sin(a[used]), np.cos(a[used])),
                           atol=1e-5)
        assert np.allclose(pts[1::3, :2] * 2, pts[0::3, :2], atol=1e-5)
    # A z band around the beam ends keeps exactly them.
    pts = np.frombuffer(bytes(clouds[0][1].data), dtype="<f4").reshape(-1, 3)
    band = (pts[:, 2] > 0.25) & (pts[:, 2] < 1.0)
    assert band.sum() * 3 == len(pts)


def small_log(path, stamps):
    """A log of intel's first FLASER lines with the given ipc stamps."""
    with gzip.open(INTEL, "rt") as f:
        lines = [ln.split() for ln in f if ln.startswith("FLASER ")][:len(stamps)]
    for t, s in zip(lines, stamps):
        t[-3] = s
    path.write_text("".join(" ".join(t) + "\n" for t in lines))
    return path


def test_shared_stamps_need_a_period(tmp_path, intel):
    log = small_log(tmp_path / "same.log", ["5.0", "5.5", "5.5", "6.0"])
    r = run_script("carmen2bag", log, tmp_path / "out.bag")
    assert r.returncode == 1
    assert f"{log}: line 3: the scan has the stamp 5.5 of line 2" in r.stderr and "--period" in r.stderr
    assert not (tmp_path / "out.bag").exists()
    r = run_script("carmen2bag", "-q", "--period", "0.1", log, tmp_path / "out.bag")
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    stamps = [m.header.stamp for _, m in bag_messages(tmp_path / "out.bag")["/scan"]]
    assert [(s.sec, s.nanosec) for s in stamps] == [(0, 100000000), (0, 200000000), (0, 300000000),
                                                      (0, 400000000)]
    assert len(vg.load_bag(tmp_path / "out.bag")) == 4


def test_usage_and_errors_name_the_file(tmp_path):
    for args in ([], [INTEL], [INTEL, tmp_path / "x.txt"], ["--period", "0", INTEL, tmp_path / "x.bag"],
                 ["--topic", "scan", INTEL, tmp_path / "x.bag"], ["--bogus", INTEL, tmp_path / "x.bag"]):
        assert run_script("carmen2bag", *args).returncode == 2, args
    r = run_script("carmen2bag", INTEL, tmp_path / "x.txt")
    assert f"{tmp_path / 'x.txt'}: expected a .bag" in r.stderr
    assert run_script("carmen2bag", "--help").returncode == 0
    missing = tmp_path / "nope.log"
    r = run_script("carmen2bag", missing, tmp_path / "x.bag")
    assert r.returncode == 1 and str(missing) in r.stderr
    bad = tmp_path / "bad.log"
    bad.write_text("FLASER 3 1 2\n")
    r = run_script("carmen2bag", bad, tmp_path / "x.bag")
    assert r.returncode == 1 and f"{bad}:1" in r.stderr, r.stderr
    r = run_script("carmen2bag", INTEL, tmp_path / "no" / "dir" / "x.mcap")
    assert r.returncode == 1 and str(tmp_path / "no" / "dir" / "x.mcap") in r.stderr
    (tmp_path / "d.bag").mkdir()
    r = run_script("carmen2bag", INTEL, tmp_path / "d.bag")
    assert r.returncode == 1 and "is a directory" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.log", "d.bag"]  # nothing else written


def test_output_is_replaced_whole_or_not_at_all(tmp_path, intel):
    out = tmp_path / "run.db3"
    out.write_bytes(b"yesterday")
    # A log that fails after reading (shared stamps) leaves the old file as it was.
    log = small_log(tmp_path / "same.log", ["1.0", "1.0"])
    assert run_script("carmen2bag", log, out).returncode == 1
    assert out.read_bytes() == b"yesterday"
    assert run_script("carmen2bag", "-q", INTEL, out).returncode == 0
    assert len(vg.load_bag(out)) == len(intel)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.db3", "same.log"]


@pytest.mark.parametrize("ext", EXTENSIONS)
def test_a_writer_that_fails_part_way_leaves_nothing(tmp_path, intel, monkeypatch, ext):
    out = tmp_path / f"run{ext}"
    out.write_bytes(b"yesterday")
    real = c2b._write_messages

    def half(w, log, ns, cloud, topic):  # the messages written, then the writer fails
        real(w, log, ns, cloud, topic)
        raise RuntimeError("disk gone")

    monkeypatch.setattr(c2b, "_write_messages", half)
    with pytest.raises(c2b.Carmen2BagError, match="disk gone") as e:
        c2b.write_bag(intel, out)
    assert isinstance(e.value, vg.Error) and str(e.value).startswith(str(out))
    assert out.read_bytes() == b"yesterday"
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # no scratch bag, no temporary


@pytest.mark.parametrize("ext", EXTENSIONS)
def test_a_run_ended_by_a_signal_leaves_nothing(tmp_path, ext):
    # SIGTERM once the bag is in its scratch path: the handlers remove it and the transaction's
    # temporary, and the process dies of the signal.
    out = tmp_path / f"run{ext}"
    out.write_bytes(b"yesterday")
    code = ("import os, signal, sys\n"
            "from vasco_gpu.bags import bag_writer, carmen2bag\n"
            "real = bag_writer._write_messages\n"
            "def then_killed(*args):\n"
            "    real(*args)\n"
            "    os.kill(os.getpid(), signal.SIGTERM)\n"
            "bag_writer._write_messages = then_killed\n"
            "sys.exit(carmen2bag.main(sys.argv[1:]))\n")
    r = subprocess.run([sys.executable, "-c", code, str(INTEL), str(out)], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == -signal.SIGTERM, r.stderr
    assert out.read_bytes() == b"yesterday"
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


def test_walkthrough_runs(tmp_path):
    """docs/walkthrough-bag.md's shell block, each command as written (readme_checks.py points
    here): the package's console scripts and the build's log2map and mapdiff on PATH, the
    bundled logs under logs/."""
    bin_dir = tool_bin()
    if bin_dir is None:
        pytest.skip("log2map and mapdiff are not built (VASCO_BIN, build/bin, PATH)")
    blocks = sys.modules.get("readme_blocks")
    if blocks is None:
        spec = importlib.util.spec_from_file_location("readme_blocks", ROOT / "tests" / "docs" / "readme_blocks.py")
        blocks = importlib.util.module_from_spec(spec)
        sys.modules["readme_blocks"] = blocks  # its dataclasses look their module up
        spec.loader.exec_module(blocks)
    shell = [b for b in blocks.read_blocks(WALKTHROUGH) if b.key.startswith("sh:")]
    assert len(shell) == 1, [b.key for b in shell]
    tools = tmp_path / ".tools"
    tools.mkdir()
    for name in ENTRIES:
        (tools / name).write_text("#!/bin/sh\nexec " + " ".join(f"'{a}'" for a in script_command(name)) + ' "$@"\n')
        (tools / name).chmod(0o755)
    for name in ("log2map", "mapdiff"):
        (tools / name).symlink_to(bin_dir / name)
    (tmp_path / "logs").symlink_to(ROOT / "logs", target_is_directory=True)
    env = dict(os.environ, PATH=f"{tools}{os.pathsep}{os.environ.get('PATH', '')}")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(vg.__file__).resolve().parents[1])] + [
        p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])
    for offset, cmd in blocks.shell_commands(shell[0].text):
        r = subprocess.run(["bash", "-c", cmd], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, f"{WALKTHROUGH.name}:{shell[0].content_line(offset)}: `{cmd}`:\n{r.stderr}{r.stdout}"
    for name in ("intel.mcap", "bag.map.gz", "bag.pgm", "bag.yaml", "log.map.gz", "log.pgm", "intel.bag",
                 "cloud.mcap"):
        assert (tmp_path / name).is_file(), name
