"""The ROS 2 node as a process, over a real DDS (Fast DDS, shared memory only: ros_support.py):
the bundled intel log replayed as LaserScan + /tf + /tf_static, the latched /map against the
log's own map, a Path of moved poses, the services, bad messages, a late subscriber, a clean
exit and no UDP socket off loopback.

How close /map is to the log's map: the LaserScans carry float32 angles (test_bags.py's module
docstring bounds what that moves: at most 0.5 % of the map's cells), and the poses pass through
tf's quaternions (a few ulps of heading). The map's size, origin and known cells are compared
exactly, the values (scale mode: round(100 p)) in all but that share of the cells."""

from __future__ import annotations

import math
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import ros_support  # noqa: F401  (the ROS environment, before rclpy starts)
from ros_support import NodeProcess, is_loopback, udp_sockets

rclpy = ros_support.import_or_skip("rclpy")
ros_support.import_or_skip("tf2_msgs")

import vasco_gpu as vg  # noqa: E402
from ros_player import LATCHED, RELIABLE  # noqa: E402
from nav_msgs.msg import OccupancyGrid  # noqa: E402
from std_srvs.srv import SetBool, Trigger  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
INTEL = ROOT / "logs" / "intel.gfs.log.gz"
ANGLE_BOUND = 0.005  # test_bags.py's bound on cells moved by float32 angles


def as_map_values(m) -> np.ndarray:
    """A finished Map as the node's scale-mode values, computed here: round(100 p) half up,
    row-major from the lower-left cell."""
    p = m.cells.T.astype(np.float64)
    return np.where((p >= 0) & (p <= 1), np.floor(p * 100 + 0.5), -1).astype(np.int8).ravel()


def window(msg, want):
    """msg's values over want's (a finished Map's) cells, row-major from its lower-left cell: /map
    is want's map in a canvas (docs/ros.md: a grid that grows keeps a margin) whose cells beyond
    want's are unknown. None where msg's cells do not hold want's on the same lattice (origins a
    whole number of cells apart), or a cell beyond them is known."""
    info = msg.info
    if not math.isclose(info.resolution, want.resolution, rel_tol=1e-6):
        return None
    w, h = want.shape
    # in want's cell (a double; info.resolution is a float32)
    fx = (want.origin[0] - info.origin.position.x) / want.resolution
    fy = (want.origin[1] - info.origin.position.y) / want.resolution
    ix, iy = round(fx), round(fy)
    # 1e-3 of a cell: a map file keeps float32 resolutions and origins (about 1e-6 of a cell
    # over 1000 cells); another lattice lies a whole fine cell, 1/downsample of a cell, apart
    if abs(fx - ix) > 1e-3 or abs(fy - iy) > 1e-3 or ix < 0 or iy < 0 or ix + w > info.width or iy + h > info.height:
        return None
    cells = np.frombuffer(bytes(msg.data), dtype=np.int8).reshape(info.height, info.width)
    inner = cells[iy:iy + h, ix:ix + w].ravel().copy()
    outside = cells.copy()
    outside[iy:iy + h, ix:ix + w] = -1
    return inner if (outside == -1).all() else None


def assert_grid_matches(msg, want, bound=ANGLE_BOUND):
    got, exp = window(msg, want), as_map_values(want)
    assert got is not None, (f"/map {msg.info.width}x{msg.info.height} at {msg.info.origin.position} does not hold "
                             f"the map {want.shape} at {want.origin} (or knows a cell beyond it)")
    assert np.array_equal(got == -1, exp == -1), "known cells differ"
    differ = int((got != exp).sum())
    assert differ <= bound * got.size, (differ, got.size)
    return differ


def grid_equals(want):
    exp = as_map_values(want)

    def match(msg):
        got = window(msg, want)
        if got is None:
            return False
        return np.array_equal(got == -1, exp == -1) and int((got != exp).sum()) <= ANGLE_BOUND * got.size
    return match


@pytest.fixture(scope="module")
def node(tmp_path_factory):
    out = tmp_path_factory.mktemp("saved")
    shm = set(os.listdir("/dev/shm"))
    proc = NodeProcess({"backend": "cpu_double", "map_mode": "scale", "scan_qos": "reliable", "cloud_topics": ["points"],
                        "map_update_interval": 0.2, "transform_timeout": 1.0,
                        "save_map_path": [str(out / "live.map.gz"), str(out / "live.pgm")]})
    proc.wait_for("ready")
    proc.saved, proc.shm_before = out, shm
    yield proc
    proc.kill()


def test_replay_gives_the_logs_map_then_a_path_moves_it(ros, node, intel):
    stamps = 10**12 + np.arange(len(intel), dtype=np.int64) * 100_000_000
    before = ros.map_count()
    ros.replay(intel.scans, stamps)
    want = vg.Mapper(intel.params, backend="cpu_double")
    want.insert(intel.scans)
    want_map = want.finish()
    got = ros.wait_map(before, grid_equals(want_map), timeout=60)
    assert got is not None, f"no /map equal to the log's map; last:\n{node.output[-2000:]}"
    assert got.header.frame_id == "map"
    assert_grid_matches(got, want_map)

    # A Path of perturbed base poses at every scan's stamp: /map = log2map --poses of them (the
    # same reader through load_log: a g2o file, matched in order).
    rng = np.random.default_rng(3)
    moved = intel.poses + rng.normal(0, [0.03, 0.03, 0.005], intel.poses.shape)
    g2o = node.saved.parent / "moved.g2o"
    g2o.write_text("".join(f"VERTEX_SE2 {i} {x:.17g} {y:.17g} {t:.17g}\n" for i, (x, y, t) in enumerate(moved)))
    by_file = vg.load_log(INTEL, poses=g2o, pose_match="order", map_resolution=0.05)
    want = vg.Mapper(by_file.params, backend="cpu_double")
    want.insert(by_file.scans)
    moved_map = want.finish()
    ros.wait_quiet(1.0)  # the replay's last map out: the next one is the Path's
    before = ros.map_count()
    t0 = time.monotonic()
    ros.publish_path(stamps, moved)
    got = ros.wait_map(before, timeout=30)
    assert got is not None, node.output[-2000:]
    latency = time.monotonic() - t0
    assert_grid_matches(got, moved_map)
    print(f"Path of {len(intel)} poses -> /map in {latency * 1e3:.0f} ms (cpu_double, this machine)")

    # A late subscriber gets the latched map, and the node, seeing it, sends the map as it is now
    # (with the updates the latched one lacks) in one piece.
    late = []
    sub = ros.node.create_subscription(OccupancyGrid, "map", late.append, LATCHED)
    end = time.monotonic() + 10
    while not (late and bytes(late[-1].data) == bytes(ros.latest().data)) and time.monotonic() < end:
        time.sleep(0.02)
    ros.node.destroy_subscription(sub)
    assert late and bytes(late[-1].data) == bytes(ros.latest().data)

    # save_map: the files of save_map_path, one transaction; the map read back is the one published.
    r = ros.call(Trigger, "/vasco_mapper/save_map", Trigger.Request())
    assert r.success, r.message
    saved = vg.read_map(node.saved / "live.map.gz")
    assert np.array_equal(as_map_values(saved), window(ros.latest(), saved))
    assert (node.saved / "live.pgm").is_file() and (node.saved / "live.yaml").is_file()
    assert sorted(p.name for p in node.saved.iterdir()) == ["live.map.gz", "live.pgm", "live.yaml"]


def set_parameter(ros, name, value):
    from rcl_interfaces.msg import Parameter as ParameterMsg
    from rcl_interfaces.srv import SetParameters
    from rclpy.parameter import Parameter

    req = SetParameters.Request(parameters=[Parameter(name, value=value).to_parameter_msg()])
    assert isinstance(req.parameters[0], ParameterMsg)
    return ros.call(SetParameters, "/vasco_mapper/set_parameters", req).results[0]


def test_a_parameter_change_maps_every_stored_scan_again(ros, node, intel):
    bad = set_parameter(ros, "vasco_p_occ", 1.5)
    assert not bad.successful and "vasco_p_occ" in bad.reason
    assert not set_parameter(ros, "scan_topics", ["other"]).successful  # read-only
    both = set_parameter(ros, "vasco_resolution", 0.05)  # resolution (0.05) says the cell already
    assert not both.successful and "resolution" in both.reason
    n, fine = ros.map_count(), ros.latest()
    assert set_parameter(ros, "resolution", 0.1).successful
    got = ros.wait_map(n, timeout=30)
    assert got is not None and math.isclose(got.info.resolution, 0.1, rel_tol=1e-6), node.output[-2000:]
    assert got.info.width < 0.6 * fine.info.width  # cells twice as large: about half as many a row
    n = ros.map_count()
    assert set_parameter(ros, "resolution", 0.05).successful
    assert ros.wait_map(n, timeout=30).info.resolution == pytest.approx(0.05)


def test_bad_messages_are_refused_by_name_and_nothing_is_lost(ros, node, intel):
    last = ros.latest()
    assert last is not None
    n = ros.map_count()
    ns = 2 * 10**12
    # ranges that disagree with the angles
    bad = ros.laser_scan(ns, intel.scans.ranges_of(0), -1.0, 0.01)
    bad.angle_max = 1.0  # 201 beams by the angles, 180 ranges
    ros.scan.publish(bad)
    node.wait_for("has 180 ranges, but angle_min")
    # a Path in another frame, and one with a NaN pose
    ros.publish_path([ns], [(0, 0, 0)], frame="odom")
    node.wait_for("is in frame 'odom', not map_frame 'map'")
    ros.publish_path([ns, ns + 1], [(0, 0, 0), (math.nan, 0, 0)])
    node.wait_for("has position (nan")
    # a frame that never appears in tf: dropped after transform_timeout, logged once
    for k in range(3):
        ros.scan.publish(ros.laser_scan(ns + k, intel.scans.ranges_of(0), -1.0, 0.5 * math.pi / 180, frame="ghost"))
    line = node.wait_for("no transform within transform_timeout")
    assert "/scan: scan at stamp 2000.000000000" in line and "'ghost'" in line
    time.sleep(1.5)
    assert sum("ghost" in ln for ln in node.lines) == 1, node.output[-2000:]
    assert node.proc.poll() is None
    assert ros.map_count() == n  # nothing changed the map
    assert bytes(ros.latest().data) == bytes(last.data)


def test_pause_and_reset(ros, node, intel):
    r = ros.call(SetBool, "/vasco_mapper/pause", SetBool.Request(data=True))
    assert r.success and "paused" in r.message
    n = ros.map_count()
    ros.replay(intel.scans.select(0, 20), 3 * 10**12 + np.arange(20) * 10**8)
    time.sleep(1.0)
    assert ros.map_count() == n  # paused: scans not mapped
    assert ros.call(SetBool, "/vasco_mapper/pause", SetBool.Request(data=False)).success
    r = ros.call(Trigger, "/vasco_mapper/reset", Trigger.Request())
    assert r.success and f"dropped {len(intel)} scans" in r.message, r.message
    replay_and_expect(ros, node, intel, n, 0, 30, 4 * 10**12)


def replay_and_expect(ros, node, intel, n, first: int, count: int, t0: int):
    """Replays count scans from first (0.1 s apart from stamp t0) to a node that has no other
    scan; a /map after the n-th equals their map."""
    some = intel.scans.select(first, count)
    ros.replay(some, t0 + np.arange(count) * 10**8)
    want = vg.Mapper(intel.params, backend="cpu_double")
    want.insert(some)
    got = ros.wait_map(n, grid_equals(want.finish()), timeout=30)
    assert got is not None, node.output[-2000:]


# Each test's stamps come after the ones before (1, 2, 3, 4, 4.1, 4.2, 4.3, 4.35, 4.4, 5 x 10^12 ns): the
# node keeps 60 s of /tf behind the newest sample, so an older replay could lose its transforms.
def test_scans_map_in_batches_or_on_arrival(ros, node, intel):
    assert "scans mapped in batches every 0.1 s" in node.output  # the default, in the ready line
    assert not set_parameter(ros, "scan_batch_interval", -0.1).successful
    assert set_parameter(ros, "scan_batch_interval", 0.0).successful
    try:
        assert ros.call(Trigger, "/vasco_mapper/reset", Trigger.Request()).success
        replay_and_expect(ros, node, intel, ros.map_count(), 30, 25, 41 * 10**11)
    finally:
        assert set_parameter(ros, "scan_batch_interval", 0.1).successful
    # batches again; after a quiet second they stop, and the next message starts them
    assert ros.call(Trigger, "/vasco_mapper/reset", Trigger.Request()).success
    time.sleep(1.5)
    replay_and_expect(ros, node, intel, ros.map_count(), 60, 25, 42 * 10**11)


def test_an_incompatible_scan_publisher_is_named_while_batching(ros, node):
    # The node's scans are reliable here (scan_qos reliable): a best-effort publisher sends it
    # nothing, and rclpy's warning about it comes while /tf keeps the batches going (the
    # subscription waits in no wait set then; its QoS events do).
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import LaserScan
    from tf2_msgs.msg import TFMessage

    quiet = ros.node.create_publisher(LaserScan, "scan", QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT))
    try:
        end, k = time.monotonic() + 20, 0
        while time.monotonic() < end and "offering incompatible QoS" not in node.output:
            ros.tf.publish(TFMessage(transforms=[ros.transform("map", "base_link", 43 * 10**11 + k * 10**8, (0, 0, 0))]))
            k += 1
            time.sleep(0.05)
        line = next((ln for ln in node.lines if "offering incompatible QoS" in ln), None)
        assert line is not None and "'scan'" in line, node.output[-2000:]
        print(f"warned after {k} /tf messages")
    finally:
        ros.node.destroy_publisher(quiet)


def test_a_batching_node_sleeps_between_its_batches(ros, node, intel):
    # While batches run, nothing of their callback group may wake the executor: in rmw_fastrtps
    # a subscription's QoS event handlers share its reader's status condition, so with them in
    # the wait set every queued scan woke the executor and it spun until the batch took the
    # scan, 80 % of a core at 40 Hz where the node takes about 5 % (2-core machine, stream and
    # mapping included; 10 % on arrival). 40 % lies between the two with room to spare for a
    # loaded machine, whose spin would still show as tens of percent of CPU time.
    cpu = node.cpu_share(lambda: ros.replay(intel.scans.select(90, 80), 435 * 10**10 + np.arange(80) * 25_000_000,
                                            rate_hz=40.0))
    print(f"batching node: {100 * cpu:.0f} % of a core at 40 Hz")
    assert cpu < 0.4, f"{100 * cpu:.0f} % of a core at 40 Hz"


def test_batches_come_on_the_steady_clock_under_sim_time(ros, node, intel):
    # use_sim_time with no /clock: ROS time stands still, and a batch timer on it would never
    # take a scan; on the steady clock the batches come and the summary counts the scans mapped.
    from sensor_msgs.msg import LaserScan
    from tf2_msgs.msg import TFMessage

    others = ros.tf.get_subscription_count()  # the module's node, when it runs
    sim = NodeProcess({"backend": "cpu_double", "use_sim_time": True, "scan_topics": ["sim_scan"], "path_topic": "",
                       "scan_qos": "reliable"})
    pub = ros.node.create_publisher(LaserScan, "sim_scan", RELIABLE)
    try:
        sim.wait_for("ready")
        end = time.monotonic() + 20
        while (pub.get_subscription_count() == 0 or ros.tf.get_subscription_count() <= others) and \
                time.monotonic() < end:
            time.sleep(0.02)
        ros.tf_static.publish(TFMessage(transforms=[ros.transform("base_link", "laser", 0, (0, 0, 0))]))
        for k in range(20):
            ns = 44 * 10**11 + k * 10**8
            ros.tf.publish(TFMessage(transforms=[ros.transform("map", "base_link", ns, intel.poses[k])]))
            pub.publish(ros.laser_scan(ns, intel.scans.ranges_of(k), float(intel.scans.first_angle[k]),
                                       float(intel.scans.angle_step[k])))
            time.sleep(0.01)
        time.sleep(1.0)
        rc, _ = sim.interrupt()
        assert rc == 0 and "vasco_mapper: 20 scans mapped" in sim.output, sim.output[-2000:]
    finally:
        ros.node.destroy_publisher(pub)
        sim.kill()


def test_point_clouds_map_as_their_scans(ros, node, intel):
    """The first 60 scans as PointCloud2 (carmen2bag --cloud's points: walls at 0.5 m, floor and
    ceiling points the default z_band leaves out): the map of those scans."""
    from vasco_gpu.bags.bag_writer import cloud_points

    assert ros.call(Trigger, "/vasco_mapper/reset", Trigger.Request()).success
    n = ros.map_count()
    first = intel.scans.select(0, 60)
    ros.replay(first, 5 * 10**12 + np.arange(60) * 10**8, rate_hz=200.0, points_of=cloud_points)
    want = vg.Mapper(intel.params, backend="cpu_double")
    want.insert(first)
    got = ros.wait_map(n, grid_equals(want.finish()), timeout=30)
    assert got is not None, node.output[-2000:]


def test_no_udp_socket_off_loopback(node):
    # on shared memory alone, with the node's map-sized profile (test_ros_transport.py)
    assert "maps in one piece over shared memory" in node.output
    sockets = udp_sockets(node.proc.pid)
    assert not [s for s in sockets if not is_loopback(s)], sockets


def test_a_clean_exit_within_a_second_leaving_no_shared_memory():
    # A node alone in a domain of its own: a peer that is still running keeps the segments it
    # shares with the node open (Fast DDS removes a segment with its last user).
    shm = set(os.listdir("/dev/shm"))
    alone = NodeProcess({"backend": "cpu_double"}, env={"ROS_DOMAIN_ID": str(int(ros_support.ROS_ENV["ROS_DOMAIN_ID"]) + 50)})
    alone.wait_for("ready")
    assert not [s for s in udp_sockets(alone.proc.pid) if not is_loopback(s)]
    rc, took = alone.interrupt()
    assert rc == 0, alone.output[-2000:]
    assert took < 1.0, f"took {took:.2f} s to exit"
    assert "0 scans mapped" in alone.output
    left = set(os.listdir("/dev/shm")) - shm
    assert not left, left


@pytest.mark.parametrize("after", [0.0, 0.05, 0.2, 0.5])
def test_a_signal_while_starting_is_a_clean_exit_too(after):
    # Once the node's main has begun (rclpy's library loaded: before that, Python is importing
    # vasco_gpu itself, as for any program): while rclpy loads, while the node declares its
    # parameters, while the executor is made: the exit status is 0, no traceback printed.
    early = NodeProcess({"backend": "cpu_double"}, env={"ROS_DOMAIN_ID": str(int(ros_support.ROS_ENV["ROS_DOMAIN_ID"]) + 50)})
    end = time.monotonic() + 30
    while "librcl" not in open(f"/proc/{early.proc.pid}/maps").read() and time.monotonic() < end:
        time.sleep(0.005)
    time.sleep(after)
    rc, _ = early.interrupt()
    assert rc == 0, early.output
    assert "Traceback" not in early.output, early.output


def test_a_signal_inside_the_exit_still_destroys_the_node_and_shuts_ros_down(monkeypatch):
    # rclpy's handler passes a SIGINT on to Python's, so a KeyboardInterrupt can arise inside
    # the exit's own steps (Jazzy shuts the context down at once, while the node still closes)
    from vasco_gpu.ros import run

    done = []

    class Closing:
        def get_fully_qualified_name(self):
            return "/n"

        def summary(self):
            raise KeyboardInterrupt

        def destroy_node(self):
            done.append("destroyed")
            raise KeyboardInterrupt

    monkeypatch.setattr(run.rclpy, "try_shutdown", lambda: done.append("shut down"))
    run._close(Closing())
    assert done == ["destroyed", "shut down"]


def test_the_node_under_test_exits_cleanly_too(node):
    rc, took = node.interrupt()
    assert rc == 0 and took < 1.0, (rc, took, node.output[-2000:])
    assert "vasco_mapper: 60 scans mapped; not mapped:" in node.output
    # where the rendered Paths' time went (the bench's node column and steps come from this line)
    assert re.search(r"Path -> /map published: p50 [\d.]+ ms, p99 [\d.]+ ms \(\d+\); Path steps p50 ms: batch [\d.]+, read [\d.]+, "
                     r"repose [\d.]+, finish [\d.]+, message [\d.]+, publish [\d.]+", node.output), node.output[-2000:]


def test_a_bad_parameter_stops_the_node_at_start_up():
    proc = NodeProcess({"map_mode": "ternary"})
    rc = proc.proc.wait(30)
    proc._reader.join(2)
    assert rc == 2
    assert "map_mode: 'ternary' is not one of trinary, scale" in proc.output
    proc = NodeProcess({"vasco_p_occ": 1.5})
    assert proc.proc.wait(30) == 2
    proc._reader.join(2)
    assert "p_occ" in proc.output


def test_the_docs_command_runs(tmp_path):
    """docs/ros.md's "Running it" block, as written but for this run's domain, a CPU backend
    where CUDA is not usable, and `python -m vasco_gpu.ros` where the console script is not
    installed: it starts, and SIGINT ends it with status 0."""
    text = (ROOT / "docs" / "ros.md").read_text()
    block = text.split("```sh\nexport FASTDDS_BUILTIN_TRANSPORTS=SHM", 1)[1].split("```", 1)[0]
    block = "export FASTDDS_BUILTIN_TRANSPORTS=SHM" + block
    block = block.replace("ROS_DOMAIN_ID=42", f"ROS_DOMAIN_ID={ros_support.ROS_ENV['ROS_DOMAIN_ID']}")
    if not vg.cuda_available():
        block = block.replace("backend:=cuda", "backend:=cpu_threads")
    if shutil.which("vasco_map_node") is None:
        block = block.replace("vasco_map_node", f"{sys.executable} -m vasco_gpu.ros")
    proc = subprocess.Popen(["bash", "-c", block], cwd=tmp_path, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True)
    lines = []
    reader = threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True)
    reader.start()
    try:
        end = time.monotonic() + 60
        while not any("ready" in ln for ln in lines) and proc.poll() is None and time.monotonic() < end:
            time.sleep(0.05)
        assert any("ready" in ln for ln in lines), "".join(lines)
        os.killpg(proc.pid, signal.SIGINT)
        assert proc.wait(10) == 0, "".join(lines)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(10)
