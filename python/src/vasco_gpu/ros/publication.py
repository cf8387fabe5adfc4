"""The node's map outputs: /map and /map_metadata (latched), map_updates (the cells changed since
the last message, as map_msgs/OccupancyGridUpdate: nav2's static layer reads it with
subscribe_to_updates) and the message ~/dynamic_map serves. The geometry /map keeps and the
updates are the canvas's (canvas.py); this file puts them in messages. Made by the node's
configure, published through lifecycle publishers (nothing goes out while the node is
inactive), dropped by its cleanup."""

from __future__ import annotations

import time
from array import array

from builtin_interfaces.msg import Time
from nav_msgs.msg import MapMetaData, OccupancyGrid
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from .canvas import Canvas, FullMap, fill_update
from .canvas_cells import PACKED_CANVAS_BYTES
from .grid import array_keeping_message, fill_grid
from .message_buffers import give_back_free_memory
from .tf_messages import map_update_type

__all__ = ["MapPublication"]

LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                     history=HistoryPolicy.KEEP_LAST)
# What nav2's static layer subscribes map_updates with (rclcpp's default: reliable, volatile,
# depth 10): an update is relative to the one before, so none may be dropped by the QoS; a
# subscriber that joins late starts from the latched /map and the updates after it.
# The finish's buffer is kept for the next publication up to this size, the size past which the
# canvas is packed: a small map made anew page-faults each time it is published (often), while a
# kept one costs a byte a /map cell for good beside the latched sample (a large site of 2e8
# cells: 200 MB); past it each publication's bytes are used once and freed (glibc gives such a
# block back to the system at once).
KEPT_FINISH_BYTES = PACKED_CANVAS_BYTES
UPDATES = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE,
                     history=HistoryPolicy.KEEP_LAST)


class MapPublication:
    """/map and map_updates of a node's LiveMap: ``publish`` sends what changed since the last
    publication. fixed: the mapper's frame never moves (map_size), so /map keeps its geometry."""

    def __init__(self, node, fixed: bool):
        self._node = node
        self.map_pub = node.create_lifecycle_publisher(OccupancyGrid, "map", LATCHED)
        self.meta_pub = node.create_lifecycle_publisher(MapMetaData, "map_metadata", LATCHED)
        update_type = map_update_type()
        self.update_pub = node.create_lifecycle_publisher(update_type, "map_updates", UPDATES)
        self.canvas = Canvas(fixed=fixed)
        self._published = -1  # the LiveMap version last published
        self.sent = False  # grid_msg published at least once: ~/dynamic_map serves it
        self.grid_msg = array_keeping_message(OccupancyGrid)  # /map's, filled again for each full map
        self.update_msg = array_keeping_message(update_type)
        self.counts = {"maps": 0, "updates": 0, "map_bytes": 0, "update_bytes": 0}
        self._finished = None  # the finish's buffer, written again for a map of its size
        self._subscribers = 0  # /map's, at the last publication
        self._updated = False  # updates sent since the last full map
        self._full_at = -1e9  # time.monotonic() of the last full map
        self._trim_due = False  # a large map was published: the heap's free pages go back at the next call

    def destroy(self) -> None:
        for pub in (self.map_pub, self.meta_pub, self.update_pub):
            self._node.destroy_lifecycle_publisher(pub)

    def again(self) -> None:
        """The next publish sends a full map, even where the grid did not change: after a render
        of every scan at new poses or with new parameters (a Path, a parameter change), or a new
        map_mode. A render the mapper makes for itself (a grid grown, a settle) moves no scan:
        what it changes goes out as an update, as any change does."""
        self._published = -1

    def reset(self, frame: str | None = None, stamp: Time | None = None) -> None:
        """A new map (~/reset, a time jump): the next map is a full one of its own size. With
        frame (the node active), the map sent so far is replaced at once by one of its geometry
        with every cell unknown: /map is latched, and a subscriber joining later (map_server,
        nav2, RViz) must not get the map of the scans just dropped."""
        geometry = self.canvas.geometry if frame is not None and self.sent else None
        self.canvas.reset()
        self._published = -1
        self.sent = geometry is not None  # inactive: ~/dynamic_map has no map until the next one
        if geometry is not None:
            cells = geometry[0] * geometry[1]
            fill_grid(self.grid_msg, geometry, array("b", b"\xff") * cells, frame=frame, stamp=stamp)
            self.map_pub.publish(self.grid_msg)
            self.meta_pub.publish(self.grid_msg.info)
            self._updated, self._full_at = False, time.monotonic()
            self._count("map", cells)

    def current(self) -> OccupancyGrid:
        """The last /map message with every update since applied (~/dynamic_map's answer), its
        stamp the last publication's. Its data is the canvas's: rclpy messages copy an array
        unless they check their fields, so it is given again here. A packed canvas's is unpacked
        into a message of its own, dropped with the answer. After a reset, until the next map:
        the empty map the reset published (its data in the message itself)."""
        canvas = self.canvas.current()
        if canvas is None:
            return self.grid_msg
        if not self.canvas.packed:
            self.grid_msg.data = canvas.data
            return self.grid_msg
        msg = array_keeping_message(OccupancyGrid)
        msg.header, msg.info, msg.data = self.grid_msg.header, self.grid_msg.info, canvas.data
        return msg

    def publish(self, live, settings, stamp: Time, *, now: bool = False) -> dict:
        """Publishes what changed in live's grid since the last publication: a full /map (and
        /map_metadata) after a render of every scan (a Path, new parameters) or a change of
        geometry, else the changed rectangle on map_updates. Returns the seconds of its steps
        (finish, message, publish); empty when nothing was published.

        No update goes out within map_update_interval of a full map (now: even so): /map and
        map_updates are two topics, and a small update sent right after a map of megabytes can
        reach a subscriber first, which applies it to the map before and then loses it under
        the new one. The changes wait for the next publication, which carries them all (the
        update is the difference from the last canvas sent)."""
        if self._trim_due:  # what the callback that published it freed since (a Path's bytes) goes back too
            self._trim_due = False
            give_back_free_memory()
        # A subscriber that joined since got the latched /map, without the updates sent after it:
        # it gets the map as it is now, in one piece (nav2's static layer joining late).
        subscribers = self.map_pub.get_subscription_count()
        joined, self._subscribers = subscribers > self._subscribers and self._updated, subscribers
        if live.version == self._published and not joined:
            return {}
        full_due = joined or self._published == -1
        if not (full_due or now) and time.monotonic() - self._full_at < settings.map_update_interval:
            return {}
        s = settings
        t0 = time.perf_counter()
        got = live.finish_grid(s.map_mode, s.free_thresh, s.occupied_thresh, out=self._finished)
        self._published = live.version
        if got is None:
            return {}
        if not isinstance(got[1], array):  # a new size: a buffer of it, written again next time
            self._finished = array("b", got[1]) if len(got[1]) <= KEPT_FINISH_BYTES else None
            if self._finished is not None:
                got = (got[0], self._finished)
        geometry = self.canvas.geometry
        if geometry is not None and geometry[2] != got[0][2]:
            self.canvas.reset()  # a new cell size: a canvas of the map's own size (its margin was in cells)
        out = self.canvas.publish(got, live.mapper.frame, full=full_due, reach=live.reach)
        live.clear_reach()
        if out is None:
            return {}
        t1 = time.perf_counter()
        if isinstance(out, FullMap):
            fill_grid(self.grid_msg, out.geometry, out.data, frame=s.map_frame, stamp=stamp)
            t2 = time.perf_counter()
            self.map_pub.publish(self.grid_msg)
            self.meta_pub.publish(self.grid_msg.info)
            if self.canvas.packed:  # the message's array was made for it: the writer holds the map now
                self.grid_msg.data = array("b")
                self._trim_due = give_back_free_memory()
            self.sent, self._updated, self._full_at = True, False, time.monotonic()
            self._count("map", len(out.data))
        else:
            fill_update(self.update_msg, out, frame=s.map_frame, stamp=stamp)
            self.grid_msg.header.stamp = stamp  # ~/dynamic_map's: the map as of this update
            t2 = time.perf_counter()
            self.update_pub.publish(self.update_msg)
            self._updated = True
            self._count("update", len(out.data))
        return {"finish": t1 - t0, "message": t2 - t1, "publish": time.perf_counter() - t2}

    def _count(self, kind: str, cells: int) -> None:
        self.counts[f"{kind}s"] += 1
        self.counts[f"{kind}_bytes"] += cells
