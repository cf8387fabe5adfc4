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
The modules here never import the compiled extension, except :mod:`.load` and :mod:`.cli`:
the rest returns plain NumPy data.

The parts, one job each: :mod:`.errors` (BagError, TfError), :mod:`.header` (stamps, frame
names), :mod:`.series` (samples over time), :mod:`.geometry` (quaternions, slerp, planar
poses), :mod:`.tf` (TfBuffer), :mod:`.topics` (which topics to read), :mod:`.storage`
(opening a bag with rosbags), :mod:`.scans` (LaserScans by REP 117, BagScans), :mod:`.poses`
(the laser pose at each scan), :mod:`.reader` (read_bag), :mod:`.carmen_writer`
(write_carmen_log), :mod:`.load` (load_bag), :mod:`.cli` (bag2map, bag2carmen).
"""

from __future__ import annotations

from .carmen_writer import write_carmen_log
from .errors import BagError, BagWarning, TfError
from .scans import NO_RETURN_FREE, BagScans
from .tf import TfBuffer

__all__ = ["BagError", "BagScans", "BagWarning", "NO_RETURN_FREE", "TfBuffer", "TfError", "read_bag", "write_carmen_log"]


def __getattr__(name: str):
    """read_bag, imported when first asked for: it needs rosbags, the rest of the package not."""
    if name == "read_bag":
        from .reader import read_bag

        return read_bag
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
