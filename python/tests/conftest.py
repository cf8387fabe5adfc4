"""Shared helpers of the Python tests: where the repository's data lives, the golden cases
(tests/data/golden/SHA256SUMS, found as tests/golden_support.h finds them) and an independent
GRIDMAP digest."""

from __future__ import annotations

import hashlib
import struct
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = ROOT / "tests" / "data" / "golden"
LOG_DIRS = [ROOT / "logs", GOLDEN]
FR079 = ROOT / "logs" / "fr079-complete.gfs.log.gz"


def golden_cases():
    """(name, log path, ini path, sha256) per line of SHA256SUMS ("HASH  LOG__PARAMS")."""
    cases = []
    for line in (GOLDEN / "SHA256SUMS").read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        digest, name = line.split()
        log, params = name.split("__", 1)
        path = next((d / f"{log}.log.gz" for d in LOG_DIRS if (d / f"{log}.log.gz").is_file()), None)
        cases.append((name, path, GOLDEN / "params" / f"{params}.ini", digest))
    return cases


def gridmap_digest(cells: np.ndarray, resolution: float) -> str:
    """SHA-256 of a CARMEN GRIDMAP payload, computed here and not by the library: int32
    size_x, int32 size_y, float32 resolution, then the cells x-major as float32, all
    little-endian."""
    size_x, size_y = cells.shape
    h = hashlib.sha256(struct.pack("<iif", size_x, size_y, resolution))
    h.update(np.asarray(cells, dtype="<f4").tobytes(order="C"))
    return h.hexdigest()


def cuda_or_skip():
    import vasco_gpu as vg

    status = vg.cuda_available()
    if not status:
        pytest.skip(f"CUDA backend not usable here: {status.reason}")


# The ROS 2 tests' two shared fixtures (each test file imports ros_support first, so the
# environment is set before rclpy starts; rclpy and the player are imported here only when a
# test asks for them, so the other tests run without ROS).
@pytest.fixture(scope="module")
def intel():
    """The intel log at the node's default map cell, ROS's 0.05 m (the log's own keys give 0.1)."""
    import vasco_gpu as vg

    return vg.load_log(ROOT / "logs" / "intel.gfs.log.gz", map_resolution=0.05)


@pytest.fixture(scope="module")
def ros():
    """rclpy started in this process for one test file, with the player that drives the node."""
    import rclpy
    from ros_player import Player

    rclpy.init()
    player = Player()
    yield player
    player.close()
    rclpy.try_shutdown()
