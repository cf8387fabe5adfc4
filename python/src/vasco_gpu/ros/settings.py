"""The node's parameters, one schema: :data:`NODE_PARAMETERS` has a row a parameter (name, default,
help, check, and for a dynamic one the effect a change has on the running node), and every key of
the mapper's parameter table is a parameter too, under its carmen.ini name as log2map's flags
spell it (``vasco_p_occ``, ``vasco_downsample``, ...; read from ``vasco_gpu.Params``, never
listed here). Options another component defines are rows that take their default, choices or
bounds, and help from that component's table, not spelled again: the session's backend,
cuda_mode, cuda_device (``device``), threads and max_memory, the map output's map_mode and
thresholds and the pose source's largest gap from the C++ tables (:func:`core_option`), the scan
adapters' options from :mod:`vasco_gpu.msgs.scan_options`; a row narrows a check or a meaning
only where the node's is narrower, and says why.

From the rows: the validation (:meth:`Settings.from_values`, each value checked under its row's
name), the declared ROS parameters with their descriptors (:func:`declare_parameters`), what a
change does (:meth:`Settings.changed`) and the parameter table of docs/ros.md
(:func:`parameter_table`; ``python -m vasco_gpu.ros.settings`` prints it). Adding a parameter is a
row here and a test. rclpy is imported only inside :func:`declare_parameters`.
"""

from __future__ import annotations

import enum
import math
import os
from dataclasses import dataclass, field

from .. import _core
from .._errors import Error
from ..msgs.header import did_you_mean
from ..msgs.scan_options import SCAN_OPTIONS
from .posing import TIME_JUMP_S

__all__ = ["NODE_PARAMETERS", "Effect", "NodeParameter", "Settings", "SettingsError", "core_option",
           "declare_parameters", "map_files", "mapper_parameter_names", "parameter_table", "unknown_parameters"]


class SettingsError(Error, ValueError):
    """A parameter value the node refuses; the message names the parameter."""


class Effect(enum.Enum):
    """What a change of a dynamic parameter asks of the running node, in the order it is done;
    the value is the docs' words."""

    REMAP = "every stored scan mapped again"  # the mapper's Params changed: LiveMap.set_params
    PUBLISH_PERIOD = "the publishing timer's period"
    BATCH_PERIOD = "the scans gathered so far mapped, then batches at the new period"
    REPUBLISH = "the map published again"
    READ_WHEN_USED = "used the next time"  # nothing to do: the node reads it when it needs it


# -- checks: each knows its rule in words, and the range a ROS descriptor can carry -----------------
def _number_text(x) -> str:
    return "" if x is None else str(int(x)) if float(x).is_integer() else f"{x:g}"


@dataclass(frozen=True)
class Number:
    """A finite number (not a bool) within [lo, hi]; lo_open/hi_open leave the bound out; whole:
    an integer. words: the rule as the refusal says it, where the bounds alone do not."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    whole: bool = False
    words: str = ""

    def __call__(self, name, v):
        ok = isinstance(v, int if self.whole else (int, float)) and not isinstance(v, bool) and (
            isinstance(v, int) or math.isfinite(v))
        if not (ok and (self.lo is None or (v > self.lo if self.lo_open else v >= self.lo))
                and (self.hi is None or (v < self.hi if self.hi_open else v <= self.hi))):
            raise SettingsError(f"{name}: {v!r} must be {self.rule()}")

    def rule(self) -> str:
        if self.words:
            return self.words
        kind = "a whole number" if self.whole else "a finite number"
        lo, hi = _number_text(self.lo), _number_text(self.hi)
        if self.hi is None:
            return f"{kind} {'>' if self.lo_open else '>='} {lo}"
        if not (self.whole or self.lo_open or self.hi_open):
            return f"between {lo} and {hi}"
        return f"{kind} in {'(' if self.lo_open else '['}{lo}, {hi}{')' if self.hi_open else ']'}"

    def ros_range(self):
        """(lo, hi) for a descriptor's range: closed bounds only (ROS's ranges include both ends)."""
        if self.lo is None or self.lo_open or self.hi_open:
            return None
        top = (2**63 - 1 if self.whole else math.inf) if self.hi is None else self.hi
        return (self.lo, top)


@dataclass(frozen=True)
class Choice:
    """One of names; what: the refusal's word for them ("a backend"), else "one of"."""

    names: tuple
    what: str = ""

    def __call__(self, name, v):
        if v not in self.names:
            listed = ", ".join(self.names)
            raise SettingsError(f"{name}: {v!r} is not {self.what} ({listed})" if self.what else
                                f"{name}: {v!r} is not one of {listed}")

    def rule(self) -> str:
        return f"one of: {', '.join(self.names)}"

    def ros_range(self):
        return None


@dataclass(frozen=True)
class Text:
    """A string; kind "frame": not empty once its slashes are stripped."""

    kind: str = ""

    def __call__(self, name, v):
        if not isinstance(v, str) or (self.kind == "frame" and not v.strip("/")):
            raise SettingsError(f"{name}: {v!r} must be {self.rule()}")

    def rule(self) -> str:
        return "a frame name" if self.kind == "frame" else "a string"

    def ros_range(self):
        return None


@dataclass(frozen=True)
class Flag:
    """true or false (a ROS bool)."""

    def __call__(self, name, v):
        if not isinstance(v, bool):
            raise SettingsError(f"{name}: {v!r} must be {self.rule()}")

    def rule(self) -> str:
        return "true or false"

    def ros_range(self):
        return None


@dataclass(frozen=True)
class Names:
    """A list of non-empty strings: topic names or file names; single: one name alone is taken
    as a list of it (a params file's ``scan_topics: /scan``)."""

    kind: str
    single: bool = False

    def __call__(self, name, v):
        if not isinstance(v, (list, tuple)) or not all(isinstance(t, str) and t for t in v):
            raise SettingsError(f"{name}: {v!r} must be {self.rule()}")

    def rule(self) -> str:
        return f"a {self.kind} name or a list of them" if self.single else f"a list of {self.kind} names"

    def as_list(self, v):
        """v as the check takes it: one name a list of it, where single."""
        return [v] if self.single and isinstance(v, str) and v else v

    def ros_range(self):
        return None


@dataclass(frozen=True)
class Band:
    """Two finite heights [min, max], min < max."""

    def __call__(self, name, v):
        if not (isinstance(v, (list, tuple)) and len(v) == 2 and all(
                isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)
                and v[0] < v[1]):
            raise SettingsError(f"{name}: {v!r} must be {self.rule()}")

    def rule(self) -> str:
        return "two finite heights [min, max], min < max"

    def ros_range(self):
        return None


@dataclass(frozen=True)
class Pair:
    """[] or two finite numbers [a, b]; positive: both > 0. what: the refusal's words for them."""

    what: str
    positive: bool = False

    def __call__(self, name, v):
        numbers = isinstance(v, (list, tuple)) and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)
        if not (numbers and len(v) in (0, 2) and (not self.positive or all(x > 0 for x in v))):
            raise SettingsError(f"{name}: {v!r} must be {self.rule()}")

    def rule(self) -> str:
        return f"[] or {self.what}" + (" (both > 0)" if self.positive else "")

    def ros_range(self):
        return None


# -- the rows -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class NodeParameter:
    """One parameter of the node: effect None is a static one (read-only once started)."""

    name: str
    default: object
    check: object  # Number, Choice, Text, Names, Band or Pair: check(name, value) raises SettingsError
    help: str
    effect: Effect | None = None

    @property
    def dynamic(self) -> bool:
        return self.effect is not None

    @property
    def meaning(self) -> str:
        return self.help


def core_option(component: str, name: str) -> dict:
    """An option the engine or the pipeline defines ("session", "map_output", "pose_source"):
    {name, type, default, help, choices, lo, hi, lo_open, hi_open, ...} from that component's
    table (vasco_gpu/option_schema.h)."""
    for row in _core.option_schema(component):
        if row["name"] == name:
            return row
    raise KeyError(f"the {component} options have no {name!r}")


def _from_core(component: str, option: str, check, *, name: str = "", help: str = "",
               effect: Effect | None = None) -> NodeParameter:
    """A row for a component's option: its default, and its help unless the node's meaning is
    narrower (help); check: the node's check, built from the option's choices or bounds."""
    o = core_option(component, option)
    return NodeParameter(name or option, o["default"], check(o), help or o["help"], effect)


def _choices(o) -> Choice:
    """The option's choices as the check."""
    return Choice(tuple(o["choices"]))


def _bounds(**node_rule):
    """The option's bounds as the check (whole for a whole number); node_rule overrides them
    where the node's are narrower."""
    return lambda o: Number(**{"lo": o["lo"], "hi": o["hi"], "lo_open": o["lo_open"], "hi_open": o["hi_open"],
                               "whole": o["type"] in ("whole", "bytes"), **node_rule})


def _from_scan(name: str, check=None) -> NodeParameter:
    """A row for a scan adapters' option (vasco_gpu.msgs): its default and meaning; check: the
    node's, where the option has no choices."""
    o = next(o for o in SCAN_OPTIONS if o.name == name)
    default = list(o.default) if isinstance(o.default, tuple) else o.default
    return NodeParameter(name, default, check or Choice(o.choices), o.meaning)


# Seconds the node turns into a timer's period or a wait: rclpy keeps a period as int64
# nanoseconds (1e12 s overflows inside create_timer), so they are bounded, at a day: no
# interval or timeout of a live mapper is longer.
LONGEST_S = 86400.0
_SECONDS = Number(lo=0, lo_open=True, hi=LONGEST_S)  # a finite number in (0, a day]
_SESSION = "session"
_MAP_OUTPUT = "map_output"

NODE_PARAMETERS = (
    NodeParameter("scan_topics", ["scan"], Names("topic", single=True), "sensor_msgs/LaserScan topics"),
    NodeParameter("scan_topic", "", Text(), "slam_toolbox's key: the LaserScan topic, in place of scan_topics (both "
                  "set name the same topic, or the start is refused); '': scan_topics"),
    NodeParameter("multi_echo_topics", [], Names("topic"),
                  "sensor_msgs/MultiEchoLaserScan topics (one echo a beam: echo)"),
    _from_scan("echo"),
    NodeParameter("cloud_topics", [], Names("topic"),
                  "sensor_msgs/PointCloud2 topics (3-D lidar: the points in z_band as beams)"),
    _from_scan("z_band", Band()),
    # the bounds of the adapters' check_cloud_options (a test holds them equal)
    _from_scan("cloud_angle_step", Number(lo=0.01, hi=10)),
    _from_scan("cloud_range_max", Number(lo=0, hi=1000, lo_open=True)),
    NodeParameter("scan_qos", "sensor_data", Choice(("sensor_data", "reliable")),
                  "the scans' QoS: sensor_data (best effort, depth 100; clouds 5) or reliable (reliable, depth 1000: "
                  "a replay loses no scan)"),
    NodeParameter("resolution", _core.ROS_MAP_RESOLUTION,
                  Number(lo=0, words="a cell size in metres > 0 (0: vasco_resolution x vasco_downsample)"),
                  "the map's cell size (m), /map's info.resolution, as log2map --resolution sets it (vasco_resolution "
                  "= resolution / vasco_downsample; the downsample kept where given, else max(1, round(resolution / "
                  "vasco_resolution))); 0: vasco_resolution x vasco_downsample alone", Effect.REMAP),
    NodeParameter("max_laser_range", 0.0, Number(lo=0, words="a range in metres >= 0 (0: vasco_range_max)"),
                  "slam_toolbox's key: the longest range mapped (m), vasco_range_max; vasco_range_sure is lowered to "
                  "it where above it (logged once); 0: vasco_range_max alone", Effect.REMAP),
    NodeParameter("minimum_time_interval", 0.0, Number(lo=0),
                  "slam_toolbox's key: seconds; a scan whose stamp is closer than it to the last scan taken from its "
                  "topic is skipped (counted, not mapped); 0: none skipped", Effect.READ_WHEN_USED),
    NodeParameter("throttle_scans", 1, Number(lo=1, whole=True),
                  "slam_toolbox's key: every Nth scan of a topic is mapped, the others skipped (counted); 1: each",
                  Effect.READ_WHEN_USED),
    _from_scan("no_return"),
    NodeParameter("map_frame", "map", Text("frame"), "the fixed frame: the map's frame and the poses' frame"),
    NodeParameter("base_frame", "base_link", Text("frame"), "the robot's frame, whose poses the Path carries"),
    NodeParameter("odom_frame", "odom", Text("frame"),
                  "slam_toolbox's key, accepted and unused: the node publishes no transform (map -> odom is the "
                  "localization's, REP 105) and looks scans up from map_frame, through odom where the tree has it"),
    NodeParameter("path_topic", "trajectory", Text(), "nav_msgs/Path of base_frame poses from the optimizer"),
    NodeParameter("transform_timeout", 0.5, _SECONDS, "seconds a scan waits for its transform map_frame -> its frame"),
    # 60 s: a replay faster than real time still finds the transforms of the scans queued for it
    NodeParameter("tf_buffer_duration", 60.0, _SECONDS,
                  "seconds of stamps each /tf link keeps for the scans' lookups (tf2's cache time)"),
    NodeParameter("scan_batch_interval", 0.1, Number(lo=0, hi=LONGEST_S),
                  "seconds scans gather before they are posed and mapped together (one tf lookup, one insert: less "
                  "CPU a scan); 0: each scan on arrival", Effect.BATCH_PERIOD),
    # nanoseconds in the node: finite and > 0, where a pose file also takes 0 and inf; beyond
    # ROS time's span (292 years) it is no limit (max_gap_ns)
    _from_core("pose_source", "pose_max_gap", _bounds(lo=0, hi=None, lo_open=True, hi_open=False),
               help="seconds: a scan between two Path poses further apart keeps its pose (over 292 years, the span "
                    "of ROS time: no limit)"),
    NodeParameter("map_update_interval", 0.5, _SECONDS, "seconds between two map publications at most",
                  Effect.PUBLISH_PERIOD),
    _from_core(_MAP_OUTPUT, "map_mode", _choices, effect=Effect.REPUBLISH),
    # /map's values as well as the map_server files of save_map_path
    _from_core(_MAP_OUTPUT, "free_thresh", _bounds(), help="trinary: p below it is free (0)", effect=Effect.REPUBLISH),
    _from_core(_MAP_OUTPUT, "occupied_thresh", _bounds(), help="trinary: p above it is occupied (100)",
               effect=Effect.REPUBLISH),
    NodeParameter("map_size", [], Pair("[width, height] in metres", positive=True),
                  "a fixed grid: /map keeps this size, axis-aligned at map_origin (which it needs), while the scans "
                  "fall inside it (cells beyond it are not mapped, as CARMEN's fixed grids); []: the grid grows with "
                  "the scans, in large steps (docs/ros.md)"),
    NodeParameter("map_origin", [], Pair("[x, y] in metres"),
                  "the fixed grid's lower-left corner in map_frame (with map_size)"),
    NodeParameter("save_map_path", [], Names("file", single=True),
                  "the files ~/save_map writes, one transaction (.map.gz, .pgm, .png, ...); a name without a map "
                  "format's extension writes NAME.pgm + NAME.yaml, as map_saver", Effect.READ_WHEN_USED),
    NodeParameter("param_file", "", Text(), "a carmen.ini with vasco_* keys (as log2map's --param-file)"),
    NodeParameter("robot", "", Text(), "the carmen.ini robot section (as log2map's --robot)"),
    _from_core(_SESSION, "backend", lambda o: Choice(tuple(o["choices"]), "a backend")),
    _from_core(_SESSION, "cuda_mode", _choices),
    _from_core(_SESSION, "cuda_device", _bounds(), name="device"),
    _from_core(_SESSION, "threads", _bounds()),
    # bytes, a ROS integer (log2map's flag takes MiB)
    _from_core(_SESSION, "max_memory", _bounds(lo=0), help="bytes the session may hold (scans and grid); 0: no limit"),
    NodeParameter("on_time_jump", "reset", Choice(("reset", "keep")),
                  f"stamps (a scan topic's, a /tf link's) or /clock gone back over {TIME_JUMP_S:g} s (a bag played "
                  "again): reset starts a new map (as ~/reset), keep maps on over the stored scans; both clear tf's "
                  "history, as tf2 does", Effect.READ_WHEN_USED),
    NodeParameter("session_path", "", Text(),
                  "the file ~/save_session writes (stored scans, stamps, mounts, poses and the mapper parameters; one "
                  "transaction); '': ~/save_session refuses", Effect.READ_WHEN_USED),
    NodeParameter("load_session", "", Text(),
                  "a file ~/save_session wrote, restored at configure: the first /map equals the last one before "
                  "the restart; '': a new map"),
    NodeParameter("autostart", True, Flag(),
                  "configure and activate at start, as slam_toolbox; false: unconfigured until a lifecycle manager "
                  "(nav2's) configures and activates it"),
    NodeParameter("strict_parameters", False, Flag(),
                  "a parameter the node does not know (a params file's, the command line's) refuses the start (exit "
                  "2); false: one warning names them"),
)

_ROWS = {p.name: p for p in NODE_PARAMETERS}


def mapper_parameter_names() -> list[str]:
    """The mapper's keys as the node's parameter names (vasco_resolution, vasco_p_occ, ...), from
    the parameter table."""
    return list(_core.Params.keys())


# -- a validated set --------------------------------------------------------------------------------
@dataclass
class Settings:
    """A validated set of the node's parameters: ``node`` (name -> value, every NODE_PARAMETERS
    row) and ``params`` (the mapper's Params: the keys given, over param_file, over vasco's
    defaults, as log2map ranks --vasco_KEY over --param-file)."""

    node: dict
    params: _core.Params
    given: dict = field(default_factory=dict)  # the mapper keys set as node parameters
    notes: tuple = ()  # what the node changed on its own (a range lowered), for the log

    def __getattr__(self, name):
        try:
            return self.__dict__["node"][name]
        except KeyError:
            raise AttributeError(name) from None

    @property
    def max_gap_ns(self) -> int:
        """pose_max_gap in nanoseconds, at most ROS time's span (longer: no limit)."""
        ns = self.node["pose_max_gap"] * 1e9
        return 2**63 - 1 if ns >= 2**63 - 1 else int(ns)

    @classmethod
    def from_values(cls, node_values: dict, mapper_values: dict) -> "Settings":
        """node_values: the node's own parameters (missing ones take their default);
        mapper_values: the mapper keys that were set (keyword names). SettingsError naming the
        parameter for any bad value."""
        node = {}
        for p in NODE_PARAMETERS:
            value = node_values.get(p.name, p.default)
            value = p.check.as_list(value) if isinstance(p.check, Names) else value
            node[p.name] = value = list(value) if isinstance(value, tuple) else value
            p.check(p.name, value)
        if node["scan_topic"]:  # slam_toolbox's one topic in place of ours
            if node["scan_topics"] not in (_ROWS["scan_topics"].default, [node["scan_topic"]]):
                raise SettingsError(f"scan_topic {node['scan_topic']!r} and scan_topics {node['scan_topics']} both "
                                    f"name the LaserScan topics: set one")
            node["scan_topics"] = [node["scan_topic"]]
        if bool(node["map_size"]) != bool(node["map_origin"]):
            raise SettingsError(f"map_size {node['map_size']} and map_origin {node['map_origin']} go together: a fixed "
                                f"grid needs both, a growing one neither")
        if not node["free_thresh"] < node["occupied_thresh"]:
            raise SettingsError(f"free_thresh {node['free_thresh']} must be below occupied_thresh "
                                f"{node['occupied_thresh']}")
        if not node["scan_topics"] and not node["multi_echo_topics"] and not node["cloud_topics"]:
            raise SettingsError("scan_topics, multi_echo_topics and cloud_topics are all empty: nothing to map")
        params, notes = _mapper_params(node, mapper_values)
        return cls(node, params, dict(mapper_values), notes)

    def changed(self, values: dict) -> tuple["Settings", tuple[Effect, ...]]:
        """These settings with values (name -> value) over them, validated whole, and what the
        running node must do for them, in Effect's order (READ_WHEN_USED left out). A mapper key
        set to None is unset; a name that is not the node's (rclpy's use_sim_time) is passed
        over. SettingsError naming the parameter for a bad value or a static parameter."""
        node, given = dict(self.node), dict(self.given)
        mapper = set(mapper_parameter_names())
        for name, value in values.items():
            if name in _ROWS:
                if not _ROWS[name].dynamic:
                    raise SettingsError(f"{name}: read-only while the node runs")
                node[name] = value
            elif name in mapper and value is None:
                given.pop(name, None)
            elif name in mapper:
                given[name] = value
        new = Settings.from_values(node, given)
        effects = {p.effect for p in NODE_PARAMETERS if p.dynamic and new.node[p.name] != self.node[p.name]}
        effects.discard(Effect.REMAP)  # resolution's: only where the Params it makes differ
        if new.params != self.params:
            effects.add(Effect.REMAP)
        return new, tuple(e for e in Effect if e in effects and e is not Effect.READ_WHEN_USED)


def _mapper_params(node: dict, given: dict) -> tuple[_core.Params, tuple]:
    """(the mapper's Params, notes): given keys over the param_file over the defaults, then
    resolution (the map's cell) by log2map --resolution's rule and max_laser_range (the longest
    range); vasco_range_sure, where not given, lowered to a longest range below it (a note)."""
    unknown = sorted(set(given) - set(mapper_parameter_names()))
    if unknown:
        raise SettingsError(f"{unknown[0]}: not a mapper parameter ({', '.join(mapper_parameter_names())})")
    cell = {"map_resolution": node["resolution"]} if node["resolution"] > 0 else {}
    if cell and "vasco_resolution" in given:
        raise SettingsError(f"vasco_resolution and resolution {node['resolution']} both set the cell size: set "
                            f"resolution (the map's cell), or resolution 0 to take vasco_resolution x vasco_downsample")
    given = dict(given)
    if node["max_laser_range"] > 0:
        if "vasco_range_max" in given:
            raise SettingsError(f"vasco_range_max and max_laser_range {node['max_laser_range']:g} both set the longest "
                                f"range: set one (max_laser_range 0 takes vasco_range_max)")
        given["vasco_range_max"] = node["max_laser_range"]
    notes = ()
    if "vasco_range_max" in given and "vasco_range_sure" not in given:
        top, key = given["vasco_range_max"], "max_laser_range" if node["max_laser_range"] > 0 else "vasco_range_max"
        sure = _params(node, {k: v for k, v in given.items() if k != "vasco_range_max"}, cell).range_sure
        if isinstance(top, (int, float)) and 0 <= top < sure:
            given["vasco_range_sure"] = top
            notes = (f"vasco_range_sure lowered from {sure:g} to {top:g} m: {key} {top:g} is below it",)
    return _params(node, given, cell), notes


def _params(node: dict, given: dict, cell: dict) -> _core.Params:
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


def map_files(paths: list) -> list:
    """save_map_path's files as the map writers take them: a name without a map format's
    extension is map_saver's base name, NAME.pgm (its NAME.yaml written beside it)."""
    known = tuple(f["extension"] for f in _core.map_formats())
    return [p if p.lower().endswith(known) else p + ".pgm" for p in paths]


def unknown_parameters(names, known) -> str:
    """The text naming each of names (parameters set but not the node's), each with the closest
    of known: "unknown parameters (not used): scan_topci: did you mean 'scan_topic'?; ..."."""
    return "unknown parameters (not used): " + "; ".join(f"{n}{did_you_mean(n, known)}" for n in sorted(names))


# -- ROS: the declarations ------------------------------------------------------------------------
def parameter_descriptor(p: NodeParameter, with_range: bool = True):
    """p's ParameterDescriptor: its help, read-only unless dynamic, its rule as the additional
    constraints, and its bounds as ROS's range where they are closed. Types stay dynamic: a ROS
    integer where a number is asked (resolution:=0) is the check's to judge."""
    from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor

    d = ParameterDescriptor(description=p.help, read_only=not p.dynamic, dynamic_typing=True,
                            additional_constraints=p.check.rule())
    bounds = p.check.ros_range() if with_range else None
    if bounds and isinstance(p.check, Number) and p.check.whole:
        d.integer_range = [IntegerRange(from_value=int(bounds[0]), to_value=int(bounds[1]), step=0)]
    elif bounds:
        d.floating_point_range = [FloatingPointRange(from_value=float(bounds[0]), to_value=float(bounds[1]), step=0.0)]
    return d


def declare_parameters(node) -> Settings:
    """Declares the node's parameters on an rclpy Node (the rows, then every mapper key, unset
    unless given: param_file and the defaults apply) and returns the Settings of their values.
    SettingsError naming the parameter for a bad value, in the check's words."""
    from rcl_interfaces.msg import ParameterDescriptor
    from rclpy.exceptions import InvalidParameterValueException

    for p in NODE_PARAMETERS:
        try:
            node.declare_parameter(p.name, p.default, parameter_descriptor(p))
        except InvalidParameterValueException:  # outside ROS's range: refused below in the check's words
            node.declare_parameter(p.name, p.default, parameter_descriptor(p, with_range=False))
    for name in mapper_parameter_names():
        node.declare_parameter(name, None, ParameterDescriptor(
            description=f"{name} (log2map --help lists its meaning)", dynamic_typing=True))
    values = {p.name: node.get_parameter(p.name).value for p in NODE_PARAMETERS}
    given = {n: node.get_parameter(n).value for n in mapper_parameter_names()}
    return Settings.from_values(values, {k: v for k, v in given.items() if v is not None})


# -- docs -----------------------------------------------------------------------------------------
def _default_text(v) -> str:
    if isinstance(v, list):
        return "[" + ", ".join(f"{x:g}" if isinstance(x, float) else str(x) for x in v) + "]"
    return "''" if v == "" else str(v)


def parameter_table() -> str:
    """docs/ros.md's table of the node's own parameters, from the rows."""
    lines = ["| parameter | default | valid values | meaning | when changed while running |", "|---|---|---|---|---|"]
    for p in NODE_PARAMETERS:
        lines.append(f"| `{p.name}` | `{_default_text(p.default)}` | {p.check.rule()} | {p.help} | "
                     f"{p.effect.value if p.dynamic else 'read-only'} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(parameter_table(), end="")
