"""A finished map as nav_msgs/OccupancyGrid values: row-major from the lower-left cell, x along a
row (CARMEN's cells are x-major: the transpose), int8 in [0, 100] or -1 unknown.

``trinary`` is what map_server's loader makes of a map_saver picture (occupied above
occupied_thresh, free below free_thresh, unknown between), ``scale`` keeps the probability:
round(100 p), halves rounded up. No rclpy here."""

from __future__ import annotations

import math
from array import array

from .. import _core

__all__ = ["grid_values", "fill_grid"]

# The node's map_mode -> the picture mode whose levels, read as int8, are the values
# (carmen_compat/occupancy_grid.h: "scale" is the raw picture's round(100 p)).
_DATA_MODES = {"trinary": "trinary", "scale": "raw"}


def grid_values(m, mode: str, free_thresh: float = 0.196, occupied_thresh: float = 0.65, out=None):
    """(size_y * size_x) int8 OccupancyGrid data of map m (-1: unknown): new bytes, or written
    into out (a writable buffer of that many bytes, returned). In C++
    (carmen_compat/occupancy_grid.h): fr101's 1302 x 1267 cells took 1.7 ms there on the 2-core
    machine, 5.4 ms in NumPy."""
    if mode not in _DATA_MODES:
        raise ValueError(f"map_mode {mode!r} is not trinary or scale")
    return _core._occupancy_grid_data(m, _DATA_MODES[mode], free_thresh, occupied_thresh, out)


def fill_grid(msg, m, *, mode: str, frame: str, stamp, free_thresh: float, occupied_thresh: float,
              data: array | None = None) -> array:
    """Fills a nav_msgs/OccupancyGrid (or anything shaped like one) with map m. Its data goes into
    ``data`` (an array('b') of a previous message, once that message is published) where the
    size is the same, else into a new array; returns the array used."""
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
    # array('b'): assigning a NumPy array to an rclpy message's data field converts element by
    # element (~60x slower for a 2000 x 2000 map). Written in place: a new map-sized buffer for
    # each map cost page faults each time.
    if data is None or len(data) != m.size_x * m.size_y:
        data = array("b", bytes(m.size_x * m.size_y))
    msg.data = grid_values(m, mode, free_thresh, occupied_thresh, out=data)
    return data
