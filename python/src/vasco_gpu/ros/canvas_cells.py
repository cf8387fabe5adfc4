"""The cells of a canvas (canvas.py): the last /map with its updates applied, which the node keeps
to compute each update as a difference from it, and to answer ~/dynamic_map. Two stores of the
same cells, chosen by the canvas's size:

- ``PlainCells``: one byte a cell in one array, written in place from one publication to the next
  (a small map made anew for each /map page-faults its bytes each time: most publications are
  of maps of a few MB, and latency matters there).
- ``PackedCells``: square tiles of ``TILE`` cells a side, each either one value (a tile all
  unknown, or all free) or its bytes deflated (zlib, level 1). A large site's canvas is mostly
  such tiles: its /map is held once already, by the DDS writer's latched sample (a byte a
  cell, the floor for any node that latches /map), and a plain canvas beside it would double
  that (a 2.2e8-cell map: 222 MB more). An update reads and writes only the tiles its box
  meets; a full map is made as an array for the message and packed from it; ~/dynamic_map's
  map is unpacked for the answer. What each costs is measured by bench/large_site_bench.py.

Both give ``cells_of`` (a box's values), ``write`` (a box's new values), ``replace`` (a full
map: the last window cleared to -1, the new one written, the whole canvas as an array('b')
for the message) and ``whole`` (the canvas as an array('b'))."""

from __future__ import annotations

import zlib
from array import array

import numpy as np

__all__ = ["PACKED_CANVAS_BYTES", "TILE", "PlainCells", "PackedCells", "cells_for"]

# Canvases of more cells than this are packed: past it a plain canvas costs more memory than its
# page faults would cost time (the finish's own buffer is dropped past the same size).
PACKED_CANVAS_BYTES = 16 << 20
TILE = 256  # a tile's side, cells: 64 KB, about what an update's box meets of a few of them
_LEVEL = 1  # zlib's fastest: the tiles are runs of -1, 0 and 100


def cells_for(h: int, w: int):
    """The store for an (h, w) canvas, every cell -1: packed past PACKED_CANVAS_BYTES."""
    return PackedCells(h, w) if h * w > PACKED_CANVAS_BYTES else PlainCells(h, w)


class PlainCells:
    packed = False

    def __init__(self, h: int, w: int):
        self.h, self.w = h, w
        self._data = array("b", b"\xff") * (h * w)
        self._cells = np.frombuffer(self._data, dtype=np.int8).reshape(h, w)

    def cells_of(self, y: int, x: int, h: int, w: int) -> np.ndarray:
        """The box's cells: a view, valid until the next write."""
        return self._cells[y:y + h, x:x + w]

    def write(self, y: int, x: int, values: np.ndarray) -> None:
        self._cells[y:y + values.shape[0], x:x + values.shape[1]] = values

    def replace(self, old, win, cells: np.ndarray) -> array:
        """A full map: `old` (a window, or None) back to -1, `cells` written at `win`; the canvas's
        own array (written in place by the next publications)."""
        if old is not None:
            self._cells[old.y:old.y + old.h, old.x:old.x + old.w] = -1
        self.write(win.y, win.x, cells)
        return self._data

    def whole(self) -> array:
        return self._data


class PackedCells:
    packed = True

    def __init__(self, h: int, w: int):
        self.h, self.w = h, w
        self._tile = TILE
        ty, tx = -(-h // self._tile), -(-w // self._tile)
        # a tile: an int (every cell that value) or bytes (its cells deflated, row-major)
        self._tiles: list[list[int | bytes]] = [[-1] * tx for _ in range(ty)]

    def _shape(self, ty: int, tx: int) -> tuple[int, int]:
        t = self._tile
        return min(t, self.h - ty * t), min(t, self.w - tx * t)

    def _unpack(self, ty: int, tx: int) -> np.ndarray:
        tile, shape = self._tiles[ty][tx], self._shape(ty, tx)
        if isinstance(tile, int):
            return np.full(shape, tile, dtype=np.int8)
        return np.frombuffer(zlib.decompress(tile), dtype=np.int8).reshape(shape).copy()

    @staticmethod
    def _pack(cells: np.ndarray) -> int | bytes:
        first = int(cells.flat[0])
        if (cells == first).all():
            return first
        return zlib.compress(np.ascontiguousarray(cells).tobytes(), _LEVEL)

    def _tiles_of(self, y: int, x: int, h: int, w: int):
        """(ty, tx, the box's part of the tile in tile cells, the same in box cells) for every
        tile the box meets."""
        t = self._tile
        for ty in range(y // t, (y + h - 1) // t + 1):
            r0, r1 = max(y, ty * t), min(y + h, (ty + 1) * t)
            for tx in range(x // t, (x + w - 1) // t + 1):
                c0, c1 = max(x, tx * t), min(x + w, (tx + 1) * t)
                yield ty, tx, (slice(r0 - ty * t, r1 - ty * t), slice(c0 - tx * t, c1 - tx * t)), \
                    (slice(r0 - y, r1 - y), slice(c0 - x, c1 - x))

    def _every_tile(self):
        """(ty, tx, the tile's cells in the canvas as a pair of slices) for every tile."""
        t = self._tile
        for ty, row in enumerate(self._tiles):
            for tx in range(len(row)):
                yield ty, tx, (slice(ty * t, (ty + 1) * t), slice(tx * t, (tx + 1) * t))

    def cells_of(self, y: int, x: int, h: int, w: int) -> np.ndarray:
        """The box's cells: a copy."""
        out = np.empty((h, w), dtype=np.int8)
        if h > 0 and w > 0:
            for ty, tx, in_tile, in_box in self._tiles_of(y, x, h, w):
                tile = self._tiles[ty][tx]
                out[in_box] = tile if isinstance(tile, int) else self._unpack(ty, tx)[in_tile]
        return out

    def write(self, y: int, x: int, values: np.ndarray) -> None:
        h, w = values.shape
        if h == 0 or w == 0:
            return
        for ty, tx, in_tile, in_box in self._tiles_of(y, x, h, w):
            if (in_tile[0].stop - in_tile[0].start, in_tile[1].stop - in_tile[1].start) == self._shape(ty, tx):
                self._tiles[ty][tx] = self._pack(values[in_box])  # the whole tile: nothing to unpack
                continue
            cells = self._unpack(ty, tx)
            cells[in_tile] = values[in_box]
            self._tiles[ty][tx] = self._pack(cells)

    def replace(self, old, win, cells: np.ndarray) -> array:
        """A full map: a new array of the canvas (-1 but `cells` at `win`), packed here. The
        array is the message's: the caller drops it once published."""
        data = array("b", b"\xff") * (self.h * self.w)
        whole = np.frombuffer(data, dtype=np.int8).reshape(self.h, self.w)
        whole[win.y:win.y + win.h, win.x:win.x + win.w] = cells
        for ty, tx, in_canvas in self._every_tile():
            self._tiles[ty][tx] = self._pack(whole[in_canvas])
        return data

    def whole(self) -> array:
        """The canvas unpacked, a new array('b')."""
        data = array("b", bytes(self.h * self.w))
        whole = np.frombuffer(data, dtype=np.int8).reshape(self.h, self.w)
        for ty, tx, in_canvas in self._every_tile():
            whole[in_canvas] = self._unpack(ty, tx)
        return data

    def packed_bytes(self) -> int:
        """What the tiles hold (deflated bytes; a one-value tile counts nothing)."""
        return sum(len(tile) for row in self._tiles for tile in row if isinstance(tile, bytes))
