"""The ROS 2 tests' and the node benchmark's own node: publishes scans, tf and Paths, records
/map as a subscriber with nav2's subscribe_to_updates has it (each /map, and each map_updates
message applied to a copy of the map before it), calls the node's services. Import ros_support
first (the environment)."""

from __future__ import annotations

import math
import threading
from array import array
import time

import numpy as np
import rclpy
from builtin_interfaces.msg import Time
from map_msgs.msg import OccupancyGridUpdate
from geometry_msgs.msg import PoseStamped, TransformStamped
from nav_msgs.msg import OccupancyGrid
from nav_msgs.msg import Path as PathMsg
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import LaserScan, PointCloud2, PointField
from tf2_msgs.msg import TFMessage

LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
RELIABLE = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
UPDATES = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)


def stamp_of(ns: int):
    return Time(sec=ns // 10**9, nanosec=ns % 10**9)


def quat(theta: float):
    return 0.0, 0.0, math.sin(theta / 2), math.cos(theta / 2)


class Player:
    """The test's own node: publishes scans, tf and Paths, records /map, calls the services."""

    def __init__(self):
        self.node = rclpy.create_node("vasco_test_player")
        n = self.node
        self.scan = n.create_publisher(LaserScan, "scan", RELIABLE)
        self.tf = n.create_publisher(TFMessage, "/tf", RELIABLE)
        self.tf_static = n.create_publisher(TFMessage, "/tf_static", LATCHED)
        self.cloud = n.create_publisher(PointCloud2, "points", RELIABLE)
        self.path = n.create_publisher(PathMsg, "trajectory", QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE))
        self.maps: list[tuple[float, OccupancyGrid]] = []  # full maps and maps with an update applied
        self.full_maps = self.updates = 0
        self.update_bytes = 0
        self._full_sent = -1  # the latest full map's source timestamp
        self.lock = threading.Lock()
        n.create_subscription(OccupancyGrid, "map", self._on_map, LATCHED)
        n.create_subscription(OccupancyGridUpdate, "map_updates", self._on_update, UPDATES)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(n)
        self.thread = threading.Thread(target=self.executor.spin, daemon=True)
        self.thread.start()

    def _on_map(self, msg, info):
        with self.lock:
            self.maps.append((time.monotonic(), msg))
            self.full_maps += 1
            self._full_sent = info["source_timestamp"]

    def _on_update(self, u, info):
        """The latest map with u applied, as a new map (its header u's). An update published
        before the latest full map (the publisher's source timestamps; the two topics are not
        ordered with respect to each other, and stamps may go back) is one that map already holds,
        and is dropped."""
        now = time.monotonic()
        with self.lock:
            if not self.maps or info["source_timestamp"] < self._full_sent:
                return
            base = self.maps[-1][1]
            info = base.info
            cells = np.frombuffer(bytes(base.data), dtype=np.int8).reshape(info.height, info.width).copy()
            assert u.x >= 0 and u.y >= 0 and u.x + u.width <= info.width and u.y + u.height <= info.height, \
                f"update {u.x},{u.y} {u.width}x{u.height} outside the {info.width}x{info.height} map"
            cells[u.y:u.y + u.height, u.x:u.x + u.width] = np.frombuffer(bytes(u.data), dtype=np.int8).reshape(
                u.height, u.width)
            m = OccupancyGrid(header=u.header, info=info)
            m.data = array("b", cells.tobytes())
            self.maps.append((now, m))
            self.updates += 1
            self.update_bytes += len(u.data)

    def map_count(self) -> int:
        with self.lock:
            return len(self.maps)

    def latest(self):
        with self.lock:
            return self.maps[-1][1] if self.maps else None

    def transform(self, parent, child, ns, pose):
        t = TransformStamped()
        t.header.frame_id, t.child_frame_id, t.header.stamp = parent, child, stamp_of(ns)
        t.transform.translation.x, t.transform.translation.y = float(pose[0]), float(pose[1])
        r = t.transform.rotation
        r.x, r.y, r.z, r.w = quat(float(pose[2]))
        return t

    def laser_scan(self, ns, ranges, a0, da, frame="laser"):
        m = LaserScan()
        m.header.frame_id, m.header.stamp = frame, stamp_of(ns)
        m.angle_min, m.angle_increment = float(a0), float(da)
        m.angle_max = float(np.float32(a0) + np.float32(da) * np.float32(len(ranges) - 1))
        m.range_min, m.range_max = 0.0, 81.91
        m.ranges = ranges.astype(np.float32).tolist()
        return m

    def wait_matched(self, timeout=20.0):
        """Until the node's subscriptions match our publishers (messages sent before are lost)."""
        end = time.monotonic() + timeout
        pubs = (self.scan, self.tf, self.tf_static, self.path)
        while time.monotonic() < end:
            if all(p.get_subscription_count() > 0 for p in pubs):
                return
            time.sleep(0.02)
        raise AssertionError("the node's subscriptions did not match within 20 s")

    def point_cloud(self, ns, points, frame="laser"):
        """A PointCloud2 of (k, 3) float32 points x, y, z."""
        m = PointCloud2()
        m.header.frame_id, m.header.stamp = frame, stamp_of(ns)
        m.height, m.width, m.is_bigendian, m.is_dense = 1, len(points), False, True
        m.fields = [PointField(name=n, offset=4 * j, datatype=PointField.FLOAT32, count=1) for j, n in enumerate("xyz")]
        m.point_step, m.row_step = 12, 12 * len(points)
        m.data = np.ascontiguousarray(points, dtype="<f4").tobytes()
        return m

    def replay(self, scans, stamps, rate_hz=500.0, points_of=None):
        """map -> base_link on /tf and a LaserScan in 'laser' at every scan's stamp; with points_of,
        a PointCloud2 of points_of(ranges, first_angle, angle_step) on 'points' instead."""
        self.wait_matched()
        self.tf_static.publish(TFMessage(transforms=[self.transform("base_link", "laser", 0, (0, 0, 0))]))
        period, start = 1.0 / rate_hz, time.monotonic()
        for s in range(len(scans)):
            ns = int(stamps[s])
            self.tf.publish(TFMessage(transforms=[self.transform("map", "base_link", ns, scans.poses[s])]))
            r, a0, da = scans.ranges_of(s), float(scans.first_angle[s]), float(scans.angle_step[s])
            if points_of is None:
                self.scan.publish(self.laser_scan(ns, r, a0, da))
            else:
                self.cloud.publish(self.point_cloud(ns, points_of(r, a0, da).reshape(-1, 3)))
            time.sleep(max(0.0, start + (s + 1) * period - time.monotonic()))  # the rate, not a gap

    def publish_path(self, stamps, poses, frame="map"):
        self.path.publish(self.path_message(stamps, poses, frame))

    def path_message(self, stamps, poses, frame="map"):
        msg = PathMsg()
        msg.header.frame_id = frame
        for ns, p in zip(stamps, poses):
            ps = PoseStamped()
            ps.header.frame_id, ps.header.stamp = frame, stamp_of(int(ns))
            ps.pose.position.x, ps.pose.position.y = float(p[0]), float(p[1])
            o = ps.pose.orientation
            o.x, o.y, o.z, o.w = quat(float(p[2]))
            msg.poses.append(ps)
        return msg

    def call(self, srv_type, name, request, timeout=10.0):
        """The service's answer. A query (GetMap, GetState) is asked again once where no answer
        came: a client made just now can miss the reply, DDS having matched the server's reply
        writer to its reader only after the reply went (wait_for_service sees the request side
        alone); a request that changes something is asked once."""
        client = self.node.create_client(srv_type, name)
        try:
            assert client.wait_for_service(timeout_sec=timeout), f"service {name} not there"
            for attempt in range(2 if srv_type.__name__ in ("GetMap", "GetState") else 1):
                future = client.call_async(request)
                end = time.monotonic() + (timeout if attempt else timeout / 2)
                while not future.done() and time.monotonic() < end:
                    time.sleep(0.01)
                if future.done():
                    return future.result()
            raise AssertionError(f"{name}: no answer within {timeout} s")
        finally:
            self.node.destroy_client(client)

    def wait_quiet(self, quiet_s: float = 1.0, limit_s: float = 300.0) -> None:
        """Until no /map has come for quiet_s: the node has mapped what it was sent and settled,
        so the next /map answers what is sent next."""
        end, n, since = time.monotonic() + limit_s, self.map_count(), time.monotonic()
        while time.monotonic() - since < quiet_s and time.monotonic() < end:
            time.sleep(0.05)
            if self.map_count() != n:
                n, since = self.map_count(), time.monotonic()

    def wait_map(self, after: int, match=None, timeout=30.0):
        """The first /map received after the after-th that satisfies match (or any)."""
        end = time.monotonic() + timeout
        seen = after
        while time.monotonic() < end:
            with self.lock:
                new = self.maps[seen:]
                seen = len(self.maps)
            for _, m in new:
                if match is None or match(m):
                    return m
            time.sleep(0.02)
        return None

    def close(self):
        self.executor.shutdown()
        self.thread.join(10)
        self.node.destroy_node()
