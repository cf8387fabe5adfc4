"""Fast DDS's shared-memory transport sized for maps, for a node on shared memory alone.

Fast DDS sends a message larger than its transport's maximum (65,500 bytes by default, in a
512 KiB segment) in fragments: a map of 1302 x 1267 cells (fr101 at 0.05 m, 1.65 MB) took
about 25 ms from publish() to a subscriber on the 2-core machine, 4-5 ms in one piece. When the
process runs on Fast DDS's shared memory alone (FASTDDS_BUILTIN_TRANSPORTS=SHM, what this
project's tests and benchmarks use) and names no XML profile itself, the node's participant
takes fastdds_shm_maps.xml beside this file: the same transport, whole messages up to 4 MiB in
an 8 MiB segment. Subscribers need nothing: the publisher decides the fragments. The profile's
endpoints free a message's buffer once the history lets it go (the XML says why), which rmw
takes from it with RMW_FASTRTPS_USE_QOS_FROM_XML=1, set here unless the user set it. Anything
else (UDP, another middleware, a profile of the user's) is left as it is; docs/ros.md says how
to take the profile there too.

Fast DDS 2 (Jazzy) reads the profile from FASTRTPS_DEFAULT_PROFILES_FILE, Fast DDS 3 (Kilted)
from FASTDDS_DEFAULT_PROFILES_FILE: both are set."""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["MAP_SIZED_SHM_PROFILE", "map_sized_shm_in_use", "use_map_sized_shm"]

MAP_SIZED_SHM_PROFILE = Path(__file__).with_name("fastdds_shm_maps.xml")
_PROFILE_VARIABLES = ("FASTDDS_DEFAULT_PROFILES_FILE", "FASTRTPS_DEFAULT_PROFILES_FILE")
_QOS_FROM_XML = "RMW_FASTRTPS_USE_QOS_FROM_XML"
_FAST_DDS = ("", "rmw_fastrtps_cpp", "rmw_fastrtps_dynamic_cpp")


def use_map_sized_shm(environ=os.environ) -> bool:
    """Points Fast DDS at the map-sized profile (before rclpy starts) when the process is on
    its shared memory alone and has no profile; True if it did."""
    if environ.get("FASTDDS_BUILTIN_TRANSPORTS", "").strip().upper() != "SHM":
        return False
    if any(environ.get(v) for v in _PROFILE_VARIABLES) or environ.get("RMW_IMPLEMENTATION", "") not in _FAST_DDS:
        return False
    if not MAP_SIZED_SHM_PROFILE.is_file():  # an install without it: Fast DDS's defaults, as before
        return False
    for variable in _PROFILE_VARIABLES:
        environ[variable] = str(MAP_SIZED_SHM_PROFILE)
    environ.setdefault(_QOS_FROM_XML, "1")
    return True


def map_sized_shm_in_use(environ=os.environ) -> bool:
    """Whether Fast DDS takes the map-sized profile in this process."""
    return all(environ.get(v) == str(MAP_SIZED_SHM_PROFILE) for v in _PROFILE_VARIABLES)
