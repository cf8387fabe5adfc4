"""The node's map outputs: /map and /map_metadata (latched), map_updates (the cells changed since
the last message, as map_msgs/OccupancyGridUpdate) and the message ~/dynamic_map serves. Made by
the node's configure, published through lifecycle publishers (nothing goes out while the node
is inactive), dropped by its cleanup."""

from __future__ import annotations

import time

from builtin_interfaces.msg import Time
from nav_msgs.msg import MapMetaData, OccupancyGrid
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from .grid import fill_grid

__all__ = ["MapPublication"]

LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                     history=HistoryPolicy.KEEP_LAST)


class MapPublication:
    """/map of a node's LiveMap: ``publish`` sends what changed since the last publication."""

    def __init__(self, node):
        self._node = node
        self.map_pub = node.create_lifecycle_publisher(OccupancyGrid, "map", LATCHED)
        self.meta_pub = node.create_lifecycle_publisher(MapMetaData, "map_metadata", LATCHED)
        self._published = -1  # the LiveMap version last published
        self.sent = False  # grid_msg published at least once: ~/dynamic_map serves it
        self.grid_msg = OccupancyGrid()  # /map's message, filled again for each map
        self._grid_data = None  # its data array, written again for a map of its size

    def destroy(self) -> None:
        self._node.destroy_lifecycle_publisher(self.map_pub)
        self._node.destroy_lifecycle_publisher(self.meta_pub)

    def again(self) -> None:
        """The next publish sends the map even where the grid did not change (map_mode)."""
        self._published = -1

    def publish(self, live, settings, stamp: Time) -> dict:
        """Publishes /map and /map_metadata when live's grid changed since the last publication.
        Returns the seconds of its steps (finish, message, publish); empty when nothing was
        published."""
        if live.version == self._published:
            return {}
        s = settings
        t0 = time.perf_counter()
        # the data written again into the last map's array where the size is the same (that
        # message was published, that is serialised, by then)
        got = live.finish_grid(s.map_mode, s.free_thresh, s.occupied_thresh, out=self._grid_data)
        self._published = live.version
        if got is None:
            return {}
        t1 = time.perf_counter()
        msg = self.grid_msg  # one message, filled again for each map
        self._grid_data = fill_grid(msg, *got, frame=s.map_frame, stamp=stamp)
        t2 = time.perf_counter()
        self.map_pub.publish(msg)
        self.meta_pub.publish(msg.info)
        self.sent = True
        return {"finish": t1 - t0, "message": t2 - t1, "publish": time.perf_counter() - t2}
