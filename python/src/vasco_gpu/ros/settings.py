"""The node's parameters, one schema: the node's own (topics, frames, QoS, publishing, the
session's backend, ``resolution``: the map's cell as ROS says it) and every key of the mapper's
parameter table under its carmen.ini name, as log2map's flags spell them (``vasco_p_occ``,
``vasco_downsample``, ...; read from ``vasco_gpu.Params``, never listed here).

``Settings.from_values`` validates a whole set at once, so that a bad value is refused before
anything starts and a dynamic change is taken whole or not at all. No rclpy here: the node
declares what :data:`NODE_PARAMETERS` and :func:`mapper_parameter_names` name.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

from .. import _core
from ..bags.cloud import check_cloud_options

__all__ = ["NODE_PARAMETERS", "NodeParameter", "Settings", "SettingsError", "mapper_parameter_names"]


class SettingsError(ValueError):
    """A parameter value the node refuses; the message names the parameter."""


@dataclass(frozen=True)
class NodeParameter:
    name: str
    default: object
    meaning: str
    dynamic: bool = False  # may change while the node runs


def _choice(*names):
    def check(name, v):
        if v not in names:
            raise SettingsError(f"{name}: {v!r} is not one of {', '.join(names)}")
    return check


def _positive(name, v):
    if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
        raise SettingsError(f"{name}: {v!r} must be a finite number > 0")


def _not_negative(name, v):
    if isinstance(v, bool) or not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
        raise SettingsError(f"{name}: {v!r} must be a finite number >= 0")


def _topics(name, v):
    if not isinstance(v, (list, tuple)) or not all(isinstance(t, str) and t for t in v):
        raise SettingsError(f"{name}: {v!r} must be a list of topic names")


def _frame(name, v):
    if not isinstance(v, str) or not v.strip("/"):
        raise SettingsError(f"{name}: {v!r} must be a frame name")


def _threshold(name, v):
    if not (isinstance(v, (int, float)) and 0 <= v <= 1):
        raise SettingsError(f"{name}: {v!r} must be between 0 and 1")


def _whole(lo):
    def check(name, v):
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise SettingsError(f"{name}: {v!r} must be a whole number >= {lo}")
    return check


def _backend(name, v):
    if v not in _core.backend_names():
        raise SettingsError(f"{name}: {v!r} is not a backend ({', '.join(_core.backend_names())})")


def _string(name, v):
    if not isinstance(v, str):
        raise SettingsError(f"{name}: {v!r} must be a string")


def _band(name, v):
    if not (isinstance(v, (list, tuple)) and len(v) == 2 and all(isinstance(x, (int, float)) for x in v)):
        raise SettingsError(f"{name}: {v!r} must be two heights [min, max]")


def _cell(name, v):
    if isinstance(v, bool) or not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
        raise SettingsError(f"{name}: {v!r} must be a cell size in metres > 0 (0: vasco_resolution x "
                            f"vasco_downsample)")


def _paths(name, v):
    if not isinstance(v, (list, tuple)) or not all(isinstance(t, str) and t for t in v):
        raise SettingsError(f"{name}: {v!r} must be a list of file names")


# name, default, meaning, dynamic; the check of each value is in _CHECKS.
NODE_PARAMETERS = (
    NodeParameter("scan_topics", ["scan"], "sensor_msgs/LaserScan topics"),
    NodeParameter("multi_echo_topics", [], "sensor_msgs/MultiEchoLaserScan topics (one echo a beam: echo)"),
    NodeParameter("echo", "last", "the echo a MultiEchoLaserScan beam gives: first, last or strongest"),
    NodeParameter("cloud_topics", [], "sensor_msgs/PointCloud2 topics (3-D lidar: the points in z_band as beams)"),
    NodeParameter("z_band", [0.2, 1.8], "clouds: the heights kept, min and max, in metres in base_frame"),
    NodeParameter("cloud_angle_step", 0.25, "clouds: the beams' angle step in degrees (nearest point per step)"),
    NodeParameter("cloud_range_max", 50.0, "clouds: points farther than this (m) are no return"),
    NodeParameter("scan_qos", "sensor_data", "the scans' QoS: sensor_data (best effort, depth 100; clouds 5) or "
                                             "reliable (reliable, depth 1000: a replay loses no scan)"),
    NodeParameter("resolution", _core.ROS_MAP_RESOLUTION, "the map's cell size (m), /map's info.resolution, as log2map --resolution "
                                      "sets it (vasco_resolution = resolution / vasco_downsample; the downsample "
                                      "kept where given, else max(1, round(resolution / vasco_resolution))); 0: "
                                      "vasco_resolution x vasco_downsample alone", dynamic=True),
    NodeParameter("no_return", "skip", "+inf ranges (REP 117 no return): skip, or free (clears up to "
                                       "range_max)", dynamic=False),
    NodeParameter("map_frame", "map", "the fixed frame: the map's frame and the poses' frame"),
    NodeParameter("base_frame", "base_link", "the robot's frame, whose poses the Path carries"),
    NodeParameter("path_topic", "trajectory", "nav_msgs/Path of base_frame poses from the optimizer"),
    NodeParameter("transform_timeout", 0.5, "seconds a scan waits for its transform map_frame -> its frame"),
    NodeParameter("scan_batch_interval", 0.1, "seconds scans gather before they are posed and mapped together "
                                              "(one tf lookup, one insert: less CPU a scan); 0: each scan on "
                                              "arrival", dynamic=True),
    NodeParameter("pose_max_gap", 5.0, "seconds: a scan between two Path poses further apart keeps its pose"),
    NodeParameter("map_update_interval", 0.5, "seconds between two map publications at most", dynamic=True),
    NodeParameter("map_mode", "trinary", "OccupancyGrid values: trinary (0/100/-1 by the thresholds) or "
                                         "scale (round(100 p), -1 unknown)", dynamic=True),
    NodeParameter("free_thresh", 0.196, "trinary: p below it is free (0)", dynamic=True),
    NodeParameter("occupied_thresh", 0.65, "trinary: p above it is occupied (100)", dynamic=True),
    NodeParameter("save_map_path", [], "the files ~/save_map writes, one transaction (.map.gz, .pgm, .png, "
                                       "...)", dynamic=True),
    NodeParameter("param_file", "", "a carmen.ini with vasco_* keys (as log2map's --param-file)"),
    NodeParameter("robot", "", "the carmen.ini robot section (as log2map's --robot)"),
    NodeParameter("backend", "auto", "the mapping backend (as log2map's --backend)"),
    NodeParameter("cuda_mode", "float", "cuda's mode: float or exact"),
    NodeParameter("device", 0, "the CUDA device"),
    NodeParameter("threads", 0, "cpu_threads' threads (0: all cores)"),
    NodeParameter("max_memory", 2 << 30, "bytes the session may hold (scans and grid); 0: no limit"),
)

_CHECKS = {
    "scan_topics": _topics, "multi_echo_topics": _topics, "echo": _choice("first", "last", "strongest"),
    "resolution": _cell, "cloud_topics": _topics, "z_band": _band, "cloud_angle_step": _positive, "cloud_range_max": _positive,
    "scan_qos": _choice("sensor_data", "reliable"), "no_return": _choice("skip", "free"),
    "map_frame": _frame, "base_frame": _frame, "path_topic": _string,
    "transform_timeout": _positive, "scan_batch_interval": _not_negative,
    "pose_max_gap": _positive, "map_update_interval": _positive,
    "map_mode": _choice("trinary", "scale"), "free_thresh": _threshold, "occupied_thresh": _threshold,
    "save_map_path": _paths, "param_file": _string, "robot": _string, "backend": _backend,
    "cuda_mode": _choice("float", "exact"), "device": _whole(0), "threads": _whole(0), "max_memory": _whole(0),
}


def mapper_parameter_names() -> list[str]:
    """The mapper's keys as the node's parameter names (vasco_resolution, vasco_p_occ, ...), from
    the parameter table."""
    return list(_core.Params.keys())


@dataclass
class Settings:
    """A validated set of the node's parameters: ``node`` (name -> value, every NODE_PARAMETERS
    entry) and ``params`` (the mapper's Params: the keys given, over param_file, over vasco's
    defaults, as log2map ranks --vasco_KEY over --param-file)."""

    node: dict
    params: _core.Params
    given: dict = field(default_factory=dict)  # the mapper keys set as node parameters

    def __getattr__(self, name):
        try:
            return self.__dict__["node"][name]
        except KeyError:
            raise AttributeError(name) from None

    @classmethod
    def from_values(cls, node_values: dict, mapper_values: dict) -> "Settings":
        """node_values: the node's own parameters (missing ones take their default);
        mapper_values: the mapper keys that were set (keyword names). SettingsError naming the
        parameter for any bad value."""
        node = {p.name: node_values.get(p.name, p.default) for p in NODE_PARAMETERS}
        for name, value in node.items():
            if isinstance(value, tuple):
                node[name] = value = list(value)
            _CHECKS[name](name, value)
        if not node["free_thresh"] < node["occupied_thresh"]:
            raise SettingsError(f"free_thresh {node['free_thresh']} must be below occupied_thresh "
                                f"{node['occupied_thresh']}")
        if not node["scan_topics"] and not node["multi_echo_topics"] and not node["cloud_topics"]:
            raise SettingsError("scan_topics, multi_echo_topics and cloud_topics are all empty: nothing to map")
        try:
            check_cloud_options(tuple(float(v) for v in node["z_band"]), math.radians(node["cloud_angle_step"]),
                                float(node["cloud_range_max"]))
        except ValueError as e:
            raise SettingsError(str(e).replace("z_band (--z-band MIN,MAX)", "z_band").replace(
                "cloud_angle_step (--cloud-angle-step)", "cloud_angle_step").replace(
                "cloud_range_max (--cloud-range-max)", "cloud_range_max")) from None
        return cls(node, _mapper_params(node, mapper_values), dict(mapper_values))


def _mapper_params(node: dict, given: dict) -> _core.Params:
    """The mapper's Params: given keys over the param_file over the defaults, then resolution
    (the map's cell) by log2map --resolution's rule."""
    unknown = sorted(set(given) - set(mapper_parameter_names()))
    if unknown:
        raise SettingsError(f"{unknown[0]}: not a mapper parameter ({', '.join(mapper_parameter_names())})")
    cell = {"map_resolution": node["resolution"]} if node["resolution"] > 0 else {}
    if cell and "vasco_resolution" in given:
        raise SettingsError(f"vasco_resolution and resolution {node['resolution']} both set the cell size: set "
                            f"resolution (the map's cell), or resolution 0 to take vasco_resolution x vasco_downsample")
    try:
        if node["param_file"]:
            if not os.path.isfile(node["param_file"]):
                raise SettingsError(f"param_file: {node['param_file']!r} is not a file")
            return _core.Params.from_ini(node["param_file"], node["robot"], **given, **cell)
        return _core.Params(**given, **cell)
    except (TypeError, ValueError) as e:
        if isinstance(e, SettingsError):
            raise
        raise SettingsError(str(e)) from None
