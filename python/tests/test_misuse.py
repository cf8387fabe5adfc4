"""Misuse of the Python API that once corrupted memory, froze other threads or wrote maps
that cannot be read back: each is refused with a clear error now."""

from __future__ import annotations

import ast
import math
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import vasco_gpu as vg
from conftest import FR079, ROOT


def _two_scans():
    return vg.Scans(np.zeros((2, 3)), np.full(362, 2.0, np.float32), [181, 181], -np.pi / 2, np.pi / 180)


def _run_isolated(code: str) -> subprocess.CompletedProcess:
    """`code` in a fresh interpreter importing this vasco_gpu: a crash fails the test, not the run."""
    env = dict(os.environ, PYTHONFAULTHANDLER="1")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(vg.__file__).resolve().parents[1])] +
                                        ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env)


# ---- Scans: which beams are whose cannot be changed from Python ----

_HEAP_WRITE = """
import numpy as np, vasco_gpu as vg
s = vg.Scans(np.zeros((2, 3)), np.full(362, 2.0, np.float32), [181, 181], -np.pi / 2, np.pi / 180)
for i, v in ((1, 1 << 20), (-1, 10**7)):
    try:
        s.beam_offsets[i] = v
    except ValueError:
        pass
    else:
        raise SystemExit("beam_offsets[%d] was writable" % i)
v = s.ranges_of(0)
assert v.shape == (181,), v.shape
vg.Mapper().insert(s)
print("ok")
"""


def test_beam_offsets_cannot_be_written():
    r = _run_isolated(_HEAP_WRITE)
    assert r.returncode == 0 and "ok" in r.stdout, f"exit status {r.returncode}\n{r.stdout}\n{r.stderr}"


def test_beam_offsets_cannot_be_made_writable():
    off = _two_scans().beam_offsets
    assert not off.flags.writeable
    with pytest.raises(ValueError):
        off.flags.writeable = True
    np.testing.assert_array_equal(off, [0, 181, 362])


def test_per_scan_views_stay_writable():
    s = _two_scans()
    s.ranges[:] = 3.0
    s.theta[1] = 0.5
    assert s.ranges_of(1)[0] == 3.0 and s.poses[1, 2] == 0.5


@pytest.mark.parametrize("counts", [[181.7, 180.3], [181.5, 180.5], [float("nan"), 362]])
def test_fractional_beam_counts_are_refused(counts):
    with pytest.raises(vg.BadInputError, match=r"beam_counts\[0\].*whole number"):
        vg.Scans(np.zeros((2, 3)), np.full(362, 2.0, np.float32), counts, -np.pi / 2, np.pi / 180)


def test_whole_beam_counts_of_any_dtype_are_accepted():
    for counts in ([181.0, 181.0], np.array([181, 181], np.uint16), (181, 181)):
        s = vg.Scans(np.zeros((2, 3)), np.full(362, 2.0, np.float32), counts, -np.pi / 2, np.pi / 180)
        np.testing.assert_array_equal(s.beam_counts, [181, 181])


@pytest.mark.parametrize("first, step", [(float("nan"), np.pi / 180), (-np.pi / 2, float("inf")),
                                          (float("-inf"), np.pi / 180)])
def test_non_finite_beam_angles_are_refused_by_insert(first, step):
    # A NaN or infinite angle was mapped (399-568 cells changed, the map twice as wide): refused,
    # naming the scan, and the session keeps nothing of the call.
    s = vg.Scans(np.zeros((2, 3)), np.full(362, 2.0, np.float32), [181, 181], first, step)
    m = vg.Mapper()
    with pytest.raises(vg.BadInputError, match="scan 0: the (first beam's angle|angle step) is not finite"):
        m.insert(s)
    assert len(m) == 0


# ---- Mapper: threads, the GIL and Ctrl-C ----

@pytest.mark.parametrize("threads", [1025, 3000, 2**31 - 1, -1])
def test_thread_count_is_capped_as_log2map_caps_it(threads):
    with pytest.raises(vg.UsageError, match="threads"):
        vg.Mapper(backend="cpu_threads", threads=threads)
    with pytest.raises(ValueError):
        vg.Mapper(backend="cpu_threads", threads=threads)


def test_thread_count_at_the_cap_is_accepted():
    m = vg.Mapper(backend="cpu_threads", threads=1024)
    assert m.backend == "cpu_threads"


@pytest.fixture(scope="module")
def long_scans():
    """fr079's scans three times over: one insert of about two seconds on cpu_double."""
    log = vg.load_log(FR079)
    s = log.scans
    return log.params, vg.Scans(np.tile(s.poses, (3, 1)), np.tile(s.ranges, 3), np.tile(s.beam_counts, 3),
                                np.tile(s.first_angle, 3), np.tile(s.angle_step, 3))


def _insert_in_background(mapper, scans):
    t = threading.Thread(target=mapper.insert, args=(scans,))
    t.start()
    time.sleep(0.2)
    if not t.is_alive():
        t.join()
        pytest.skip("the insert ended before it could be observed")
    return t


@pytest.mark.parametrize("query", ["len", "frame", "last_stats", "repr", "renders"])
def test_state_answers_during_an_insert(long_scans, query):
    params, scans = long_scans
    m = vg.Mapper(params, backend="cpu_double")
    ask = {"len": len, "frame": lambda m: m.frame, "last_stats": lambda m: m.last_stats, "repr": repr,
           "renders": lambda m: m.renders}[query]
    t = _insert_in_background(m, scans)
    t0 = time.monotonic()
    ask(m)
    waited = time.monotonic() - t0
    busy = t.is_alive()
    t.join()
    assert busy, "the query waited for the insert"
    assert waited < 0.1
    assert len(m) == len(scans)  # the snapshot follows the call once it ends


def test_poses_wait_without_the_gil(long_scans):
    params, scans = long_scans
    m = vg.Mapper(params, backend="cpu_double")
    t = _insert_in_background(m, scans)
    ticks = []
    ticker = threading.Thread(target=lambda: [ticks.append(time.sleep(0.01)) for _ in range(30)])
    ticker.start()
    p = m.poses  # waits for the insert, but lets the ticker run meanwhile
    ticker.join()
    t.join()
    assert p.shape == (len(scans), 3)
    assert len(ticks) == 30


def _signal_soon(delay=0.2):
    timer = threading.Timer(delay, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def test_a_signal_handler_runs_during_an_insert(long_scans):
    params, scans = long_scans
    m = vg.Mapper(params, backend="cpu_double")
    seen = []
    old = signal.signal(signal.SIGINT, lambda *_: seen.append(time.monotonic()))
    try:
        t0 = time.monotonic()
        _signal_soon()
        m.insert(scans)
        t1 = time.monotonic()
    finally:
        signal.signal(signal.SIGINT, old)
    if t1 - t0 < 0.6:
        pytest.skip("the insert was too short to tell")
    assert seen and seen[0] - t0 < 0.4, (seen, t1 - t0)


def test_ctrl_c_raises_once_the_insert_is_done(long_scans):
    params, scans = long_scans
    m = vg.Mapper(params, backend="cpu_double")
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _signal_soon()
        with pytest.raises(KeyboardInterrupt):
            m.insert(scans)
    finally:
        signal.signal(signal.SIGINT, old)
    # The session holds what the call did: every scan, and a grid that finishes.
    assert len(m) == len(scans)
    assert m.finish().size_x > 0


# ---- Maps that could not be read back ----

@pytest.fixture
def small_map():
    cells = np.full((4, 3), -1.0, np.float32)
    cells[1, 1] = 0.9
    cells[2, 1] = 0.1
    return vg.Map(cells, 0.05, (1.0, 2.0, 0.0))


@pytest.mark.parametrize("resolution", [math.nan, 0.0, -1.0, math.inf, 1e-50])
@pytest.mark.parametrize("name", ["m.map", "m.map.gz", "m.pgm"])
def test_write_map_refuses_a_resolution_read_map_refuses(tmp_path, small_map, name, resolution):
    small_map.resolution = resolution
    with pytest.raises(vg.BadInputError, match="resolution") as e:
        vg.write_map(tmp_path / name, small_map)
    assert name in str(e.value)
    assert list(tmp_path.iterdir()) == []


def test_write_map_png_needs_no_resolution(tmp_path, small_map):
    small_map.resolution = 0.0
    vg.write_map(tmp_path / "m.png", small_map)
    assert vg.read_map(tmp_path / "m.png").shape == (4, 3)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -0.5, 1.5])
@pytest.mark.parametrize("name", ["m.map", "m.pgm", "m.png"])
def test_write_map_refuses_cells_read_map_refuses(tmp_path, small_map, name, bad):
    small_map.cells[3, 2] = bad
    with pytest.raises(vg.BadInputError, match=r"cell \(3, 2\)"):
        vg.write_map(tmp_path / name, small_map)
    assert list(tmp_path.iterdir()) == []


def test_written_map_reads_back(tmp_path, small_map):
    vg.write_map(tmp_path / "m.map", small_map)
    back = vg.read_map(tmp_path / "m.map")
    np.testing.assert_array_equal(back.cells, small_map.cells)


def test_compare_refuses_nan_cells(small_map):
    other = vg.Map(small_map.cells.copy(), small_map.resolution, small_map.origin)
    other.cells[1, 1] = np.nan
    with pytest.raises(vg.BadInputError, match="map b"):
        vg.compare(small_map, other)
    with pytest.raises(vg.BadInputError, match="map a"):
        vg.compare(other, small_map)
    assert vg.compare(small_map, small_map).class_agreement == 1.0


@pytest.mark.parametrize("shape", [(2**31, 1), (1, 2**31), (2**32 + 3, 1)])
def test_map_shape_beyond_int_is_refused(shape):
    huge = np.broadcast_to(np.float32(-1), shape)  # no memory behind it
    with pytest.raises(vg.TooLargeError, match="at most 2147483647"):
        vg.Map(huge, 0.05)


def test_map_of_sevens_is_refused_before_it_is_written():
    # Once accepted and written, then refused by read_map (and mapconvert) as damaged.
    with pytest.raises(vg.BadInputError, match=r"^Map: cell \(0, 0\) is 7: ") as e:
        vg.Map(np.full((4, 3), 7), 0.05)
    assert isinstance(e.value, ValueError)


@pytest.mark.parametrize("bad, shown", [(7.0, "7"), (-0.5, "-0.5"), (math.nan, "nan"), (math.inf, "inf"),
                                        (-math.inf, "-inf"), (1.5, "1.5"), (3.5, "3.5"), (-1.0001, "-1.00010002")])
def test_map_refuses_cells_read_map_refuses(bad, shown):
    cells = np.full((4, 3), -1.0, np.float32)
    cells[0, 0] = 0.5
    cells[2, 1] = bad  # the first bad cell, x-major
    cells[3, 0] = bad
    with pytest.raises(vg.BadInputError, match=rf"cell \(2, 1\) is {re.escape(shown)}: a cell is -1"):
        vg.Map(cells, 0.05)
    with pytest.raises(ValueError, match=r"cell \(2, 1\)"):
        vg.Map(cells.astype(np.float64), 0.05)  # converted first, then checked


@pytest.mark.parametrize("value", [0.0, 1.0, -1.0, 0.5, -0.0, 2.0, 2.5, 3.0])
def test_map_accepts_what_read_map_accepts(tmp_path, value):
    # -1 unknown, a probability, or an off-limits value in [2, 3] (CARMEN's overlay, a
    # probability plus 2), which CARMEN's map files may hold and read_map gives back.
    cells = np.full((4, 3), value)
    m = vg.Map(cells, 0.05)
    np.testing.assert_array_equal(m.cells, cells.astype(np.float32))
    vg.write_map(tmp_path / "m.map", m)
    back = vg.read_map(tmp_path / "m.map")
    np.testing.assert_array_equal(back.cells, m.cells)
    assert vg.Map(back.cells, back.resolution, back.origin).sha256() == m.sha256()


@pytest.mark.parametrize("name", ["maps/freiburg.map", "golden/maps/edge_cases__paper.map.gz",
                                  "golden/maps/intel.gfs__vasco_default_ds4.map.gz"])
def test_maps_read_map_gives_are_constructible(name):
    m = vg.read_map(ROOT / "tests" / "data" / name)
    again = vg.Map(m.cells, m.resolution, m.origin)
    assert again.sha256() == m.sha256()


def test_maps_read_from_images_are_constructible(tmp_path, small_map):
    small_map.cells[0, 0] = 0.0
    small_map.cells[3, 2] = 1.0
    for name in ("m.png", "m.pgm"):
        vg.write_map(tmp_path / name, small_map)
        m = vg.read_map(tmp_path / name)
        assert vg.Map(m.cells, m.resolution, m.origin).sha256() == m.sha256()


def test_map_cells_written_later_are_refused_where_they_leave_python(tmp_path, small_map):
    small_map.cells[1, 2] = 7  # the view is writable: write_map and compare check it
    with pytest.raises(vg.BadInputError, match=r"cell \(1, 2\) is 7"):
        vg.write_map(tmp_path / "m.map", small_map)
    with pytest.raises(vg.BadInputError, match=r"cell \(1, 2\) is 7"):
        vg.Map(small_map.cells, small_map.resolution)


# ---- Docstrings that say what the calls do ----

def test_backends_docstring_lists_what_backends_returns():
    doc = vg.backends.__doc__
    listed = ast.literal_eval(doc.split("takes in this build:\n\n  ", 1)[1].split("\n", 1)[0])
    assert listed == vg.backends()  # exactly the list it returns, auto included
    assert vg.backends()[-1] == "auto" and "then 'auto'" in doc
    for name in vg.backends():
        assert f"\n  {name}: " in doc, name  # each explained
        if name != "cuda" or vg.cuda_available():
            vg.Mapper(backend=name)  # and each a name Mapper takes


def test_params_docstring_lists_every_key_with_its_default():
    defaults = vg.Params().to_dict()
    for key, value in defaults.items():
        assert f"{key}: " in vg.Params.__doc__ and f"default {value:g}" in vg.Params.__doc__, key
        assert getattr(vg.Params, key).__doc__.startswith(f"vasco_{key}: "), key


def test_extend_is_refused_while_a_view_of_the_scans_is_alive():
    """A view of Scans' arrays points into memory extend would move (reading it crashed, writing
    it corrupted the heap): extend refuses while one is alive, and works once it is gone."""
    import gc

    log = vg.load_log(ROOT / "logs" / "intel.gfs.log.gz")
    more = log.scans.select(10, 5)
    for take in (lambda s: s.ranges, lambda s: s.x, lambda s: s.lines, lambda s: s.ranges_of(2),
                 lambda s: s.beam_offsets):
        s = log.scans.select(0, 10)
        view = take(s)
        with pytest.raises(RuntimeError, match="1 NumPy view is alive"):
            s.extend(more)
        assert len(s) == 10 and view[0] == view[0]  # unchanged, and the view still reads
        del view
        gc.collect()
        s.extend(more)
        assert len(s) == 15
    view = log.ranges  # Log.ranges is a view of Log.scans' memory
    with pytest.raises(RuntimeError, match="NumPy view"):
        log.scans.extend(more)
    del view
    gc.collect()
    n = len(log.scans)
    log.scans.extend(more)
    assert len(log.scans) == n + 5
