"""The published map's canvas and its updates (vasco_gpu.ros.canvas), without ROS: updates
applied to a full map give the next full map, a growing canvas at least doubles its area with
the finished map located exactly in it, a canvas the size of the map is today's /map bit for
bit, a fixed frame gives only updates, reset starts again. Every test runs on both stores of
the canvas's cells (canvas_cells.py): plain, and packed in tiles of 7 cells (odd, so the maps'
edges cut tiles), and the packed store is checked against a NumPy array."""

from __future__ import annotations

import copy
from array import array
from types import SimpleNamespace as NS

import numpy as np
import pytest

from vasco_gpu import _core
from vasco_gpu.ros import canvas_cells
from vasco_gpu.ros.canvas import Canvas, FullMap, MapUpdate, fill_update
from vasco_gpu.ros.grid import finished_grid
from vasco_gpu.ros.live_map import LiveMap

MODE = ("trinary", 0.25, 0.65)


@pytest.fixture(params=["plain", "packed"], autouse=True)
def store(request, monkeypatch):
    """The canvas's cells plain (the default for a map of these sizes) or packed, small tiles."""
    if request.param == "packed":
        monkeypatch.setattr(canvas_cells, "PACKED_CANVAS_BYTES", -1)
        monkeypatch.setattr(canvas_cells, "TILE", 7)
    return request.param


class Subscriber:
    """What nav2's static layer does with /map and map_updates: keeps the last full map and
    writes each update into it."""

    def __init__(self):
        self.geometry, self.cells = None, None

    def take(self, got):
        if isinstance(got, FullMap):
            self.geometry = got.geometry
            size_x, size_y = got.geometry[:2]
            self.cells = np.array(got.data, dtype=np.int8).reshape(size_y, size_x)  # a copy, as a message is
        elif isinstance(got, MapUpdate):
            patch = np.array(got.data, dtype=np.int8).reshape(got.height, got.width)
            self.cells[got.y:got.y + got.height, got.x:got.x + got.width] = patch


def expected_canvas(geometry, finished) -> np.ndarray:
    """The canvas of `geometry` holding `finished`, placed by its world origin (floats, not the
    canvas's integer bookkeeping): -1 outside it."""
    size_x, size_y, res, (cx, cy, ctheta) = geometry
    (fx, fy, fres, (ox, oy, otheta)), data = finished
    assert fres == res and otheta == ctheta
    col, row = (ox - cx) / res, (oy - cy) / res
    assert abs(col - round(col)) < 1e-6 and abs(row - round(row)) < 1e-6, "not on the canvas's cells"
    col, row = round(col), round(row)
    assert 0 <= col and col + fx <= size_x and 0 <= row and row + fy <= size_y, "not inside the canvas"
    want = np.full((size_y, size_x), -1, dtype=np.int8)
    want[row:row + fy, col:col + fx] = np.frombuffer(data, dtype=np.int8).reshape(fy, fx)
    return want


def publish_and_check(canvas, sub, finished, frame, full=False, live=None):
    """Publishes, applies to the subscriber, and checks the subscriber against the map placed
    independently in the canvas's geometry. With `live`, only the cells in its reach are
    compared (as the node publishes), and the reach cleared after."""
    got = canvas.publish(finished, frame, full=full, reach=None if live is None else live.reach)
    if live is not None:
        live.clear_reach()
    sub.take(got)
    assert sub.geometry == canvas.geometry
    np.testing.assert_array_equal(sub.cells, expected_canvas(sub.geometry, finished))
    return got


def add_scans(live, scans, order, stamps):
    live.add_many([stamps[s] for s in order], scans.poses[order], [scans.ranges_of(s) for s in order],
                  scans.first_angle[order], scans.angle_step[order], [(0.0, 0.0, 0.0)] * len(order))


@pytest.mark.parametrize("seed, backend, downsample, reach", [
    (1, "cpu_double", 2, False), (2, "cpu_double", 2, False),
    (3, "cpu_double", 2, True), (4, "cpu_float", 1, True), (5, "cpu_threads", 3, True)])
def test_updates_applied_to_a_full_map_give_the_next_full_map(intel, seed, backend, downsample, reach):
    # intel (conftest) at the node's map cell: 0.025 m cells, downsample 2, so the blocks
    # move whenever the frame grows by an odd number of cells a side (a new lattice). With
    # reach, only the cells the scans since the last publication can reach are compared: a
    # reach too small leaves the subscriber's map short of cells the independent one has.
    assert intel.params.downsample == 2
    params = copy.copy(intel.params)
    params.downsample = downsample
    rng = np.random.default_rng(seed)
    scans = intel.scans.select(0, 260)
    stamps = 10**9 + np.arange(260, dtype=np.int64) * 10**8
    order = rng.permutation(260)  # random order: the map grows in jumps, and back
    live = LiveMap(params, backend=backend)
    canvas, sub, kinds = Canvas(), Subscriber(), []
    at, given = 0, live if reach else None
    while at < len(order):
        k = int(rng.integers(1, 12))
        add_scans(live, scans, order[at:at + k], stamps)
        at += k
        kinds.append(type(publish_and_check(canvas, sub, live.finish_grid(*MODE), live.mapper.frame, live=given)))
        if at >= 130 and "path" not in kinds:  # a Path: every scan moved, a full map due
            base = scans.poses + rng.normal(0, [0.03, 0.03, 0.005], (260, 3))
            assert live.repose(stamps, base, max_gap_ns=10**9)["moved"] == len(live)
            got = publish_and_check(canvas, sub, live.finish_grid(*MODE), live.mapper.frame, full=True, live=given)
            assert isinstance(got, FullMap)
            kinds.append("path")
    assert kinds.count(MapUpdate) > 10 and canvas.growths + canvas.lattices >= 2  # the canvas changed at least once


def test_a_canvas_the_size_of_the_map_is_todays_map_bit_for_bit(intel):
    scans = intel.scans.select(0, 200)
    live = LiveMap(intel.params, backend="cpu_double")
    for first in range(0, 200, 25):
        add_scans(live, scans, np.arange(first, first + 25), np.arange(200))
        finished = live.finish_grid(*MODE)
        got = Canvas().publish(finished, live.mapper.frame)  # a first canvas: exactly the map
        assert isinstance(got, FullMap)
        assert got.geometry == finished[0]  # the origin's floats themselves
        assert got.data.tobytes() == bytes(finished[1])


def synthetic(frame, kx, ky, size_x, size_y, rng, ds=2, theta=0.0):
    """A finished map of `frame` whose first cell is fine cell (kx, ky) from the centre, its
    origin computed as CARMEN's world_origin does: (k) r + x0."""
    origin = (kx * frame.resolution + frame.x0, ky * frame.resolution + frame.y0, theta)
    data = rng.integers(-1, 101, size_x * size_y, dtype=np.int8).tobytes()
    return (size_x, size_y, frame.resolution * ds, origin), data


def test_growth_at_least_doubles_the_area_and_locates_the_window():
    rng = np.random.default_rng(3)
    frame = NS(x0=1.2345, y0=-5.678, resolution=0.025, size_x=0, size_y=0)
    canvas, sub = Canvas(), Subscriber()
    kx, ky, w, h = -41, 17, 30, 20  # phase 1 in both axes (ds 2)
    publish_and_check(canvas, sub, synthetic(frame, kx, ky, w, h, rng), frame)
    grown = 0
    for step in range(40):
        # the window grows by a few blocks on a random side (kx, ky in fine cells, 2 a block)
        side, more = int(rng.integers(4)), int(rng.integers(0, 9))
        kx, w = (kx - 2 * more, w + more) if side == 0 else (kx, w + more if side == 2 else w)
        ky, h = (ky - 2 * more, h + more) if side == 1 else (ky, h + more if side == 3 else h)
        before, old = canvas.growths, canvas.geometry
        got = publish_and_check(canvas, sub, synthetic(frame, kx, ky, w, h, rng), frame)
        if canvas.growths == before:
            assert isinstance(got, MapUpdate) and canvas.geometry == old
            continue
        grown += 1
        assert isinstance(got, FullMap)
        (ow, oh, res, (ox, oy, _)), (nw, nh, _, (nx, ny, _)) = old, canvas.geometry
        assert nw * nh >= 2 * ow * oh
        for new_side, old_side, window_side in ((nw, ow, w), (nh, oh, h)):
            assert new_side == old_side or (new_side - window_side) % 2 == 0
        # the new canvas holds the old one
        assert nx <= ox + 1e-9 and ny <= oy + 1e-9
        assert nx + nw * res >= ox + ow * res - 1e-9 and ny + nh * res >= oy + oh * res - 1e-9
    assert 3 <= grown <= 12  # large steps: few growths for a window that grew ~5x per side


def test_a_new_lattice_gives_a_full_map_centred_on_the_window_never_smaller():
    rng = np.random.default_rng(4)
    frame = NS(x0=0.5, y0=0.25, resolution=0.05, size_x=0, size_y=0)
    canvas, sub = Canvas(), Subscriber()
    publish_and_check(canvas, sub, synthetic(frame, -100, -60, 80, 50, rng), frame)
    publish_and_check(canvas, sub, synthetic(frame, -100, -60, 120, 50, rng), frame)  # grows in x
    w0, h0 = canvas.geometry[:2]
    moved = NS(x0=0.51, y0=0.25, resolution=0.05, size_x=0, size_y=0)  # a Path moved the first scan
    for kx in (-100, -101):  # then the blocks moved by one fine cell (ds 2)
        got = publish_and_check(canvas, sub, synthetic(moved, kx, -60, 90, 40, rng), moved)
        assert isinstance(got, FullMap)
        w, h, res, (ox, oy, _) = got.geometry
        assert (w, h) == (w0, h0)  # the window fits: the canvas keeps its size
        col, row = (kx * 0.05 + 0.51 - ox) / res, (-60 * 0.05 + 0.25 - oy) / res
        assert (round(col), round(row)) == ((w - 90) // 2, (h - 40) // 2)  # centred
    assert canvas.lattices == 3 and canvas.growths == 1


def test_nothing_changed_gives_nothing_and_a_rerender_a_full_map():
    rng = np.random.default_rng(5)
    frame = NS(x0=0.0, y0=0.0, resolution=0.05, size_x=0, size_y=0)
    canvas, sub = Canvas(), Subscriber()
    finished = synthetic(frame, -10, -10, 20, 20, rng, ds=1)
    publish_and_check(canvas, sub, finished, frame)
    assert publish_and_check(canvas, sub, finished, frame) is None
    got = publish_and_check(canvas, sub, finished, frame, full=True)
    assert isinstance(got, FullMap) and got.geometry == finished[0]


def test_an_update_is_the_bounding_box_of_the_changed_cells():
    rng = np.random.default_rng(6)
    frame = NS(x0=0.0, y0=0.0, resolution=0.05, size_x=0, size_y=0)
    canvas, sub = Canvas(), Subscriber()
    (geometry, data) = synthetic(frame, -10, -10, 40, 30, rng, ds=1)
    publish_and_check(canvas, sub, (geometry, data), frame)
    cells = np.frombuffer(data, dtype=np.int8).reshape(30, 40).copy()
    cells[3, 7] = (cells[3, 7] + 1) % 100  # two cells: the box from (7, 3) to (25, 12)
    cells[12, 25] = (cells[12, 25] + 1) % 100
    got = publish_and_check(canvas, sub, (geometry, cells.tobytes()), frame)
    assert (got.x, got.y, got.width, got.height) == (7, 3, 19, 10)
    assert got.data.typecode == "b" and got.data.tobytes() == cells[3:13, 7:26].tobytes()


def test_a_window_that_moves_inside_the_canvas_clears_what_it_left():
    rng = np.random.default_rng(7)
    frame = NS(x0=0.0, y0=0.0, resolution=0.05, size_x=0, size_y=0)
    canvas, sub = Canvas(), Subscriber()
    publish_and_check(canvas, sub, synthetic(frame, 0, 0, 50, 40, rng, ds=1), frame)
    for _ in range(30):  # windows inside the first one: updates only, the rest back to -1
        x, y = int(rng.integers(0, 40)), int(rng.integers(0, 30))
        w, h = int(rng.integers(1, 51 - x)), int(rng.integers(1, 41 - y))
        got = publish_and_check(canvas, sub, synthetic(frame, x, y, w, h, rng, ds=1), frame)
        assert got is None or isinstance(got, MapUpdate)
    assert canvas.geometry[:2] == (50, 40)


def fixed_mapper(intel, size):
    frame = _core.Frame(size, size, intel.params.resolution)
    return _core.Mapper(intel.params, backend="cpu_double", frame=frame)


def test_a_fixed_frame_gives_only_updates(intel):
    scans = intel.scans.select(0, 150)
    mapper = fixed_mapper(intel, 1600)
    canvas, sub = Canvas(fixed=True), Subscriber()
    first, geometry = None, None
    for at in range(0, 150, 10):
        mapper.insert(scans.select(at, at + 10))
        got = publish_and_check(canvas, sub, finished_grid(mapper, *MODE), mapper.frame)
        if first is None:
            first, geometry = got, canvas.geometry
            assert isinstance(got, FullMap)
        else:
            assert got is None or isinstance(got, MapUpdate)
            assert canvas.geometry == geometry
    # the frame's whole block extent: 1600 // 2 - 1 blocks from the frame's cell 0
    f = mapper.frame
    assert geometry == (799, 799, 0.05, (f.x0 - 800 * 0.025, f.y0 - 800 * 0.025, 0.0))
    assert canvas.growths == 0 and canvas.lattices == 1
    got = publish_and_check(canvas, sub, finished_grid(mapper, *MODE), mapper.frame, full=True)
    assert isinstance(got, FullMap) and got.geometry == geometry


def test_reset_starts_with_a_map_of_its_own_size():
    rng = np.random.default_rng(8)
    frame = NS(x0=0.0, y0=0.0, resolution=0.05, size_x=0, size_y=0)
    canvas = Canvas()
    canvas.publish(synthetic(frame, 0, 0, 50, 40, rng, ds=1), frame)
    canvas.publish(synthetic(frame, 0, 0, 80, 40, rng, ds=1), frame)
    assert canvas.geometry[:2] == (100, 40) and canvas.growths == 1
    canvas.reset()
    assert canvas.geometry is None and canvas.current() is None and canvas.growths == 0
    small = synthetic(frame, 4, 4, 10, 12, rng, ds=1)
    got = canvas.publish(small, frame)
    assert isinstance(got, FullMap) and got.geometry == small[0] and got.data.tobytes() == small[1]


def test_a_map_not_of_the_frame_is_refused():
    frame = NS(x0=0.0, y0=0.0, resolution=0.05, size_x=0, size_y=0)
    finished = ((4, 4, 0.05, (0.02, 0.0, 0.0)), bytes(16))  # 0.4 of a cell off the lattice
    with pytest.raises(ValueError, match="not of the frame"):
        Canvas().publish(finished, frame)


def test_fill_update_fills_an_update_message():
    msg = NS(header=NS(frame_id="", stamp=None), x=0, y=0, width=0, height=0, data=None)
    update = MapUpdate(3, 4, 2, 1, array("b", [5, -1]))
    data = fill_update(msg, update, frame="map", stamp="t")
    assert (msg.header.frame_id, msg.header.stamp, msg.x, msg.y, msg.width, msg.height) == ("map", "t", 3, 4, 2, 1)
    assert msg.data is data and data.typecode == "b" and list(data) == [5, -1]


def test_a_widened_crop_is_compared_whole_whatever_the_reach():
    # CARMEN's crop can widen over blocks known before but never published (the frame grew
    # inside the grid without a render; a border of 0): no scan since touched them, so the
    # scans' reach does not hold them, and the update must carry them all the same.
    rng = np.random.default_rng(5)
    frame = NS(x0=0.0, y0=0.0, resolution=0.05, size_x=400, size_y=400)
    canvas, sub = Canvas(fixed=True), Subscriber()
    first = synthetic(frame, -100, -100, 60, 40, rng, ds=1)
    publish_and_check(canvas, sub, first, frame)
    (sx, sy, res, origin), data = first
    cells = np.frombuffer(data, dtype=np.int8).reshape(sy, sx)
    wider = np.concatenate([cells, rng.integers(0, 101, (sy, 1), dtype=np.int8)], axis=1)
    second = ((sx + 1, sy, res, origin), wider.tobytes())
    far = (origin[0] - 50.0, origin[1] - 50.0, origin[0] - 49.0, origin[1] - 49.0)  # nowhere near the new column
    got = canvas.publish(second, frame, reach=far)
    assert isinstance(got, MapUpdate)
    sub.take(got)
    np.testing.assert_array_equal(sub.cells, expected_canvas(sub.geometry, second))
    # the same window again: only the reach is compared, and nothing changed there
    assert canvas.publish(second, frame, reach=far) is None


def test_packed_cells_are_the_cells_written(store):
    # boxes written and read at random against a NumPy array; tiles of one value and deflated
    # ones both (a box of one value written over a whole tile, random values elsewhere)
    rng = np.random.default_rng(9)
    h, w = 40, 53
    cells, want = canvas_cells.cells_for(h, w), np.full((h, w), -1, dtype=np.int8)
    assert cells.packed == (store == "packed")
    for _ in range(200):
        y, x = int(rng.integers(0, h)), int(rng.integers(0, w))
        bh, bw = int(rng.integers(0, h - y + 1)), int(rng.integers(0, w - x + 1))
        values = rng.choice(np.array([-1, 0, 100], dtype=np.int8), (bh, bw)) if rng.random() < 0.5 else \
            np.full((bh, bw), rng.choice([-1, 0, 100]), dtype=np.int8)
        cells.write(y, x, values)
        want[y:y + bh, x:x + bw] = values
        y, x = int(rng.integers(0, h)), int(rng.integers(0, w))
        bh, bw = int(rng.integers(0, h - y + 1)), int(rng.integers(0, w - x + 1))
        np.testing.assert_array_equal(cells.cells_of(y, x, bh, bw), want[y:y + bh, x:x + bw])
    np.testing.assert_array_equal(np.frombuffer(cells.whole(), dtype=np.int8).reshape(h, w), want)
    # full maps: the last window back to -1 (outside it every cell is -1 already), the new written
    every, old, win = NS(x=0, y=0, w=w, h=h), NS(x=3, y=4, w=20, h=10), NS(x=30, y=1, w=20, h=30)
    new = rng.integers(-1, 101, (win.h, win.w), dtype=np.int8)
    cells.replace(None, every, want)
    cells.replace(every, old, want[old.y:old.y + old.h, old.x:old.x + old.w])
    data = cells.replace(old, win, new)
    want[:] = -1
    want[win.y:win.y + win.h, win.x:win.x + win.w] = new
    for got in (data, cells.whole()):
        np.testing.assert_array_equal(np.frombuffer(got, dtype=np.int8).reshape(h, w), want)
    if store == "packed":
        assert 0 < cells.packed_bytes() < h * w
