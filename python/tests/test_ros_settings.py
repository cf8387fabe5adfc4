"""The node's parameter schema (vasco_gpu/ros/settings.py) without a running node: each row's
check refuses naming the row, rows of other components' options take those components' values,
a change says what the node must do, the ROS descriptors, and docs/ros.md's table is the
schema's."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import vasco_gpu as vg
from vasco_gpu.msgs.scan_options import SCAN_OPTIONS, check_cloud_options
from vasco_gpu.ros.posing import TIME_JUMP_S, Posing, ScanFilter, TimeJumps
from vasco_gpu.ros.settings import (NODE_PARAMETERS, Effect, Number, Settings, SettingsError, core_option, map_files,
                                    mapper_parameter_names, parameter_descriptor, parameter_table, unknown_parameters)

ROOT = Path(__file__).resolve().parents[2]
ROWS = {p.name: p for p in NODE_PARAMETERS}


def test_settings_refuse_naming_the_parameter(tmp_path):
    assert "vasco_resolution" in mapper_parameter_names() and "vasco_p_occ" in mapper_parameter_names()
    s = Settings.from_values({}, {})
    assert s.scan_topics == ["scan"] and s.map_mode == "trinary"
    # resolution 0.05 by default, ROS's cell: CARMEN's 0.025 m evidence grid in blocks of 2
    assert (s.params.resolution, s.params.downsample, s.params.map_resolution) == (0.025, 2, 0.05)
    assert s.params == vg.Params(downsample=2)
    for node, mapper, word in [({"map_mode": "ternary"}, {}, "map_mode"), ({"scan_topics": ""}, {}, "scan_topics"),
                               ({"transform_timeout": -1.0}, {}, "transform_timeout"),
                               ({"backend": "gpu9"}, {}, "backend"), ({}, {"vasco_p_occ": 1.5}, "vasco_p_occ"),
                               ({}, {"vasco_resolutoin": 0.1}, "vasco_resolutoin"), ({}, {"p_occ": 0.6}, "p_occ"),
                               ({"resolution": -0.05}, {}, "resolution"), ({"resolution": 1e-9}, {}, "resolution"),
                               ({}, {"vasco_resolution": 0.05}, "vasco_resolution and resolution"),
                               ({"free_thresh": 0.7}, {}, "free_thresh"),
                               ({"param_file": str(tmp_path / "none.ini")}, {}, "param_file")]:
        with pytest.raises(SettingsError, match=word):
            Settings.from_values(node, mapper)
    assert Settings.from_values({"resolution": 0}, {"vasco_resolution": 0.05}).params.map_resolution == 0.2
    one = Settings.from_values({"resolution": 0.05}, {"vasco_downsample": 1}).params  # a given block stays
    assert (one.resolution, one.downsample) == (0.05, 1)
    ini = tmp_path / "carmen.ini"
    ini.write_text("[*]\nvasco_resolution 0.1\nvasco_p_occ 0.8\n")
    s = Settings.from_values({"param_file": str(ini), "resolution": 0}, {"vasco_p_occ": 0.6})
    assert s.params.resolution == 0.1 and s.params.p_occ == 0.6  # given over the file
    s = Settings.from_values({"param_file": str(ini)}, {})  # resolution over the file's vasco_resolution
    assert (s.params.resolution, s.params.downsample, s.params.p_occ) == (0.05, 1, 0.8)  # round(0.05 / 0.1) = 1


@pytest.mark.parametrize("p", NODE_PARAMETERS, ids=lambda p: p.name)
def test_each_row_takes_its_default_and_refuses_by_its_name(p):
    p.check(p.name, p.default)
    for bad in (object(), None, "true" if isinstance(p.default, bool) else True, float("nan")):
        with pytest.raises(SettingsError, match=rf"^{p.name}: "):
            p.check(p.name, bad)
        with pytest.raises(SettingsError, match=rf"^{p.name}: "):
            Settings.from_values({p.name: bad}, {})


def test_the_refusals_words():
    for name, value, words in [("map_mode", "ternary", "map_mode: 'ternary' is not one of trinary, scale"),
                               ("transform_timeout", 0, "transform_timeout: 0 must be a finite number in (0, 86400]"),
                               ("scan_batch_interval", -0.1, "scan_batch_interval: -0.1 must be between 0 and 86400"),
                               ("free_thresh", 1.5, "free_thresh: 1.5 must be between 0 and 1"),
                               ("threads", 1.0, "threads: 1.0 must be a whole number in [0, 1024]"),
                               ("max_memory", -1, "max_memory: -1 must be a whole number >= 0"),
                               ("cloud_range_max", 2000.0,
                                "cloud_range_max: 2000.0 must be a finite number in (0, 1000]"),
                               ("z_band", [1.0, 0.5], "z_band: [1.0, 0.5] must be two finite heights [min, max], "
                                                      "min < max"),
                               ("map_frame", "/", "map_frame: '/' must be a frame name"),
                               ("save_map_path", [""], "save_map_path: [''] must be a file name or a list of them")]:
        with pytest.raises(SettingsError) as e:
            Settings.from_values({name: value}, {})
        assert str(e.value) == words
    with pytest.raises(SettingsError, match="^backend: 'gpu9' is not a backend "):
        Settings.from_values({"backend": "gpu9"}, {})
    with pytest.raises(SettingsError, match="nothing to map"):
        Settings.from_values({"scan_topics": []}, {})


def test_rows_of_other_components_take_their_values():
    """The session's, the map output's and the pose source's options come from their C++
    tables, the scan options from vasco_gpu.msgs: one default, one set of choices."""
    for row, component, option in [("backend", "session", "backend"), ("cuda_mode", "session", "cuda_mode"),
                                   ("max_memory", "session", "max_memory"), ("map_mode", "map_output", "mode"),
                                   ("free_thresh", "map_output", "free_thresh"),
                                   ("occupied_thresh", "map_output", "occupied_thresh"),
                                   ("pose_max_gap", "pose_source", "pose_max_gap")]:
        o = core_option(component, option)
        assert set(o) >= {"name", "type", "default", "help", "choices", "lo", "hi"}, o
        if o["choices"]:
            assert set(ROWS[row].check.names) <= set(o["choices"]), row
    assert ROWS["max_memory"].default == 2 << 30  # bytes, a ROS integer, whatever unit the table writes
    assert (ROWS["free_thresh"].default, ROWS["occupied_thresh"].default) == (0.196, 0.65)
    assert ROWS["map_mode"].check.names == ("trinary", "scale") and ROWS["map_mode"].default == "trinary"
    assert set(ROWS["cuda_mode"].check.names) == {"float", "exact"} and ROWS["cuda_mode"].default == "float"
    assert ROWS["backend"].default == "auto" and ROWS["pose_max_gap"].default == 5.0
    for o in SCAN_OPTIONS:
        want = list(o.default) if isinstance(o.default, tuple) else o.default
        assert (ROWS[o.name].default, ROWS[o.name].help) == (want, o.meaning), o.name
    with pytest.raises(KeyError, match="no 'nothing'"):
        core_option("session", "nothing")


def test_the_cloud_rows_bounds_are_the_adapters():
    step, top = ROWS["cloud_angle_step"].check, ROWS["cloud_range_max"].check
    band, angle, range_max = (0.2, 1.8), math.radians(1.0), 50.0
    for degrees in (step.lo, step.hi, math.nextafter(step.lo, 0), math.nextafter(step.hi, 99)):
        inside = step.lo <= degrees <= step.hi
        try:
            check_cloud_options(band, math.radians(degrees), range_max)
            assert inside, degrees
        except ValueError:
            assert not inside, degrees
    for metres in (top.hi, math.nextafter(top.hi, 1e9), 1e-9, 0.0):
        inside = top.lo < metres <= top.hi
        try:
            check_cloud_options(band, angle, metres)
            assert inside, metres
        except ValueError:
            assert not inside, metres


def test_a_change_says_what_the_node_does():
    s = Settings.from_values({"scan_batch_interval": 0.1}, {})
    new, effects = s.changed({"map_update_interval": 0.2, "use_sim_time": True})  # not the node's: passed over
    assert effects == (Effect.PUBLISH_PERIOD,) and new.map_update_interval == 0.2 and s.map_update_interval == 0.5
    assert s.changed({"free_thresh": 0.25, "map_mode": "scale"})[1] == (Effect.REPUBLISH,)
    assert s.changed({"scan_batch_interval": 0.0})[1] == (Effect.BATCH_PERIOD,)
    assert s.changed({"scan_batch_interval": 0.1})[1] == ()  # the same value: nothing to do
    assert s.changed({"save_map_path": ["a.pgm"]})[1] == ()  # read when used
    assert s.changed({"resolution": 0.05})[1] == ()  # the same Params
    new, effects = s.changed({"vasco_p_occ": 0.6, "map_update_interval": 1.0, "map_mode": "scale"})
    assert effects == (Effect.REMAP, Effect.PUBLISH_PERIOD, Effect.REPUBLISH) and new.params.p_occ == 0.6
    assert new.changed({"vasco_p_occ": None})[0].params == s.params  # unset: the default again
    assert s.changed({"resolution": 0.1})[1] == (Effect.REMAP,)
    with pytest.raises(SettingsError, match="^scan_topics: read-only while the node runs"):
        s.changed({"scan_topics": ["other"]})
    with pytest.raises(SettingsError, match="^vasco_p_occ"):
        s.changed({"vasco_p_occ": 1.5})
    with pytest.raises(SettingsError, match="vasco_resolution and resolution"):
        s.changed({"vasco_resolution": 0.05})
    with pytest.raises(SettingsError, match="must be below occupied_thresh"):
        s.changed({"free_thresh": 0.9})  # taken whole or not at all


def test_docs_ros_md_has_the_schemas_table():
    """docs/ros.md's table of the node's own parameters is parameter_table()'s, line for line
    (python -m vasco_gpu.ros.settings prints it)."""
    text = (ROOT / "docs" / "ros.md").read_text()
    table = parameter_table()
    head = table.splitlines()[0]
    assert head in text, "docs/ros.md has no table of the node's parameters"
    start = text.index(head)
    end = text.index("\n\n", start) + 1
    assert text[start:end] == table, "docs/ros.md's table differs from the schema: python -m vasco_gpu.ros.settings"
    assert [line.split("`")[1] for line in table.splitlines()[2:]] == list(ROWS)


def test_the_ros_descriptors():
    msgs = pytest.importorskip("rcl_interfaces.msg")
    d = parameter_descriptor(ROWS["scan_topics"])
    assert d.read_only and d.dynamic_typing and d.description == ROWS["scan_topics"].help
    assert not d.floating_point_range and not d.integer_range
    d = parameter_descriptor(ROWS["free_thresh"])
    assert not d.read_only and d.additional_constraints == "between 0 and 1"
    assert [(r.from_value, r.to_value) for r in d.floating_point_range] == [(0.0, 1.0)]
    assert [(r.from_value, r.to_value) for r in parameter_descriptor(ROWS["threads"]).integer_range] == [(0, 1024)]
    d = parameter_descriptor(ROWS["max_memory"])
    assert [(r.from_value, r.to_value) for r in d.integer_range] == [(0, 2**63 - 1)]
    d = parameter_descriptor(ROWS["transform_timeout"])  # > 0: ROS's ranges hold both ends
    assert not d.floating_point_range and d.additional_constraints == "a finite number in (0, 86400]"
    assert parameter_descriptor(ROWS["map_mode"]).additional_constraints == "one of: trinary, scale"
    assert isinstance(d, msgs.ParameterDescriptor)
    assert Number(lo=0, hi=1, hi_open=True).ros_range() is None


def test_declared_on_a_node(monkeypatch):
    """declare_parameters on an rclpy Node: the rows' defaults, overrides checked in the
    schema's words (a value outside a descriptor's range too), the mapper keys unset."""
    import ros_support  # noqa: F401  (the ROS environment, before rclpy starts)

    rclpy = ros_support.import_or_skip("rclpy")
    from rclpy.context import Context
    from rclpy.node import Node
    from rclpy.parameter import Parameter

    from vasco_gpu.ros.settings import declare_parameters

    context = Context()
    rclpy.init(context=context)
    try:
        def declared(**overrides):
            node = Node("settings_test", context=context,
                        parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()])
            try:
                return declare_parameters(node), node.describe_parameter("free_thresh")
            finally:
                node.destroy_node()

        s, d = declared()
        assert s.node == {p.name: p.default for p in NODE_PARAMETERS} and s.given == {}
        assert not d.read_only and d.floating_point_range[0].to_value == 1.0
        s, _ = declared(free_thresh=0.25, z_band=[0.1, 2.0], vasco_p_occ=0.6, resolution=0)
        assert (s.free_thresh, list(s.z_band), s.params.p_occ, s.resolution) == (0.25, [0.1, 2.0], 0.6, 0)
        with pytest.raises(SettingsError) as e:
            declared(free_thresh=1.5)  # outside the descriptor's range
        assert str(e.value) == "free_thresh: 1.5 must be between 0 and 1"
        with pytest.raises(SettingsError, match="^map_mode: 'raw' is not one of trinary, scale"):
            declared(map_mode="raw")
    finally:
        rclpy.shutdown(context=context)


def test_slam_toolboxs_keys():
    """slam_toolbox's keys with its meanings: one scan topic (scan_topics takes one name too),
    max_laser_range the mapper's longest range, vasco_range_sure lowered with it (a note)."""
    s = Settings.from_values({"scan_topic": "/front", "scan_topics": "/front"}, {})
    assert s.scan_topics == ["/front"] and s.notes == ()
    assert Settings.from_values({"scan_topics": "/a"}, {}).scan_topics == ["/a"]
    with pytest.raises(SettingsError, match=r"^scan_topic '/front' and scan_topics \['/b'\] both name"):
        Settings.from_values({"scan_topic": "/front", "scan_topics": ["/b"]}, {})
    s = Settings.from_values({"max_laser_range": 8.0}, {})  # above range_sure 5: nothing lowered
    assert (s.params.range_max, s.params.range_sure, s.notes) == (8.0, 5.0, ())
    s = Settings.from_values({"max_laser_range": 4.0}, {})
    assert (s.params.range_max, s.params.range_sure) == (4.0, 4.0)
    assert s.notes == ("vasco_range_sure lowered from 5 to 4 m: max_laser_range 4 is below it",)
    s = Settings.from_values({}, {"vasco_range_max": 3})  # lowered alone: range_sure follows
    assert (s.params.range_max, s.params.range_sure) == (3, 3) and "vasco_range_max 3" in s.notes[0]
    with pytest.raises(SettingsError, match="range_sure"):  # both given: the mapper's check, naming them
        Settings.from_values({}, {"vasco_range_max": 3, "vasco_range_sure": 4})
    with pytest.raises(SettingsError, match="vasco_range_max and max_laser_range 4 both set"):
        Settings.from_values({"max_laser_range": 4.0}, {"vasco_range_max": 3})
    s = Settings.from_values({"max_laser_range": 8.0}, {})
    new, effects = s.changed({"max_laser_range": 4.0})
    assert effects == (Effect.REMAP,) and new.params.range_sure == 4.0 and new.notes
    for name, value in [("throttle_scans", 0), ("throttle_scans", 1.0), ("minimum_time_interval", -1.0),
                        ("max_laser_range", -1.0), ("odom_frame", "")]:
        with pytest.raises(SettingsError, match=f"^{name}: "):
            Settings.from_values({name: value}, {})
    with pytest.raises(SettingsError, match="read-only"):
        s.changed({"tf_buffer_duration": 10.0})


def test_the_scan_filter():
    """throttle_scans: every Nth scan of a topic; minimum_time_interval: a scan within it of the
    last one taken is skipped (a stamp far back is not within it)."""
    f = ScanFilter()
    got = [f.skip("a", i * 100_000_000, 2, 0.0) for i in range(5)]
    assert got == [None, "scans skipped by throttle_scans", None, "scans skipped by throttle_scans", None]
    f = ScanFilter()
    got = [f.skip("a", i * 100_000_000, 1, 0.25) for i in range(7)]
    assert [g is None for g in got] == [True, False, False, True, False, False, True]
    assert f.skip("b", 0, 1, 0.25) is None  # per topic
    assert f.skip("a", 0, 1, 0.25) is None  # 0.6 s back


def test_time_going_back_is_told_per_source():
    """A stamp more than TIME_JUMP_S behind its own source's newest is a jump (not one behind
    another source's); /clock gone back is one where the stamps seen lie ahead of it."""
    s = 10**9
    j = TimeJumps()
    assert j.back("a", 100 * s) == 0 and j.back("b", 50 * s) == 0  # b behind a: another source
    assert j.back("a", 99 * s) == 0  # within the bound: jitter, reordering
    assert j.back("a", 101 * s) == 0 and j.back("a", 90 * s) == 11 * s
    assert j.newest["a"] == 101 * s  # a jump is not taken as the newest: the node clears
    assert j.ahead_of(101 * s) == 0 and j.ahead_of(100 * s + s // 2) == 0 and j.ahead_of(10 * s) == 91 * s
    j.clear()
    assert j.ahead_of(0) == 0 and j.back("a", 0) == 0
    assert TIME_JUMP_S == 1.0 and "over 1 s" in ROWS["on_time_jump"].help
    assert ROWS["on_time_jump"].default == "reset" and ROWS["on_time_jump"].effect is Effect.READ_WHEN_USED
    with pytest.raises(SettingsError, match="^on_time_jump: 'drop' is not one of reset, keep"):
        Settings.from_values({"on_time_jump": "drop"}, {})


def _tf(parent, child, sec):
    from types import SimpleNamespace as NS
    return NS(header=NS(frame_id=parent, stamp=NS(sec=sec, nanosec=0)), child_frame_id=child,
              transform=NS(translation=NS(x=float(sec), y=0.0, z=0.0), rotation=NS(x=0.0, y=0.0, z=0.0, w=1.0)))


def test_a_jump_back_on_tf_clears_the_tf_history_but_not_tf_static():
    from types import SimpleNamespace as NS
    settings = Settings.from_values({}, {})
    jumps = []

    def jumped(where, back_ns):
        jumps.append((where, back_ns))
        posing.clear_time()  # what the node does

    posing = Posing(lambda: settings, str, None, jumped)
    posing.add_tf(NS(transforms=[_tf("base_link", "laser", 0)]), True)
    for sec in (100, 101, 102):
        posing.add_tf(NS(transforms=[_tf("map", "base_link", sec)]), False)
    assert posing.tf.covers("map", "laser", [101 * 10**9]).all() and not jumps
    posing.add_tf(NS(transforms=[_tf("map", "base_link", 100)]), False)  # a bag played again
    assert jumps == [("/tf (frame 'base_link')", 2 * 10**9)]
    assert not posing.tf.covers("map", "laser", [101 * 10**9]).any()  # the old time's samples gone
    posing.add_tf(NS(transforms=[_tf("map", "base_link", 101)]), False)
    t, _ = posing.tf.lookup("map", "laser", [100_500_000_000])
    assert t[0][0] == pytest.approx(100.5) and len(jumps) == 1  # /tf_static kept; the new time goes on


def test_save_map_path_forms_and_unknown_keys():
    assert Settings.from_values({"save_map_path": "/maps/site"}, {}).save_map_path == ["/maps/site"]
    assert map_files(["/maps/site", "a.PGM", "b.map.gz", "c.v2", "d.png"]) == [
        "/maps/site.pgm", "a.PGM", "b.map.gz", "c.v2.pgm", "d.png"]
    assert unknown_parameters(["scan_topci", "zzz"], list(ROWS)) == (
        "unknown parameters (not used): scan_topci: did you mean 'scan_topic'?; zzz")


def test_a_refused_static_link_is_not_added_again_when_time_jumps():
    # (the node fuzzer's finding) a /tf_static transform the tree refused must not be kept for
    # the rebuild after a jump back, where it was refused again out of a scan's callback
    from types import SimpleNamespace as NS
    from vasco_gpu.msgs.errors import BagError
    settings = Settings.from_values({}, {})
    posing = Posing(lambda: settings, str, None, lambda where, back: posing.clear_time())
    posing.add_tf(NS(transforms=[_tf("base_link", "laser", 0)]), True)
    bad = _tf("base_link", "laser", 0)
    bad.transform.translation.x = -1e300
    with pytest.raises(BagError, match="translation"):
        posing.add_tf(NS(transforms=[bad]), True)
    posing.clear_time()  # the rebuild: the good static link again, not the refused one
    assert posing.tf.covers("base_link", "laser", [5 * 10**9]).all()
