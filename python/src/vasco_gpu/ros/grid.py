"""A finished map as nav_msgs/OccupancyGrid values: row-major from the lower-left cell, x along a
row (CARMEN's cells are x-major: the transpose), int8 in [0, 100] or -1 unknown.

``trinary`` is what map_server's loader makes of a map_saver picture (occupied above
occupied_thresh, free below free_thresh, unknown between), ``scale`` keeps the probability:
round(100 p), halves rounded up. No rclpy here."""

from __future__ import annotations

import math
from array import array

from .. import _core

__all__ = ["grid_values", "finished_grid", "fill_grid", "array_keeping_message"]

# The map output's rows (vasco_gpu/pipeline/map_output_options.h): map_mode's choices and the
# thresholds' defaults.
_ROWS = {row["name"]: row for row in _core.option_schema("map_output")}
_MAP_MODES = tuple(_ROWS["map_mode"]["choices"])


def _map_mode(mode: str) -> str:
    # The engine also takes "raw" for scale (carmen_compat's name for the mode); the node's
    # map_mode is one of the row's choices only.
    if mode not in _MAP_MODES:
        raise ValueError(f"map_mode {mode!r} is not {' or '.join(_MAP_MODES)}")
    return mode


def grid_values(m, mode: str, free_thresh: float = _ROWS["free_thresh"]["default"],
                occupied_thresh: float = _ROWS["occupied_thresh"]["default"], out=None):
    """(size_y * size_x) int8 OccupancyGrid data of map m (-1: unknown): new bytes, or written
    into out (a writable buffer of that many bytes, returned). In C++
    (carmen_compat/occupancy_grid.h): fr101's 1302 x 1267 cells took 1.7 ms there on the 2-core
    machine, 5.4 ms in NumPy."""
    return _core._occupancy_grid_data(m, _map_mode(mode), free_thresh, occupied_thresh, out)


def finished_grid(mapper, mode: str, free_thresh: float, occupied_thresh: float, out=None):
    """A session's finish as OccupancyGrid data: ((size_x, size_y, resolution, origin), data),
    the values grid_values gives for mapper.finish(), converted where the grid is (on the GPU
    for cuda, which then sends a byte a cell instead of a float). data is out (a writable
    buffer) when the map has its size, else new bytes."""
    return mapper._finish_occupancy_grid(_map_mode(mode), free_thresh, occupied_thresh, out)


def array_keeping_message(cls):
    """A message of cls whose array fields keep the array('b') given: with check_fields=True
    rclpy's generated setters check an array instead of copying it, where by default (Kilted,
    Jazzy) each /map's data would be copied once more, a byte a cell held beside the canvas (a
    map of 2e8 cells: 200 MB and 0.3 s a /map). Messages of a distribution that takes no such
    keyword (Humble: its constructor asserts) are made plain."""
    try:
        return cls(check_fields=True)
    except (AssertionError, TypeError):
        return cls()


def fill_grid(msg, frame_of_map, data, *, frame: str, stamp) -> array:
    """Fills a nav_msgs/OccupancyGrid (or anything shaped like one) with a finished map:
    frame_of_map (size_x, size_y, resolution, origin) and its data (finished_grid's), as an
    array('b'): data itself when it is one (the previous message's, written again), else a new
    array of its bytes. Returns the array."""
    size_x, size_y, resolution, (x, y, theta) = frame_of_map
    msg.header.frame_id = frame
    msg.header.stamp = stamp
    info = msg.info
    info.map_load_time = stamp
    info.resolution = float(resolution)
    info.width, info.height = int(size_x), int(size_y)
    info.origin.position.x, info.origin.position.y, info.origin.position.z = float(x), float(y), 0.0
    info.origin.orientation.z = math.sin(theta / 2.0)
    info.origin.orientation.w = math.cos(theta / 2.0)
    # array('b'): assigning a NumPy array to an rclpy message's data field converts element by
    # element (~60x slower for a 2000 x 2000 map). Written in place where the size is the
    # same: a new map-sized buffer for each map cost page faults each time.
    if not (isinstance(data, array) and data.typecode == "b"):
        data = array("b", data)
    msg.data = data
    return data
