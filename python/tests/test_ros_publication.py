"""MapPublication without a ROS graph (its publishers stand-ins): what it keeps between
publications. A finish's buffer past KEPT_FINISH_BYTES is used once and dropped (a large site's
map would otherwise be held twice, the canvas and the buffer), and a packed canvas's /map message
lets its array go once published (the DDS writer holds the map); either way the map it keeps for
~/dynamic_map is the finished map placed in the canvas, computed here independently."""

from __future__ import annotations

from types import SimpleNamespace as NS

import numpy as np
import pytest

import ros_support  # noqa: F401  (the ROS environment)

ros_support.import_or_skip("rclpy")

from builtin_interfaces.msg import Time  # noqa: E402

from test_ros_canvas import MODE, add_scans, expected_canvas  # noqa: E402
from vasco_gpu.ros import canvas_cells, publication  # noqa: E402
from vasco_gpu.ros.live_map import LiveMap  # noqa: E402


class Publisher:
    def __init__(self):
        self.sent = 0

    def publish(self, msg):
        self.sent += 1

    def get_subscription_count(self):
        return 1


class Node:
    def create_lifecycle_publisher(self, msg_type, topic, qos):
        return Publisher()


SETTINGS = NS(map_mode=MODE[0], free_thresh=MODE[1], occupied_thresh=MODE[2], map_update_interval=0.0,
              map_frame="map")


@pytest.mark.parametrize("kept, packed", [(publication.KEPT_FINISH_BYTES, False), (0, False), (0, True)])
def test_the_kept_map_is_the_finished_map_whether_the_buffer_is_kept_or_not(intel, monkeypatch, kept, packed):
    monkeypatch.setattr(publication, "KEPT_FINISH_BYTES", kept)
    trims = []
    if packed:  # a packed canvas: the message drops its map once published, and the heap is trimmed
        monkeypatch.setattr(canvas_cells, "PACKED_CANVAS_BYTES", -1)
        monkeypatch.setattr(canvas_cells, "TILE", 7)
        monkeypatch.setattr(publication, "give_back_free_memory", lambda: trims.append(pub.map_pub.sent) or True)
    pub = publication.MapPublication(Node(), fixed=False)
    live = LiveMap(intel.params, backend="cpu_float")
    scans = intel.scans.select(0, 120)
    stamps = np.arange(120, dtype=np.int64)
    for first in range(0, 120, 15):
        add_scans(live, scans, np.arange(first, first + 15), stamps)
        pub.publish(live, SETTINGS, Time(), now=True)
        kept_map = pub.current()
        info = kept_map.info
        geometry = (info.width, info.height, info.resolution,
                    (info.origin.position.x, info.origin.position.y, 0.0))
        got = np.frombuffer(kept_map.data, dtype=np.int8).reshape(info.height, info.width)
        np.testing.assert_array_equal(got, expected_canvas(geometry, live.finish_grid(*MODE)))
        assert (pub._finished is None) == (kept == 0)
        assert (len(pub.grid_msg.data) == 0) == packed and len(kept_map.data) == info.width * info.height
    assert pub.map_pub.sent + pub.update_pub.sent == 8 and pub.update_pub.sent > 0
    # a packed canvas: trimmed after each full map, and again at the next publication (what its
    # caller freed since); a plain one never
    fulls = pub.map_pub.sent
    assert (len(trims) in (2 * fulls - 1, 2 * fulls)) if packed else trims == [], (trims, fulls)
