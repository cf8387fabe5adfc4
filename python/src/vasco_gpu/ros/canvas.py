"""The published map's geometry (the canvas) and its updates: what /map and map_updates carry.
No rclpy here: the node feeds it each finished map (LiveMap.finish_grid's) and publishes what it
gives back.

The lattice. A finished map is CARMEN's finish of the mapper's frame: blocks of ``downsample``
fine cells counted from the frame's cell 0, cropped to the known box plus the border. Its cell
(i, j) covers the world square from (x0 + (kx + i ds) r, y0 + (ky + j ds) r), r the fine
resolution, (x0, y0) the frame's centre, kx, ky whole fine cells (the grid axes are the world
axes: the origin's theta is 0). A canvas is a rectangle of such blocks, all of one lattice
(x0, y0, r, ds, theta, and kx mod ds); the finished map is a window of it, the cells outside it
-1. Its origin is computed as CARMEN computes a finished map's, ``k r + x0`` (the library is
built with -ffp-contract=off), so a canvas that is exactly the finished map has the finished
map's origin floats, bit for bit, and two canvases with a cell in common agree on it. A frame
that grows keeps (x0, y0) but can move the blocks (kx mod ds changes with the frame's half
size when ds > 1); a re-render can move (x0, y0); the resolution can change: each is a new
lattice, and a new canvas.

Growth (growing mode). The first canvas is the finished map itself (the first /map is what it
was without a canvas). A window that leaves its canvas on the same lattice grows the canvas:
each side that must grow becomes max(the span of old canvas and window, f x the old side),
f = 2 when one side grows and 1.5 when both do, so the area at least doubles; the side that
did not overflow keeps its place, so the margin lies where the map grew, and the new canvas
holds the old one. A new lattice makes a new canvas centred on the window, as large as the old
one where the window fits (the canvas never shrinks, except on reset), by the growth rule where
it does not. A side chosen anew differs from the window's side by an even number of cells.
Cost: one byte per canvas cell for the canvas kept here (a large canvas is packed, far less:
canvas_cells.py), one more per copy of it the node's message holds; after a growth a side is
at most twice the map's (plus a cell), so a canvas holds up to 4 x the map's cells, about 2 x
on average (intel at 0.025 m, batches of 10 scans: a 2327 x 2636 canvas, 6.1 MB, for the final
1297 x 1326 map). A map that grows to n times its first area grows its canvas O(log n) times
(intel: 4 growths, 5 full maps, 86 updates in 91 publications). A new lattice is a geometry
change too: a full /map, which nav2's static layer takes as a resize. With ds > 1 a growing
frame moves its blocks often (intel at 0.05 m, ds 2: 9 new lattices in the same 91
publications); a fixed frame never does.

Fixed mode (a frame that never moves): the canvas is the frame's whole block extent, blocks
[0, n - 1) of n = size // ds (CARMEN's crop never reaches block n - 1): every finished map
lies in it, so its geometry never changes and inserts give only updates.

What is published. After scans were inserted, the update is the bounding box of the cells
whose value differs from the last published canvas, row-major int8 (or nothing when none
does). After a re-render (a Path, new parameters) a full /map is sent: every stored
scan may have moved, so the box is usually the whole map anyway, and a full /map is what a
subscriber that missed an update or joined late (the latched /map) can start from again. A
geometry change is always a full /map.

The invariant: the canvas kept here is the last /map with every update since applied to it,
and each update is computed as its difference from the next canvas (exact by construction):
applying every update since a full map to it gives exactly the next full map.
"""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass

import numpy as np

from .canvas_cells import cells_for

__all__ = ["Canvas", "FullMap", "MapUpdate", "fill_update"]

# A side that must grow: the factor on the old side when one side grows, and when both do
# (1.5^2 = 2.25): the area at least doubles either way.
_GROW_ONE = 2.0
_GROW_BOTH = 1.5


@dataclass(frozen=True)
class FullMap:
    """A whole /map: geometry (size_x, size_y, resolution, (x, y, theta)) as grid.fill_grid
    takes it, and data, the canvas row-major from the lower-left cell (int8, -1 unknown). A plain
    canvas's data is its own array: later publications write into it (in place while the size is
    the same), so it always holds the last /map with its updates applied; a packed one's is made
    for this map alone (Canvas.packed)."""

    geometry: tuple
    data: array


@dataclass(frozen=True)
class MapUpdate:
    """A changed rectangle of the canvas (map_msgs/OccupancyGridUpdate): x, y of its lower-left
    cell and its size, in canvas cells; data (width * height int8) row-major."""

    x: int
    y: int
    width: int
    height: int
    data: array


@dataclass(frozen=True)
class _Lattice:
    x0: float
    y0: float
    fine: float     # the mapper's cell, metres
    ds: int         # fine cells per map cell
    theta: float
    phase_x: int    # kx mod ds: where the blocks start
    phase_y: int


@dataclass(frozen=True)
class _Rect:
    """A rectangle of map cells: x, y of its lower-left cell, in blocks from the lattice's
    centre (canvas rectangles) or from the canvas's corner (windows in a canvas)."""

    x: int
    y: int
    w: int
    h: int

    def holds(self, o: _Rect) -> bool:
        return self.x <= o.x and self.y <= o.y and o.x + o.w <= self.x + self.w and o.y + o.h <= self.y + self.h

    def union(self, o: _Rect) -> _Rect:
        x, y = min(self.x, o.x), min(self.y, o.y)
        return _Rect(x, y, max(self.x + self.w, o.x + o.w) - x, max(self.y + self.h, o.y + o.h) - y)


def _locate(finished, frame) -> tuple[_Lattice, _Rect]:
    """The lattice of a finished map ((size_x, size_y, resolution, origin), data) of `frame`
    (x0, y0, resolution: the mapper's frame), and its rectangle in blocks from the centre."""
    (size_x, size_y, resolution, (ox, oy, theta)), _ = finished
    fine = float(frame.resolution)
    ds = round(resolution / fine)
    kx, ky = round((ox - frame.x0) / fine), round((oy - frame.y0) / fine)
    if ds < 1 or abs(kx * fine + frame.x0 - ox) > fine / 4 or abs(ky * fine + frame.y0 - oy) > fine / 4:
        raise ValueError(f"a map at ({ox}, {oy}), cell {resolution} m, is not of the frame {frame}")
    lattice = _Lattice(float(frame.x0), float(frame.y0), fine, ds, float(theta), kx % ds, ky % ds)
    return lattice, _Rect(kx // ds, ky // ds, int(size_x), int(size_y))


def _growth(out_x: bool, out_y: bool) -> float:
    return _GROW_BOTH if out_x and out_y else _GROW_ONE


def _chosen_side(side: int, window_side: int) -> int:
    """side, one more where it differs from window_side by an odd number of cells."""
    return side + (side - window_side) % 2


class Canvas:
    """The geometry /map keeps and the last canvas published. ``publish`` takes each finished
    map and gives what to send: a FullMap, a MapUpdate, or None (no cell changed)."""

    def __init__(self, *, fixed: bool = False):
        self.fixed = fixed  # the frame never moves: the canvas is its whole extent
        self.reset()

    def reset(self) -> None:
        """Forgets the canvas: the next publication is a full map exactly the size of its map."""
        self._lattice: _Lattice | None = None
        self._rect: _Rect | None = None     # the canvas, in blocks from the lattice's centre
        self._window: _Rect | None = None   # the last finished map, in canvas cells
        self._cells = cells_for(0, 0)
        self.growths = 0    # canvases made for a window that left its canvas on the same lattice
        self.lattices = 0   # canvases made for a new lattice (the first one included)

    @property
    def packed(self) -> bool:
        """The canvas is packed (canvas_cells.py): a FullMap's data is not kept here."""
        return self._cells.packed

    @property
    def geometry(self) -> tuple | None:
        """(size_x, size_y, resolution, (x, y, theta)) of the canvas; None before a map."""
        if self._rect is None:
            return None
        lat, r = self._lattice, self._rect
        # CARMEN's world_x of the canvas's first cell, (k - size/2) r + x0 with k - size/2 = kx
        origin = ((r.x * lat.ds + lat.phase_x) * lat.fine + lat.x0, (r.y * lat.ds + lat.phase_y) * lat.fine + lat.y0,
                  lat.theta)
        return r.w, r.h, lat.fine * lat.ds, origin

    def current(self) -> FullMap | None:
        """The canvas as last published with its updates (what a GetMap answers); None before
        a map."""
        return None if self._rect is None else FullMap(self.geometry, self._cells.whole())

    def publish(self, finished, frame, *, full: bool = False, reach=None) -> FullMap | MapUpdate | None:
        """What to publish for `finished` (LiveMap.finish_grid's ((size_x, size_y, resolution,
        origin), data)), a map of `frame` (the mapper's frame: x0, y0, resolution, size_x,
        size_y). full: every scan was rendered again (a Path, new parameters), a full map
        is due. A full map also when the canvas changes; else the changed rectangle, or None.
        reach: a world box (x0, y0, x1, y1) outside which no cell changed since the last
        publication (LiveMap.reach), or None: only the cells in it are compared."""
        lattice, window = _locate(finished, frame)
        (size_x, size_y, _, _), data = finished
        cells = np.frombuffer(data, dtype=np.int8, count=size_x * size_y).reshape(size_y, size_x)
        rect = self._fit(lattice, window, frame)
        if rect is None and not full:
            return self._update(cells, self._in_canvas(window), None if reach is None else self._cells_of(reach))
        size_changed = False
        if rect is not None:
            size_changed = self._rect is None or (rect.w, rect.h) != (self._rect.w, self._rect.h)
            self._lattice, self._rect = lattice, rect
        return self._full(cells, self._in_canvas(window), size_changed)

    def _in_canvas(self, window: _Rect) -> _Rect:
        return _Rect(window.x - self._rect.x, window.y - self._rect.y, window.w, window.h)

    # -- the canvas's rectangle ------------------------------------------------------------
    def _fit(self, lattice: _Lattice, window: _Rect, frame) -> _Rect | None:
        """The canvas for a finished map at `window` (blocks from the lattice's centre): a new
        rectangle, or None where the canvas holds it."""
        if self._rect is not None and lattice == self._lattice:
            if self._rect.holds(window):
                return None
            self.growths += 1
            return self._grown(window)
        self.lattices += 1
        if self.fixed:
            whole = self._frame_rect(lattice, frame)
            if whole.holds(window):
                return whole
        if self._rect is None:
            return window
        return self._around(window)

    @staticmethod
    def _frame_rect(lattice: _Lattice, frame) -> _Rect:
        """A frame's whole extent in blocks: blocks [0, n - 1) of n = size // ds from its cell
        0, which lies size / 2 fine cells below the centre (the sizes are even)."""
        ds = lattice.ds
        return _Rect(-(int(frame.size_x) // 2) // ds, -(int(frame.size_y) // 2) // ds,
                     max(int(frame.size_x) // ds - 1, 0), max(int(frame.size_y) // ds - 1, 0))

    def _grown(self, window: _Rect) -> _Rect:
        """The canvas grown to hold `window` on the same lattice: each side the window leaves
        grows to max(the span of canvas and window, f x the side), on the side it left."""
        c, u = self._rect, self._rect.union(window)
        out_x, out_y = u.w > c.w, u.h > c.h  # u holds c: it is larger where the window left c
        f = _growth(out_x, out_y)

        def axis(start, side, ustart, uside, wside, out):
            if not out:
                return start, side
            new = _chosen_side(max(uside, math.ceil(f * side)), wside)
            if ustart == start:          # left where it was: the margin goes where it grew
                return start, new
            if ustart + uside == start + side:
                return start + side - new, new
            return ustart - (new - uside) // 2, new

        x, w = axis(c.x, c.w, u.x, u.w, window.w, out_x)
        y, h = axis(c.y, c.h, u.y, u.h, window.h, out_y)
        return _Rect(x, y, w, h)

    def _around(self, window: _Rect) -> _Rect:
        """A canvas on a new lattice, centred on `window`: the old sides where it fits, grown
        by the growth rule where it does not."""
        c = self._rect
        out_x, out_y = window.w > c.w, window.h > c.h
        f = _growth(out_x, out_y)
        w = _chosen_side(max(window.w, math.ceil(f * c.w)), window.w) if out_x else c.w
        h = _chosen_side(max(window.h, math.ceil(f * c.h)), window.h) if out_y else c.h
        return _Rect(window.x - (w - window.w) // 2, window.y - (h - window.h) // 2, w, h)

    # -- what is sent ----------------------------------------------------------------------
    def _full(self, cells: np.ndarray, win: _Rect, size_changed: bool) -> FullMap:
        r, old = self._rect, self._window  # outside the last window every cell is -1 already
        if size_changed:
            self._cells, old = cells_for(r.h, r.w), None  # every cell -1
        data = self._cells.replace(old, win, cells)
        self._window = win
        return FullMap(self.geometry, data)

    def _cells_of(self, reach) -> _Rect:
        """A world box's canvas cells, one of margin a side, clipped to the canvas (empty for
        an empty box)."""
        x0, y0, x1, y1 = reach
        _, _, cell, (ox, oy, _) = self.geometry
        r = self._rect

        def first_end(lo: float, hi: float, origin: float, n: int) -> tuple[int, int]:
            if not lo <= hi:
                return 0, 0
            first = math.floor(min(max((lo - origin) / cell - 1, 0.0), float(n)))
            end = math.floor(min(max((hi - origin) / cell + 2, 0.0), float(n)))
            return first, end

        cx, ex = first_end(x0, x1, ox, r.w)
        cy, ey = first_end(y0, y1, oy, r.h)
        return _Rect(cx, cy, max(ex - cx, 0), max(ey - cy, 0))

    def _update(self, cells: np.ndarray, win: _Rect, reach: _Rect | None) -> MapUpdate | None:
        """The bounding box of the cells that differ from the canvas, written into it; only those
        in `reach` (canvas cells) are compared where the window is the last one (a crop that
        widens brings in cells known before but never published, which no scan since touched)."""
        old = self._window
        region = win if win.holds(old) else win.union(old)
        if region is win:
            new = cells
        else:  # the window left cells of the last one: -1 there now
            new = np.full((region.h, region.w), -1, dtype=np.int8)
            new[win.y - region.y:win.y - region.y + win.h, win.x - region.x:win.x - region.x + win.w] = cells
        self._window = win
        if reach is not None and win == old:
            x, y = max(region.x, reach.x), max(region.y, reach.y)
            w, h = min(region.x + region.w, reach.x + reach.w) - x, min(region.y + region.h, reach.y + reach.h) - y
            if w <= 0 or h <= 0:
                return None
            new = new[y - region.y:y - region.y + h, x - region.x:x - region.x + w]
            region = _Rect(x, y, w, h)
        now = self._cells.cells_of(region.y, region.x, region.h, region.w)
        # the whole window compared: 0.7 ms for a 2000 x 2000 canvas with nothing changed on
        # the 2-core machine, a box of the whole canvas costs its copy besides (2 to 6 ms); a
        # batch's reach is a few hundred cells a side
        changed = now != new
        rows = np.flatnonzero(changed.any(axis=1))
        if rows.size == 0:
            return None
        cols = np.flatnonzero(changed.any(axis=0))
        r0, r1, c0, c1 = int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1
        patch = new[r0:r1, c0:c1]
        self._cells.write(region.y + r0, region.x + c0, patch)
        data = array("b")
        data.frombytes(patch.tobytes())
        return MapUpdate(region.x + c0, region.y + r0, c1 - c0, r1 - r0, data)


def fill_update(msg, update: MapUpdate, *, frame: str, stamp) -> array:
    """Fills a map_msgs/OccupancyGridUpdate (or anything shaped like one) with an update, as
    grid.fill_grid fills a /map. Returns its data (an array('b'))."""
    msg.header.frame_id = frame
    msg.header.stamp = stamp
    msg.x, msg.y = int(update.x), int(update.y)
    msg.width, msg.height = int(update.width), int(update.height)
    msg.data = update.data
    return update.data


def fixed_frame(size_m, origin_m, params) -> tuple:
    """The mapper's fixed frame for map_size [W, H] and map_origin [X, Y] (metres, the lower-left
    corner, axis-aligned): (Frame, (x0, y0)), the frame's fine cells and its centre, so that its
    whole block extent (the fixed canvas) starts at (X, Y) and covers at least W x H: n blocks of
    downsample fine cells a side, n = ceil(W / map cell) (1e-9 of a cell forgiven: 40 m at 0.05 m
    is 800 cells, not 801), in a frame of (n + 1) blocks (CARMEN's crop never reaches the
    last). (None, None) without map_size."""
    from .. import _core

    if not size_m:
        return None, None
    fine, ds = params.resolution, params.downsample
    cells = [(math.ceil(side / (fine * ds) - 1e-9) + 1) * ds for side in size_m]
    centre = tuple(o + c / 2 * fine for o, c in zip(origin_m, cells))
    return _core.Frame(cells[0], cells[1], fine, 0.0), centre
