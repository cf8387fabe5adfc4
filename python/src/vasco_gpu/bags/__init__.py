"""ROS bags for the mapper: laser scans and laser poses read from ROS 1 ``.bag`` files, ROS 2 bag
directories (sqlite3 or MCAP storage, with ``metadata.yaml``) and bare ``.db3`` / ``.mcap``
files, as plain NumPy arrays; and tf's frame tree for live use (TfBuffer).

:func:`read_bag` reads the ``sensor_msgs/LaserScan`` (or ``MultiEchoLaserScan``) messages of one
or more topics and the pose of each laser at each scan's stamp, taken either from tf (``/tf``, ``/tf_static``) or from a
pose topic (``nav_msgs/Odometry``, ``geometry_msgs/PoseStamped``,
``geometry_msgs/PoseWithCovarianceStamped``). :func:`write_carmen_log` writes the result as a
CARMEN log of ``ROBOTLASER1`` lines. :class:`TfBuffer` is the tf tree read_bag builds, which a
ROS node can feed with TFMessages as they come and ask for transforms at stamps, without a bag.

The bags are read with the pure-Python ``rosbags`` package (its ``AnyReader``), which
deserializes with the type definitions stored in the bag; a ROS 2 bag without them falls back
to the ROS 2 Humble definitions. Only :mod:`.storage` and :mod:`.reader` need rosbags:
``read_bag`` imports it when first asked for (an ImportError then when it is not installed).
The modules here never import the compiled extension, except :mod:`.load`, :mod:`.cli`,
:mod:`.bag_writer` and :mod:`.carmen2bag` (which write through it or hand the scans to it):
the rest returns plain NumPy data. What a message means (LaserScan, MultiEchoLaserScan,
PointCloud2, tf) is :mod:`vasco_gpu.msgs`'s, which the ROS 2 node shares.

The parts, one job each: :mod:`.errors` (BagError, TfError, BagWarning), :mod:`.topics`
(which topics to read), :mod:`.options` (the bag options' values, checked before a bag is
read), :mod:`.storage` (opening a bag with rosbags), :mod:`.scans` (a topic's scans through
the message table, BagScans), :mod:`.poses` (the laser pose at each
scan), :mod:`.reader` (read_bag), :mod:`.carmen_writer` (write_carmen_log), :mod:`.load`
(load_bag), :mod:`.info` (bag_info: what a bag holds and the command that maps it),
:mod:`.bag_writer` (a CARMEN log as a bag), and the console tools :mod:`.cli`
(bag2map, bag2carmen) and :mod:`.carmen2bag` (carmen2bag).
"""

from __future__ import annotations

from ..msgs.laser import NO_RETURN_FREE
from ..msgs.tf import TfBuffer
from .carmen_writer import write_carmen_log
from .errors import BagError, BagWarning, TfError
from .scans import BagScans

__all__ = ["BagError", "BagScans", "BagWarning", "NO_RETURN_FREE", "TfBuffer", "TfError", "read_bag", "write_carmen_log"]


def __getattr__(name: str):
    """read_bag, imported when first asked for: it needs rosbags, the rest of the package not."""
    if name == "read_bag":
        from .reader import read_bag

        return read_bag
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
