"""A finished map as nav_msgs/OccupancyGrid values: row-major from the lower-left cell, x along a
row (CARMEN's cells are x-major: the transpose), int8 in [0, 100] or -1 unknown.

``trinary`` is what map_server's loader makes of a map_saver picture (occupied above
occupied_thresh, free below free_thresh, unknown between), ``scale`` keeps the probability:
round(100 p), halves rounded up. No rclpy here."""

from __future__ import annotations

import math
from array import array

import numpy as np

__all__ = ["grid_values", "fill_grid"]


def grid_values(cells: np.ndarray, mode: str, free_thresh: float = 0.196,
                occupied_thresh: float = 0.65) -> np.ndarray:
    """(size_y * size_x,) int8 OccupancyGrid data of x-major cells (-1: unknown, else p)."""
    # (size_y, size_x), row y; float64, so that the thresholds compare as map_server's doubles do
    p = np.ascontiguousarray(np.asarray(cells, dtype=np.float32).T).astype(np.float64)
    known = (p >= 0) & (p <= 1)
    out = np.full(p.shape, -1, dtype=np.int8)
    if mode == "scale":
        out[known] = np.floor(p[known] * 100.0 + 0.5).astype(np.int8)
    elif mode == "trinary":
        out[known & (p > occupied_thresh)] = 100
        out[known & (p < free_thresh)] = 0
    else:
        raise ValueError(f"map_mode {mode!r} is not trinary or scale")
    return out.ravel()


def fill_grid(msg, m, *, mode: str, frame: str, stamp, free_thresh: float, occupied_thresh: float) -> None:
    """Fills a nav_msgs/OccupancyGrid (or anything shaped like one) with map m."""
    msg.header.frame_id = frame
    msg.header.stamp = stamp
    info = msg.info
    info.map_load_time = stamp
    info.resolution = float(m.resolution)
    info.width, info.height = int(m.size_x), int(m.size_y)
    x, y, theta = m.origin
    info.origin.position.x, info.origin.position.y, info.origin.position.z = float(x), float(y), 0.0
    info.origin.orientation.z = math.sin(theta / 2.0)
    info.origin.orientation.w = math.cos(theta / 2.0)
    values = grid_values(m.cells, mode, free_thresh, occupied_thresh)
    # array('b') filled from bytes: assigning a NumPy array to an rclpy message's data field
    # converts element by element (~60x slower for a 2000 x 2000 map).
    data = array("b")
    data.frombytes(values.tobytes())
    msg.data = data
