"""glibc's malloc kept from page-faulting fresh memory for every large message.

Each map the node publishes and each Path it takes passes through buffers of the message's size
(rclpy's serialised copy, Fast DDS's, the taken bytes), allocated and freed per message. glibc
serves an allocation above its mmap threshold with fresh pages and trims freed memory off the
heap's top, so each message of a few hundred KB or more page-faults its buffers in anew: about
half of a 1.65 MB map's time from publish() to a subscriber on the 2-core machine
(bench/ros_map_transport.py, its ``+buffers`` column; docs/ros.md). The node raises both
thresholds at start: allocations up to 8 MiB come from the heap, and up to 32 MiB freed there
stay for the next message. Another process (a subscriber of /map) can do the same with glibc's
environment variables: MALLOC_MMAP_THRESHOLD_=8388608 MALLOC_TRIM_THRESHOLD_=33554432.
Elsewhere than glibc nothing is changed."""

from __future__ import annotations

import ctypes
import platform

__all__ = ["KEPT_FREE_BYTES", "MESSAGE_BUFFER_BYTES", "give_back_free_memory", "keep_message_buffers"]

MESSAGE_BUFFER_BYTES = 8 << 20  # a 2000 x 2000 map (4 MB) and its copies
KEPT_FREE_BYTES = 32 << 20  # what the heap may hold freed: at most this much more than the node uses
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3  # <malloc.h>


def _libc_function(name: str):
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return None
    try:
        return getattr(ctypes.CDLL(None), name)
    except (OSError, AttributeError):
        return None


def give_back_free_memory() -> bool:
    """glibc's malloc_trim(0): the free pages of every arena go back to the system, also those
    below the trim threshold and between chunks in use. After a large site's full /map (a
    packed canvas), and again at the publication after it: making and packing the map, and the
    callback that asked for it (a Path's bytes, 8 MB for 10^5 poses), free tens of MB in pieces
    under the mmap threshold, which the heap would otherwise hold for good
    (bench/large_site_bench.py). A few ms; not done for small maps, whose buffers the
    thresholds keep on purpose. True where it ran."""
    trim = _libc_function("malloc_trim")
    if trim is None:
        return False
    trim.argtypes, trim.restype = [ctypes.c_size_t], ctypes.c_int
    trim(0)
    return True


def keep_message_buffers() -> bool:
    """Raises glibc's mmap and trim thresholds in this process (as above); True where it did."""
    mallopt = _libc_function("mallopt")
    if mallopt is None:
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return mallopt(_M_MMAP_THRESHOLD, MESSAGE_BUFFER_BYTES) == 1 and mallopt(_M_TRIM_THRESHOLD, KEPT_FREE_BYTES) == 1
