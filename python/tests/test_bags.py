"""ROS bags made here from the bundled intel log (ROS 1 .bag, ROS 2 sqlite3 and MCAP, with
rosbags' writers) through load_bag, bag2map and bag2carmen: the map against the map of the
CARMEN log itself, and poses from pose files.

How close a bag's map can be to the log's: a LaserScan carries angle_min and angle_increment
as float32, while CARMEN's angles are doubles (-pi/2 and pi/180 for intel's 180 beams). The
start angle moves by |float32(pi/2) - pi/2| = 4.4e-8 rad, the step by at most 2^-24 of pi/180
(1.0e-9 rad) per beam, 1.9e-7 rad over 179 steps: every beam by less than 2.4e-7 rad. A tf
pose goes through a quaternion (yaw -> (sin, cos) of half of it -> atan2), which moves a
heading by a few ulps and wraps it into (-pi, pi]: both change cos and sin by ~1e-15.
A beam end (r < 50 m) moves by less than 50 m x 2.4e-7 = 1.2e-5 m, 4.8e-4 of intel's 2.5 cm
cells: its end cell changes only where it lies that close to a cell border, for at most
2 x 4.8e-4 ~ 1e-3 of the beams (x or y border), ~160 of intel's 160 000. Such a beam changes
at most the ~10 cells at its end (the wall is 0.2 m: 8 cells, plus the end and the cell
before), which are at most 3 cells of the finished map (4 x 4 blocks) each: ~500 of intel's
128 000 map cells, 0.4 %. The tests accept 0.5 % differing cells; a bag that bag_maker.py writes from intel has differed
in 5 cells, by about 6e-8.
Where only the laser's poses pass (a g2o file printed with 17 digits, bag2carmen's log) the
maps are compared bit for bit.
"""

from __future__ import annotations

import math
import os
import shutil
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")

import vasco_gpu as vg  # noqa: E402
from vasco_gpu.bags.errors import BagWarning  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bag_maker  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
INTEL = ROOT / "logs" / "intel.gfs.log.gz"
FORMATS = bag_maker.FORMATS
# The share of map cells a bag's map may differ in from the log's (module docstring).
ANGLE_BOUND = 0.005


# A bag's default map cell (bag2map's --resolution, load_bag's map_resolution): ROS's 0.05 m,
# where a CARMEN log's own keys give 0.1 m.
BAG_CELL = 0.05


@pytest.fixture(scope="module")
def intel():
    """The log, its parameters at a bag's default cell: the maps a bag of it should give."""
    return vg.load_log(INTEL, map_resolution=BAG_CELL)


@pytest.fixture(scope="module")
def intel_map(intel):
    return finished(intel)


def finished(log, backend="cpu_double"):
    m = vg.Mapper(log.params, backend=backend)
    m.insert(log.scans)
    return m.finish()


def scan_stamps(n):
    # intel's own stamps go back now and then; a recorder's header stamps increase.
    return 1000.0 + 0.2 * np.arange(n)


def make_bag(tmp_path, fmt, log, name="intel", first=0, count=None, **poses):
    s = log.scans.select(first, -1 if count is None else count)
    n = len(s)
    ranges = [s.ranges_of(i).copy() for i in range(n)]
    path = bag_maker.bag_path(tmp_path, fmt, name)
    return bag_maker.write_bag(path, fmt, scan_stamps(log.scans.__len__())[first:first + n], ranges,
                               float(s.first_angle[0]), float(s.angle_step[0]), 0.0, 81.91, **poses)


def tf_bag(tmp_path, fmt, log, **kw):
    """map -> base_link on /tf at every scan, base_link -> laser identity on /tf_static."""
    first, count = kw.get("first", 0), kw.get("count")
    poses = log.poses[first:None if count is None else first + count]
    return make_bag(tmp_path, fmt, log, tf_poses=poses, static_mount=(0.0, 0.0, 0.0), **kw)


def assert_within_angle_bound(want, got):
    c = vg.compare(want, got)
    assert got.shape == want.shape
    assert c.differing_cells <= ANGLE_BOUND * c.cells, (c.differing_cells, c.cells)
    return c


def g17(v: float) -> str:
    return "%.17g" % v


def run_script(name, *args):
    """The console script as pip installs it, else its entry point under this interpreter."""
    exe = Path(sys.executable).parent / name
    entry = {"bag2map": "bag2map_main", "bag2carmen": "bag2carmen_main"}[name]
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-c",
                                            f"import sys; from vasco_gpu.bags.cli import {entry}; sys.exit({entry}())"]
    return subprocess.run(cmd + [str(a) for a in args], capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("fmt", FORMATS)
def test_tf_bag_maps_as_the_log(tmp_path, intel, intel_map, fmt):
    bag = vg.load_bag(tf_bag(tmp_path, fmt, intel))
    assert len(bag) == len(intel)
    assert np.array_equal(bag.ranges, intel.ranges)  # float32 ranges pass unchanged
    # Headings wrapped into (-pi, pi] by the quaternion; equal up to that and a few ulps.
    d = bag.poses - intel.poses
    d[:, 2] = (d[:, 2] + math.pi) % (2 * math.pi) - math.pi
    assert np.abs(d).max() < 1e-12
    assert_within_angle_bound(intel_map, finished(bag))


def test_odometry_topic_and_a_mount(tmp_path, intel, intel_map):
    # The robot 0.1 m behind the laser, turned by 0.05 rad: base = laser o inverse(mount).
    mx, my, ma = 0.1, 0.0, 0.05
    lp = intel.poses
    bth = lp[:, 2] - ma
    bx = lp[:, 0] - (np.cos(bth) * mx - np.sin(bth) * my)
    by = lp[:, 1] - (np.sin(bth) * mx + np.cos(bth) * my)
    path = make_bag(tmp_path, "mcap", intel, odom_poses=np.stack([bx, by, bth], axis=1), static_mount=(mx, my, ma))
    bag = vg.load_bag(path, pose_topic="/odom")
    d = bag.poses - lp
    d[:, 2] = (d[:, 2] + math.pi) % (2 * math.pi) - math.pi
    assert np.abs(d).max() < 1e-9  # the mount's round trip: a few ulps of 10 m
    assert_within_angle_bound(intel_map, finished(bag))


def write_g2o(path, poses):
    with open(path, "w") as f:
        for i, (x, y, t) in enumerate(poses):
            f.write(f"VERTEX_SE2 {i} {g17(x)} {g17(y)} {g17(t)}\n")
    return path


def test_pose_file_gives_the_laser_poses_bit_for_bit(tmp_path, intel, intel_map):
    path = make_bag(tmp_path, "rosbag1", intel)  # no tf at all: the poses come from the file
    bag = vg.load_bag(path, poses=write_g2o(tmp_path / "opt.g2o", intel.poses))
    assert bag.posed_from_file == len(intel)
    assert np.array_equal(bag.poses, intel.poses)
    assert_within_angle_bound(intel_map, finished(bag))


def test_bag2carmen_log_maps_as_the_bag_bit_for_bit(tmp_path, intel):
    path = tf_bag(tmp_path, "sqlite3", intel)
    out = tmp_path / "from_bag.log.gz"
    r = run_script("bag2carmen", path, out)
    assert r.returncode == 0, r.stderr
    bag, log = vg.load_bag(path), vg.load_log(out, map_resolution=BAG_CELL)
    assert np.array_equal(log.poses, bag.poses)
    assert np.array_equal(log.ranges, bag.ranges)
    assert np.array_equal(log.scans.first_angle, bag.scans.first_angle)
    assert np.array_equal(log.scans.angle_step, bag.scans.angle_step)
    assert np.array_equal(log.stamps, bag.stamps)
    assert finished(log).sha256() == finished(bag).sha256()
    assert sorted(os.listdir(tmp_path)) == sorted(["from_bag.log.gz", Path(path).name])  # no temporary left


@pytest.mark.parametrize("fmt", ["mcap", "rosbag1"])
def test_bag2map_writes_the_logs_map(tmp_path, intel_map, intel, fmt):
    path = tf_bag(tmp_path, fmt, intel)
    out = tmp_path / "bag.map.gz"
    r = run_script("bag2map", "--backend", "cpu_double", path, out, tmp_path / "bag.pgm")
    assert r.returncode == 0, r.stderr
    assert "910 scans" in r.stderr
    assert (tmp_path / "bag.yaml").exists()
    assert_within_angle_bound(intel_map, vg.read_map(out))


def test_bag2map_poses_from_a_file_and_two_sessions(tmp_path, intel):
    # Two halves of intel as two bags, their poses from one pose file per bag: first the
    # halves through --add, then the whole as one bag; the same cells bit for bit.
    whole = make_bag(tmp_path, "mcap", intel, name="whole", tf_poses=intel.poses, static_mount=(0.0, 0.0, 0.0))
    a = tf_bag(tmp_path, "mcap", intel, name="a", first=0, count=400)
    b = tf_bag(tmp_path, "mcap", intel, name="b", first=400)
    r = run_script("bag2map", "--backend", "cpu_threads", a, "--add", b, tmp_path / "ab.map")
    assert r.returncode == 0, r.stderr
    r = run_script("bag2map", "--backend", "cpu_threads", whole, tmp_path / "whole.map")
    assert r.returncode == 0, r.stderr
    assert vg.read_map(tmp_path / "ab.map").sha256() == vg.read_map(tmp_path / "whole.map").sha256()


def test_bag2map_with_a_g2o_file_equals_load_bag(tmp_path, intel):
    path = make_bag(tmp_path, "sqlite3", intel)
    g2o = write_g2o(tmp_path / "opt.g2o", intel.poses)
    r = run_script("bag2map", "--backend", "cpu_double", "--poses", g2o, path, tmp_path / "m.map")
    assert r.returncode == 0, r.stderr
    assert "poses from" in r.stderr
    assert vg.read_map(tmp_path / "m.map").sha256() == finished(vg.load_bag(path, poses=g2o)).sha256()


def test_bag2map_errors_name_the_bag(tmp_path, intel):
    path = tf_bag(tmp_path, "mcap", intel)
    r = run_script("bag2map", "--scan-topic", "/front_scan", path, tmp_path / "x.map")
    assert r.returncode == 1
    assert str(path) in r.stderr and "/front_scan" in r.stderr
    not_a_bag = tmp_path / "notes.bag"
    not_a_bag.write_text("not a bag\n")
    r = run_script("bag2map", not_a_bag, tmp_path / "x.map")
    assert r.returncode == 1 and "notes.bag" in r.stderr
    r = run_script("bag2map", "--no-such-option", path, tmp_path / "x.map")
    assert r.returncode == 2
    r = run_script("bag2map", "--fixed-frame", "world", path, tmp_path / "x.map")
    assert r.returncode == 1 and "world" in r.stderr
    assert not (tmp_path / "x.map").exists()
    r = run_script("bag2carmen", path, tmp_path / "x.txt")
    assert r.returncode == 2


def test_bag2carmen_writes_through_the_engines_output_file(tmp_path, intel):
    # The log is written as every map is (atomic_file.h): a FIFO target is refused and left as it
    # is, and a new file gets 0666 less the umask (not a private temporary's 0600).
    path = tf_bag(tmp_path, "mcap", intel, count=50)
    fifo = tmp_path / "pipe.log"
    os.mkfifo(fifo)
    r = run_script("bag2carmen", path, fifo)
    assert r.returncode == 1 and "pipe.log" in r.stderr, r.stderr
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    umask = os.umask(0o022)
    try:
        r = run_script("bag2carmen", path, tmp_path / "plain.log")
    finally:
        os.umask(umask)
    assert r.returncode == 0, r.stderr
    assert stat.S_IMODE(os.stat(tmp_path / "plain.log").st_mode) == 0o644
    assert sorted(os.listdir(tmp_path)) == sorted(["pipe.log", "plain.log", Path(path).name])  # no temporary


def test_bag2carmen_leaves_no_temporary_on_a_signal(tmp_path, intel):
    # SIGTERM, SIGINT or SIGHUP while the log's temporary is written: the process dies of it and
    # the temporary goes (the engine's handlers); the target, had it existed, would be unchanged.
    path = tf_bag(tmp_path, "mcap", intel)
    out = tmp_path / "out" / "x.log"
    out.parent.mkdir()
    code = "import sys; from vasco_gpu.bags.cli import bag2carmen_main; sys.exit(bag2carmen_main())"
    caught = 0
    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP) * 3:
        proc = subprocess.Popen([sys.executable, "-c", code, "-q", str(path), str(out)], stderr=subprocess.DEVNULL)
        end = time.monotonic() + 60
        while proc.poll() is None and time.monotonic() < end and not any(
                p.name.startswith(".x.log.tmp.") for p in out.parent.iterdir()):
            time.sleep(0.0005)
        if proc.poll() is None:
            proc.send_signal(sig)
        rc = proc.wait(60)
        if rc == -sig:
            caught += 1
        assert rc in (0, -sig), rc
        assert [p.name for p in out.parent.iterdir()] in ([], ["x.log"]), list(out.parent.iterdir())
        if out.exists():
            out.unlink()
    assert caught > 0, "no run was caught while writing: the test saw nothing"


def test_bag2map_batch_mode_gives_each_bags_map(tmp_path, intel):
    # log2map's --out-dir through bag2map: bags of two formats mapped in one process, each to
    # the map its own bag2map run writes; a file that is no bag reported and skipped (exit 1).
    first = tf_bag(tmp_path, "mcap", intel, name="first", count=500)
    second = tf_bag(tmp_path, "rosbag1", intel, name="second", first=500)
    not_a_bag = tmp_path / "notes.bag"
    not_a_bag.write_text("not a bag\n")
    out = tmp_path / "maps"
    r = run_script("bag2map", "--backend", "cpu_threads", "--out-dir", out, "--formats", "map,pgm",
                   first, not_a_bag, second)
    assert r.returncode == 1, r.stderr
    assert "2 of 3 inputs mapped" in r.stderr and "notes.bag" in r.stderr
    assert sorted(os.listdir(out)) == ["first.map", "first.pgm", "first.yaml", "second.map", "second.pgm", "second.yaml"]
    for bag, stem in ((first, "first"), (second, "second")):
        one = tmp_path / f"{stem}_one.map"
        r = run_script("bag2map", "--backend", "cpu_threads", bag, one)
        assert r.returncode == 0, r.stderr
        want, got = vg.read_map(one), vg.read_map(out / f"{stem}.map")
        assert got.shape == want.shape and np.array_equal(got.cells, want.cells), stem


def test_no_return_free_clears_space(tmp_path, intel):
    # Every reading at or beyond 50 m is +inf in this bag: skipped, CARMEN's way, or free
    # up to vasco_range_max, the ROS mappers' way, which knows more cells.
    s = intel.scans
    ranges = [np.where(s.ranges_of(i) >= 50, np.float32(np.inf), s.ranges_of(i)).astype(np.float32)
              for i in range(len(s))]
    assert sum(int(np.isinf(r).sum()) for r in ranges) > 1000
    path = bag_maker.write_bag(bag_maker.bag_path(tmp_path, "mcap"), "mcap", scan_stamps(len(s)), ranges,
                               float(s.first_angle[0]), float(s.angle_step[0]), 0.0, 81.91,
                               tf_poses=intel.poses, static_mount=(0.0, 0.0, 0.0))
    skip = finished(vg.load_bag(path))
    free = finished(vg.load_bag(path, no_return="free"))
    known = lambda m: int((m.cells != -1).sum())
    assert known(free) > known(skip)
    assert_within_angle_bound(finished(intel), skip)  # skip: the log's own semantics


def test_load_bag_errors(tmp_path, intel):
    path = tf_bag(tmp_path, "rosbag1", intel)
    with pytest.raises(vg.FileError) as e:
        vg.load_bag(path, fixed_frame="world")
    assert e.value.file == str(path) and "world" in str(e.value)
    with pytest.raises(vg.FileError):
        vg.load_bag(tmp_path / "missing.bag")
    with pytest.raises(vg.UsageError):
        vg.load_bag(path, pose_tolerance=0.5)  # a pose option without poses=


def test_pgm_and_yaml_as_nav2_map_server_reads_them(tmp_path, intel):
    """map_server (nav2_map_server's map_io) reads the YAML's image (relative to the YAML),
    resolution, origin, negate, occupied_thresh, free_thresh and mode, and in trinary mode
    turns a pixel v into p = (255 - v) / 255: occupied above occupied_thresh, free below
    free_thresh, else unknown. Done here by hand, against the map's own cells."""
    yaml = pytest.importorskip("ruamel.yaml")
    path = tf_bag(tmp_path, "mcap", intel)
    r = run_script("bag2map", "--backend", "cpu_double", path, tmp_path / "map.pgm", tmp_path / "map.map")
    assert r.returncode == 0, r.stderr
    y = yaml.YAML(typ="safe").load((tmp_path / "map.yaml").read_text())
    assert set(y) >= {"image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh", "mode"}
    assert y["mode"] == "trinary" and y["negate"] == 0
    m = vg.read_map(tmp_path / "map.map")
    assert y["resolution"] == pytest.approx(m.resolution)
    assert y["origin"][:2] == pytest.approx(list(m.origin[:2]))
    data = (tmp_path / y["image"]).read_bytes()
    fields = data.split(maxsplit=4)  # P5, width, height, maxval, pixels
    assert fields[0] == b"P5"
    w, h = int(fields[1]), int(fields[2])
    assert (w, h) == (m.size_x, m.size_y)
    pixels = np.frombuffer(data[len(data) - w * h:], dtype=np.uint8).reshape(h, w)
    p = (255.0 - pixels) / 255.0
    ros = np.where(p > y["occupied_thresh"], 100, np.where(p < y["free_thresh"], 0, -1))
    cells = m.image  # row 0 at the top, as the PGM
    want = np.where(cells == -1, -1, np.where(cells > 0.65, 100, np.where(cells < 0.196, 0, -1)))
    assert np.array_equal(ros, want)
    assert (ros == 100).sum() > 1000 and (ros == 0).sum() > 10000


def test_scans_before_the_first_transform(tmp_path, intel):
    # tf starts at the 11th scan, as when a recorder starts the laser first: those scans left
    # out and counted by default, with one warning.
    n = len(intel)
    path = make_bag(tmp_path, "mcap", intel, tf_poses=intel.poses[10:], tf_stamps=scan_stamps(n)[10:],
                    static_mount=(0.0, 0.0, 0.0))
    with pytest.warns(BagWarning, match="10 scans of /scan before the first pose"):
        log = vg.load_bag(path)
    assert len(log) == n - 10 and log.unposed_skipped == 10
    with pytest.warns(BagWarning, match="10 scans"):
        log = vg.load_bag(path, skip_unposed=True)
    assert len(log) == n - 10 and log.unposed_skipped == 10
    r = run_script("bag2map", "--skip-unposed", path, tmp_path / "m.map")
    assert r.returncode == 0, r.stderr
    assert "10 scans without a pose left out (--skip-unposed)" in r.stderr
    r = run_script("bag2map", path, tmp_path / "m.map")  # the default: the edges, named as such
    assert r.returncode == 0, r.stderr
    assert "10 scans without a pose left out (before the first or after the last pose)" in r.stderr


# ----------------------------------------------------------------------------------------------
# Bags shaped like real recordings (bag_maker.Recording), each against the map of intel's log


def intel_recording(fmt, log, tf=True, mounts=None, scan=None):
    """A Recording of intel: map -> base_link on /tf at every scan stamp (the robot at the laser
    pose composed with the inverse of the scan's mount), base_link -> laser on /tf_static;
    scan(rec, k, t, ranges) writes scan k (default: a LaserScan on /scan in frame laser)."""
    rec = bag_maker.Recording(fmt)
    s, stamps = log.scans, scan_stamps(len(log))
    a0, da = float(s.first_angle[0]), float(s.angle_step[0])
    if tf:
        rec.tf(stamps[0], "base_link", "laser", 0.0, 0.0, 0.0, static=True)
        for k, (t, p) in enumerate(zip(stamps, log.poses)):
            base = p if mounts is None else robot_of(p, mounts[k])
            rec.tf(t, "map", "base_link", *base)
    for k, t in enumerate(stamps):
        if scan is None:
            rec.scan("/scan", t, "laser", s.ranges_of(k).copy(), a0, da, 0.0, 81.91)
        else:
            scan(rec, k, t, s.ranges_of(k).copy(), a0, da)
    return rec


def robot_of(laser, mount):
    """The robot pose r with r o mount = laser (planar)."""
    mx, my, ma = mount
    th = laser[2] - ma
    return (laser[0] - (math.cos(th) * mx - math.sin(th) * my), laser[1] - (math.sin(th) * mx + math.cos(th) * my), th)


def selected_map(log, first, count):
    m = vg.Mapper(log.params, backend="cpu_double")
    m.insert(log.scans.select(first, count))
    return m.finish()


@pytest.mark.parametrize("fmt", ["mcap", "rosbag1"])
def test_localisation_stack_tf_post_dated_and_odometry_ending_early(tmp_path, intel, fmt):
    # amcl's map -> odom, post-dated by its transform tolerance (0.1 s), from its first update at
    # the 6th scan on; the odometry's odom -> base_link ends 5 scans before the laser. The first
    # 6 and the last 5 scans have no pose: left out, counted, one warning; the rest is the map
    # of those scans of the log (and, bit for bit, of a bag with plain tf over just those scans).
    n, stamps = len(intel), scan_stamps(len(intel))
    rec = bag_maker.Recording(fmt)
    rec.tf(stamps[0], "base_link", "laser", 0.0, 0.0, 0.0, static=True)
    for t in stamps[5:]:
        rec.tf(t + 0.1, "map", "odom", 0.0, 0.0, 0.0, receive=t + 0.1)
    for t, p in zip(stamps[:n - 5], intel.poses[:n - 5]):
        rec.tf(t, "odom", "base_link", *p)
    s = intel.scans
    for k, t in enumerate(stamps):
        rec.scan("/scan", t, "laser", s.ranges_of(k).copy(), float(s.first_angle[0]), float(s.angle_step[0]),
                 0.0, 81.91)
    path = rec.write(bag_maker.bag_path(tmp_path, fmt, "amcl"))
    with pytest.warns(BagWarning) as caught:
        bag = vg.load_bag(path)
    assert len(caught) == 1 and "6 scans of /scan before the first pose" in str(caught[0].message)
    assert "5 after the last" in str(caught[0].message)
    assert len(bag) == n - 11 and bag.unposed_skipped == 11
    assert np.array_equal(bag.ranges, intel.scans.select(6, n - 11).ranges)
    got = finished(bag)
    assert_within_angle_bound(selected_map(intel, 6, n - 11), got)
    plain = tf_bag(tmp_path, fmt, intel, name="plain", first=6, count=n - 11)
    assert got.sha256() == finished(vg.load_bag(plain)).sha256()
    r = run_script("bag2map", "--backend", "cpu_double", path, tmp_path / "amcl.map")
    assert r.returncode == 0, r.stderr
    warnings = [line for line in r.stderr.splitlines() if "warning" in line]
    assert len(warnings) == 1 and warnings[0].startswith("bag2map: warning: ") and "6 scans" in warnings[0]
    assert vg.read_map(tmp_path / "amcl.map").sha256() == got.sha256()


def test_two_lasers_with_their_own_mounts_and_rates(tmp_path, intel, intel_map):
    # intel's scans from two lasers: /front (two scans in three) at (0.15, 0, 0) and /rear
    # (every third) at (-0.2, 0.05, pi) on the robot; /rear's messages arrive 0.25 s late, after
    # the next /front scan. Merged in stamp order they are intel's scans in intel's order.
    n = len(intel)
    front, rear = (0.15, 0.0, 0.0), (-0.2, 0.05, math.pi)
    is_rear = np.arange(n) % 3 == 1
    mounts = [rear if r else front for r in is_rear]

    def scan(rec, k, t, ranges, a0, da):
        topic, frame, receive = ("/rear", "rear", t + 0.25) if is_rear[k] else ("/front", "front", t)
        rec.scan(topic, t, frame, ranges, a0, da, 0.0, 81.91, receive=receive)

    rec = intel_recording("mcap", intel, mounts=mounts, scan=scan)
    rec.tf(1000.0, "base_link", "front", *front, static=True)
    rec.tf(1000.0, "base_link", "rear", *rear, static=True)
    path = rec.write(bag_maker.bag_path(tmp_path, "mcap", "two"))
    with pytest.raises(vg.FileError, match="several laser scan topics"):
        vg.load_bag(path)
    bag = vg.load_bag(path, scan_topic=["/front", "/rear"])
    assert len(bag) == n and np.array_equal(bag.ranges, intel.ranges)
    d = bag.poses - intel.poses
    d[:, 2] = (d[:, 2] + math.pi) % (2 * math.pi) - math.pi
    assert np.abs(d).max() < 1e-9
    got = finished(bag)
    assert_within_angle_bound(intel_map, got)
    r = run_script("bag2map", "--backend", "cpu_double", "--scan-topic", "/front", "--scan-topic=/rear", path,
                   tmp_path / "two.map")
    assert r.returncode == 0, r.stderr
    assert f"{n} scans" in r.stderr
    assert vg.read_map(tmp_path / "two.map").sha256() == got.sha256()
    r = run_script("bag2map", "--scan-topic", "/front,/rear", "--laser-mount", "0,0,0", path, tmp_path / "x.map")
    assert r.returncode == 1 and "several scan topics" in r.stderr


@pytest.mark.parametrize("fmt", ["sqlite3", "rosbag1"])
def test_multi_echo_scans_with_three_echoes(tmp_path, intel, fmt):
    # Each beam of intel with three echoes, a quarter and half of the way and at the wall, the
    # middle one the strongest; no echo where the log has 50 m or more (CARMEN skips those).
    def scan(rec, k, t, ranges, a0, da):
        echoes = [[] if r >= 50 else [r * np.float32(0.25), r * np.float32(0.5), r] for r in ranges]
        power = [[] if not e else [20.0, 100.0, 60.0] for e in echoes]
        rec.multi_echo("/echoes", t, "laser", echoes, power, a0, da, 0.0, 81.91)

    path = intel_recording(fmt, intel, scan=scan).write(bag_maker.bag_path(tmp_path, fmt, "echoes"))
    last = vg.load_bag(path)
    far = intel.ranges >= 50
    assert np.array_equal(last.ranges[~far], intel.ranges[~far]) and np.isinf(last.ranges[far]).all()
    want = finished(vg.load_bag(tf_bag(tmp_path, fmt, intel)))  # the same scans as LaserScans
    assert finished(last).sha256() == want.sha256()
    first = vg.load_bag(path, echo="first")
    assert np.array_equal(first.ranges[~far], intel.ranges[~far] * np.float32(0.25))
    strongest = vg.load_bag(path, echo="strongest")
    assert np.array_equal(strongest.ranges[~far], intel.ranges[~far] * np.float32(0.5))
    r = run_script("bag2map", "--backend", "cpu_double", "--echo", "strongest", path, tmp_path / "s.map")
    assert r.returncode == 0, r.stderr
    assert vg.read_map(tmp_path / "s.map").sha256() == finished(strongest).sha256()


def test_bad_laser_clock_and_receive_stamps(tmp_path, intel):
    # The laser driver stamps with its own clock (seconds since it started); the bag received
    # each scan at the true time, which tf shares.
    def scan(rec, k, t, ranges, a0, da):
        rec.scan("/scan", 3.0 + 0.2 * k, "laser", ranges, a0, da, 0.0, 81.91, receive=t)

    path = intel_recording("mcap", intel, scan=scan).write(bag_maker.bag_path(tmp_path, "mcap", "clock"))
    with pytest.raises(vg.FileError) as e:
        vg.load_bag(path)
    assert "none of the 910 scans" in str(e.value) and "--stamp receive" in str(e.value)
    bag = vg.load_bag(path, stamp="receive")
    good = vg.load_bag(tf_bag(tmp_path, "mcap", intel))
    assert np.array_equal(bag.stamps, good.stamps) and np.array_equal(bag.poses, good.poses)
    got = finished(bag)
    assert got.sha256() == finished(good).sha256()
    r = run_script("bag2map", "--backend", "cpu_double", "--stamp", "receive", path, tmp_path / "c.map")
    assert r.returncode == 0, r.stderr
    assert vg.read_map(tmp_path / "c.map").sha256() == got.sha256()
    r = run_script("bag2map", path, tmp_path / "d.map")
    assert r.returncode == 1 and "--stamp receive" in r.stderr


def built_log2map():
    """log2map of a build of this checkout (VASCO_BIN, build/bin, PATH), or None."""
    for d in (os.environ.get("VASCO_BIN"), ROOT / "build" / "bin", Path(sys.executable).parent):
        if d and (Path(d) / "log2map").is_file():
            return Path(d) / "log2map"
    found = shutil.which("log2map")
    return Path(found) if found else None


def test_bag2carmen_log_of_an_infinite_range_max_is_read_by_log2map(tmp_path, intel):
    # range_max = +inf (REP 117: no limit) was written as maximum_range "inf", which log2map's
    # reader (load_log's too) refuses: now the whole metre above the topic's farthest reading.
    s = intel.scans.select(0, 100)
    ranges = [s.ranges_of(i).copy() for i in range(len(s))]
    path = bag_maker.write_bag(bag_maker.bag_path(tmp_path, "mcap"), "mcap", scan_stamps(len(s)), ranges,
                               float(s.first_angle[0]), float(s.angle_step[0]), 0.0, math.inf,
                               tf_poses=intel.poses[:len(s)], static_mount=(0.0, 0.0, 0.0))
    out = tmp_path / "inf.log"
    r = run_script("bag2carmen", path, out)
    assert r.returncode == 0, r.stderr
    log, bag = vg.load_log(out, map_resolution=BAG_CELL), vg.load_bag(path)  # log2map's reader
    fields = {line.split()[5] for line in out.read_text().splitlines()[1:]}
    farthest = max(float(x.max()) for x in ranges)
    assert fields == {repr(max(80.0, math.floor(farthest) + 1.0))}, (fields, farthest)
    assert np.array_equal(log.ranges, bag.ranges) and np.array_equal(log.poses, bag.poses)
    assert finished(log).sha256() == finished(bag).sha256()
    log2map = built_log2map()
    if log2map is not None:  # the program itself, where built
        done = subprocess.run([str(log2map), "-q", str(out), str(tmp_path / "inf.map")], capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == 0, done.stderr


def test_a_message_type_without_a_header_is_an_error_naming_bag_topic_and_type(tmp_path):
    # A custom message recorded under LaserScan's name: bag2carmen ended in a traceback.
    definition = ("float32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\nfloat32 range_min\n"
                  "float32 range_max\nfloat32[] ranges\n")
    fields = {"angle_min": -1.0, "angle_max": 1.0, "angle_increment": 1.0, "range_min": 0.0, "range_max": 10.0,
              "ranges": np.array([1.0, 2.0, 3.0], np.float32)}
    path = bag_maker.write_foreign_type(bag_maker.bag_path(tmp_path, "mcap", "custom"), "mcap", "/scan",
                                        bag_maker.LASER_SCAN, definition, [fields, fields], [1000.0, 1000.2])
    for tool, out in (("bag2carmen", "x.log"), ("bag2map", "x.map")):
        r = run_script(tool, "--static-pose", "0,0,0", path, tmp_path / out)
        assert r.returncode == 1, (tool, r.stderr)
        assert "Traceback" not in r.stderr, r.stderr
        assert f"{tool}: {path}: topic '/scan' (sensor_msgs/LaserScan): " in r.stderr, r.stderr
        assert "has no field 'header'" in r.stderr
        assert not (tmp_path / out).exists()


def test_a_scan_of_more_than_100000_beams_names_the_bag_topic_and_stamp(tmp_path):
    # carmen::kMaxCount bounds a log line's beams and the mapper's: bag2carmen and bag2map said
    # "beam_counts[1] = 100001: must be ...", naming neither the bag, nor the topic, nor the scan.
    ranges = [np.full(1000, 4.0, np.float32), np.full(100_001, 4.0, np.float32)]
    path = bag_maker.write_bag(bag_maker.bag_path(tmp_path, "mcap", "wide"), "mcap", [1000.0, 1000.2], ranges,
                               -math.pi, 2 * math.pi / 100_001, 0.0, 30.0, tf_poses=np.zeros((2, 3)),
                               static_mount=(0.0, 0.0, 0.0))
    want = f"{path}: scan at stamp 1000.200000000 on '/scan' has 100001 beams, more than the 100000"
    for tool, out in (("bag2carmen", "x.log"), ("bag2map", "x.map")):
        r = run_script(tool, path, tmp_path / out)
        assert r.returncode == 1, (tool, r.stderr)
        assert f"{tool}: {want}" in r.stderr, r.stderr
        assert not (tmp_path / out).exists()
    with pytest.raises(vg.FileError) as e:
        vg.load_bag(path)
    assert e.value.file == str(path) and want in str(e.value)
