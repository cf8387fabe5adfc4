"""The ROS 2 node's session (vasco_gpu.ros.live_map), its OccupancyGrid values and its
parameter schema, without ROS: scans fed one at a time reach CARMEN's golden bytes, a Path moves
the scans it spans as --poses would, refusals leave the session as it was."""

from __future__ import annotations

import math
import re
import subprocess
import sys
import tracemalloc
from array import array
from pathlib import Path

import numpy as np
import pytest

import vasco_gpu as vg
from conftest import golden_cases, gridmap_digest
from vasco_gpu.ros.grid import grid_values
from vasco_gpu.ros.live_map import LiveMap, LiveMapError
from vasco_gpu.ros.settings import NODE_PARAMETERS, mapper_parameter_names

CASES = {name: (log, ini, digest) for name, log, ini, digest in golden_cases()}


def feed(live, scans, stamps, mount=None):
    for s in range(len(scans)):
        r = scans.ranges_of(s)
        live.add(int(stamps[s]), scans.poses[s], r, float(scans.first_angle[s]), float(scans.angle_step[s]),
                 mount)


@pytest.mark.parametrize("name", ["intel.gfs__vasco_default_ds4", "edge_cases__paper"])
def test_one_scan_at_a_time_then_settled_is_carmens_golden(name):
    log_path, ini, digest = CASES[name]
    log = vg.load_log(log_path, param_file=ini)
    live = LiveMap(log.params, backend="cpu_double")
    feed(live, log.scans, np.arange(len(log)) * 10**8)
    grew = live.settle()
    m = live.finish()
    assert gridmap_digest(m.cells, m.resolution) == digest, f"settled after growing: {grew}"
    assert not live.settle()  # nothing grew since


def laser_of(base, mount):
    """base o mount, written out here (not the library's planar_compose)."""
    x, y, t = base
    mx, my, mt = mount
    return (x + math.cos(t) * mx - math.sin(t) * my, y + math.sin(t) * mx + math.cos(t) * my, t + mt)


def test_a_path_moves_the_scans_it_spans_as_a_fresh_map_of_the_moved_poses():
    log = vg.load_log(CASES["intel.gfs__vasco_default_ds4"][0])
    scans = log.scans.select(0, 300)
    stamps = 10**9 + np.arange(300, dtype=np.int64) * 200_000_000
    mount = (0.1, -0.05, 0.02)
    live = LiveMap(log.params, backend="cpu_double")
    feed(live, scans, stamps, mount)
    rng = np.random.default_rng(7)
    # A Path of base poses at every other scan stamp from scan 50 to 250; scans between two
    # samples take the interpolation, the rest keep their pose.
    k = np.arange(50, 251, 2)
    base = scans.poses[k] + rng.normal(0, [0.05, 0.05, 0.01], (len(k), 3))
    counts = live.repose(stamps[k], base, max_gap_ns=5 * 10**9)
    assert counts == {"moved": 201, "outside": 99, "in_gap": 0, "no_mount": 0}
    want = scans.poses.copy()
    for j, s in enumerate(k):
        want[s] = laser_of(base[j], mount)
    for s in range(51, 250, 2):  # half way between two samples
        a, b = base[(s - 50) // 2], base[(s - 50) // 2 + 1]
        mid = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2, a[2] + math.remainder(b[2] - a[2], 2 * math.pi) / 2)
        want[s] = laser_of(mid, mount)
    np.testing.assert_allclose(live.mapper.poses, want, rtol=0, atol=1e-12)
    fresh = vg.Mapper(log.params, backend="cpu_double")
    fresh.insert(vg.Scans(live.mapper.poses, scans.ranges, scans.beam_counts, scans.first_angle, scans.angle_step))
    assert live.finish().sha256() == fresh.finish().sha256()


def test_path_rules_gap_and_no_mount_and_outside():
    log = vg.load_log(CASES["intel.gfs__vasco_default_ds4"][0])
    scans = log.scans.select(0, 20)
    stamps = np.arange(20, dtype=np.int64) * 10**9
    live = LiveMap(log.params, backend="cpu_double")
    feed(live, scans.select(0, 10), stamps[:10], (0, 0, 0))
    feed(live, scans.select(10, 10), stamps[10:], None)  # no mount: a Path cannot move them
    before = live.mapper.poses
    # samples at 2 s and 9 s (7 s apart: more than pose_max_gap 5 s) and at 12 s
    counts = live.repose([2 * 10**9, 9 * 10**9, 12 * 10**9], [[0, 0, 0], [1, 1, 0], [2, 2, 0]], 5 * 10**9)
    assert counts == {"moved": 2, "outside": 9, "in_gap": 6, "no_mount": 3}
    after = live.mapper.poses
    assert np.array_equal(after[[2, 9]], [[0, 0, 0], [1, 1, 0]])
    unchanged = [s for s in range(20) if s not in (2, 9)]
    assert np.array_equal(after[unchanged], before[unchanged])


def test_max_memory_refusal_leaves_the_session_as_it_was():
    log = vg.load_log(CASES["intel.gfs__vasco_default_ds4"][0])
    scans = log.scans.select(0, 5)
    one = scans.ranges_of(0).nbytes + 72
    live = LiveMap(log.params, backend="cpu_double", max_memory=10 * 2**20)
    live.max_memory = 3 * one  # our own store's bound (the grid has the mapper's)
    feed(live, scans.select(0, 3), [0, 1, 2])
    m = live.finish().sha256()
    with pytest.raises(LiveMapError, match="max_memory"):
        feed(live, scans.select(3, 1), [3])
    assert len(live) == 3 and live.mapper.num_scans == 3 and live.finish().sha256() == m


def test_new_parameters_map_every_stored_scan_again():
    log = vg.load_log(CASES["intel.gfs__vasco_default_ds4"][0])
    live = LiveMap(log.params, backend="cpu_threads")
    feed(live, log.scans.select(0, 100), np.arange(100))
    p = vg.Params(resolution=0.05, p_occ=0.7)
    live.set_params(p)
    fresh = vg.Mapper(p, backend="cpu_double")
    fresh.insert(log.scans.select(0, 100))
    assert live.finish().sha256() == fresh.finish().sha256()
    n = live.reset()
    assert n == 100 and len(live) == 0 and live.finish() is None


def test_the_ranges_are_stored_once_in_the_mapper():
    """A scan's ranges stay in the Mapper only (a large site's 10^5 scans: 144 MB, not twice):
    the Python heap holds no copy of 4 MB of ranges added, and the copy set_params and a saved
    session take comes back from the Mapper bit for bit."""
    log = vg.load_log(CASES["intel.gfs__vasco_default_ds4"][0])
    live = LiveMap(log.params, backend="cpu_double")
    rng = np.random.default_rng(7)
    # float64 given: add_many makes the float32 arrays (4 MB) while tracemalloc watches
    ranges = [rng.uniform(0.1, 20, 1000) for _ in range(1000)]
    want = np.concatenate(ranges).astype(np.float32)
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        live.add_many(np.arange(1000), np.zeros((1000, 3)), ranges, np.full(1000, -1.5), np.full(1000, 0.003),
                      [None] * 1000)
        held = tracemalloc.get_traced_memory()[0] - base
    finally:
        tracemalloc.stop()
    assert held < 1_000_000, f"{held} bytes kept on the Python side for 4 MB of ranges"
    assert live.stored_ranges().tobytes() == want.tobytes()
    live.set_params(vg.Params(resolution=0.05))
    assert live.stored_ranges().tobytes() == want.tobytes() and len(live) == 1000


def test_grid_values_by_hand():
    # cells[x, y], x-major: 3 wide, 2 high; values exact in float32
    cells = np.array([[-1.0, 0.125], [0.5, 0.6875], [0.1875, 0.0625]], dtype=np.float32)
    m = vg.Map(cells, 0.05)
    values = lambda *a: list(array("b", grid_values(m, *a)))  # noqa: E731
    # rows from y = 0: (x0, x1, x2) = (-1, 0.5, 0.1875), then (0.125, 0.6875, 0.0625)
    assert values("scale") == [-1, 50, 19, 13, 69, 6]  # 12.5 rounds up
    assert values("trinary") == [-1, -1, 0, 0, 100, 0]
    assert values("trinary", 0.1, 0.7) == [-1, -1, -1, -1, -1, 0]
    with pytest.raises(ValueError, match="map_mode 'raw'"):
        grid_values(m, "raw")


def test_finish_grid_is_the_values_of_the_finish_written_into_the_last_array():
    log = vg.load_log(CASES["intel.gfs__vasco_default_ds4"][0])
    live = LiveMap(log.params, backend="cpu_double")
    assert live.finish_grid("trinary", 0.196, 0.65) is None  # no scan yet
    feed(live, log.scans.select(0, 200), np.arange(200) * 10**8)
    m = live.finish()
    for mode, free, occupied in [("trinary", 0.196, 0.65), ("trinary", 0.25, 0.5), ("scale", 0.196, 0.65)]:
        want = grid_values(m, mode, free, occupied)
        (sx, sy, res, origin), data = live.finish_grid(mode, free, occupied)
        assert (sx, sy, res, origin) == (m.size_x, m.size_y, m.resolution, tuple(m.origin))
        assert isinstance(data, bytes) and data == want
        out = array("b", bytes(sx * sy))
        assert live.finish_grid(mode, free, occupied, out=out)[1] is out and out.tobytes() == want
    assert {-1, 0, 100} <= set(array("b", grid_values(m, "trinary")))  # every kind of cell compared
    other = array("b", bytes(7))  # another size: left alone, new bytes returned
    assert isinstance(live.finish_grid("scale", 0.196, 0.65, out=other)[1], bytes) and other.tobytes() == bytes(7)
    with pytest.raises(ValueError, match="map_mode 'raw'"):
        live.finish_grid("raw", 0.196, 0.65)
    for bad in (bytes(len(want)), array("i", [0]) * len(want)):  # read-only; items wider than a byte
        with pytest.raises(TypeError, match="out: expected a writable buffer of bytes"):
            live.finish_grid("trinary", 0.196, 0.65, out=bad)
        with pytest.raises(TypeError, match="out: expected a writable buffer of bytes"):
            grid_values(m, "trinary", out=bad)


ROOT = Path(__file__).resolve().parents[2]


def test_the_launch_example_names_parameters_the_node_has():
    text = (ROOT / "examples" / "ros" / "vasco_with_slam_toolbox.launch.py").read_text()
    compile(text, "vasco_with_slam_toolbox.launch.py", "exec")
    names = re.findall(r'"([a-z_]+):=', text)
    assert len(names) >= 8
    known = {p.name for p in NODE_PARAMETERS} | set(mapper_parameter_names())
    assert not set(names) - known, set(names) - known


def test_without_rclpy_the_node_says_how_to_install_it():
    code = ("import sys; sys.modules['rclpy'] = None\n"
            "from vasco_gpu.ros import main\nsys.exit(main())")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1
    assert "rclpy does not import" in r.stderr and "pip install '.[ros]' ./ros from" in r.stderr


def test_a_fixed_frame_reaches_the_mapper_and_none_is_never_passed(monkeypatch):
    log = vg.load_log(CASES["intel.gfs__vasco_default_ds4"][0])
    scans = log.scans.select(0, 60)
    frame = vg.Frame(900, 700, log.params.resolution)
    live = LiveMap(log.params, backend="cpu_double", frame=frame)
    feed(live, scans, np.arange(60))
    fixed = vg.Mapper(log.params, backend="cpu_double", frame=frame)
    fixed.insert(scans)
    m = live.finish()
    assert (m.size_x, m.size_y) == (fixed.finish().size_x, fixed.finish().size_y)
    assert m.sha256() == fixed.finish().sha256() and live.mapper.frame.size_x == 900
    seen = []
    real = vg._core.Mapper

    def recording(*args, **kwargs):
        seen.append(sorted(k for k in kwargs if k.startswith("frame")))
        kwargs.pop("frame_centre", None)  # a Mapper that may not take it yet: what was passed is the test
        return real(*args, **kwargs)

    monkeypatch.setattr(vg._core, "Mapper", recording)
    LiveMap(log.params, backend="cpu_double")
    LiveMap(log.params, backend="cpu_double", frame=frame, frame_centre=(1.0, 2.0))
    assert seen == [[], ["frame", "frame_centre"]]


def test_restore_maps_the_saved_scans_with_the_saved_parameters_or_changes_nothing():
    from vasco_gpu.ros.session_file import SavedSession

    log = vg.load_log(CASES["intel.gfs__vasco_default_ds4"][0])
    scans = log.scans.select(0, 50)
    p = vg.Params(resolution=0.05, p_occ=0.7)
    live = LiveMap(p, backend="cpu_double")
    feed(live, scans, np.arange(50) * 7, (0.1, 0, 0))
    saved = SavedSession.of(live)
    fresh = vg.Mapper(p, backend="cpu_double")
    fresh.insert(scans)
    restored = LiveMap(log.params, backend="cpu_double")
    restored.restore(saved)
    assert restored.finish().sha256() == fresh.finish().sha256()
    assert list(restored.stamps) == list(np.arange(50) * 7) and list(restored.mounts[:3]) == [0.1, 0, 0]
    with pytest.raises(LiveMapError, match="already stores 50 scans"):
        restored.restore(saved)
    small = LiveMap(log.params, backend="cpu_double")
    small.max_memory = 1000  # our own store's bound: far less than 50 scans
    with pytest.raises(LiveMapError, match="max_memory"):
        small.restore(saved)
    assert len(small) == 0 and small.mapper.params.to_dict() == log.params.to_dict()
