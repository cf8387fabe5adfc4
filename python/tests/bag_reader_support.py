"""What the bag reader's tests share: vasco_gpu's bags and msgs packages loaded on their own
(package_under_test: no compiled extension), the synthetic bags and the numbers they are made of.
The bags are small synthetic ones written by bag_maker in the three formats rosbags writes (ROS 1
.bag, ROS 2 sqlite3 and MCAP directories).
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np

import package_under_test

HERE = Path(__file__).resolve().parent


def _load(name: str, path: Path):
    """A module loaded from a file and registered under name (dataclasses and pickle need that)."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


vb = package_under_test.load("bags")
laser = package_under_test.load("msgs.laser")
writer = package_under_test.load("bags.carmen_writer")
bm = _load("vasco_gpu_bag_maker", HERE / "bag_maker.py")

FORMATS = bm.FORMATS
T0 = 1_700_000_000.05  # a realistic epoch, with a fraction nanoseconds do not hold exactly
RMIN, RMAX = 0.1, 30.0
ANGLE_MIN, ANGLE_STEP = -1.5707963, 0.0174533


def stamps_of(n: int, dt: float = 0.1) -> list[float]:
    return [T0 + k * dt for k in range(n)]


def plain_ranges(n_scans: int, n_beams: int = 37, seed: int = 1) -> list[np.ndarray]:
    """Valid float32 ranges (within [RMIN, RMAX]), random bits in the mantissa."""
    rng = np.random.default_rng(seed)
    return [rng.uniform(RMIN, RMAX, n_beams).astype(np.float32) for _ in range(n_scans)]


def base_poses(n: int) -> np.ndarray:
    k = np.arange(n, dtype=np.float64)
    return np.column_stack([1.0 + 0.3 * k, -2.0 + 0.1 * k * k, 0.4 * k - 1.0])


def make(tmp_path, fmt, name="bag", n=5, ranges=None, **kw) -> Path:
    """A bag of n scans in tmp_path; keywords go to bag_maker.write_bag."""
    stamps = kw.pop("stamps", stamps_of(n))
    if ranges is None:
        ranges = plain_ranges(len(stamps))
    return bm.write_bag(bm.bag_path(tmp_path, fmt, name), fmt, stamps, ranges, ANGLE_MIN, ANGLE_STEP,
                        RMIN, RMAX, **kw)


def bits(a) -> np.ndarray:
    a = np.ascontiguousarray(a)
    return a.view(np.uint32 if a.dtype == np.float32 else np.uint64)


def quat_yaw(yaw: float) -> float:
    """The yaw the reader gets back from bag_maker's quaternion of yaw."""
    x, y, z, w = bm.yaw_quaternion(yaw)
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def expected_stamps(stamps) -> np.ndarray:
    return np.array([s + ns * 1e-9 for s, ns in map(bm.split_stamp, stamps)])


def rep117_case():
    """(input ranges, expected 'skip' output, expected 'free' output, expected counts)."""
    f32 = np.float32
    v = np.array([RMIN, RMAX, 5.25, np.nan, np.inf, -np.inf, 0.05, 0.0, -1.0, 30.5, 60.0, 12.0], dtype=f32)
    nan = f32(np.nan)
    skip = np.array([RMIN, RMAX, 5.25, nan, np.inf, nan, nan, nan, nan, nan, nan, 12.0], dtype=f32)
    free = skip.copy()
    free[4] = np.nextafter(f32(50), f32(0))
    counts = {"nan": 1, "pos_inf": 1, "neg_inf": 1, "below_min": 3, "above_max": 2}
    return v, skip, free, counts


def stamp_of(t: float) -> str:
    """A bag_maker stamp as the errors write it: exact seconds text."""
    sec, ns = bm.split_stamp(t)
    return f"{sec}.{ns:09d}"


def parse_robotlaser(line: str) -> dict:
    tok = line.split()
    assert tok[0] == "ROBOTLASER1"
    n = int(tok[8])
    rest = tok[9 + n:]
    assert int(rest[0]) == 0  # no remissions
    nums = [float(x) for x in rest[1:12]]
    return {
        "laser_type": int(tok[1]), "start": float(tok[2]), "fov": float(tok[3]), "res": float(tok[4]),
        "max_range": float(tok[5]), "accuracy": float(tok[6]), "remission_mode": int(tok[7]),
        "ranges": np.array([float(x) for x in tok[9:9 + n]], dtype=np.float64).astype(np.float32),
        "laser": nums[0:3], "robot": nums[3:6], "tv_rv": nums[6:8], "safety": nums[8:10],
        "turn_axis": nums[10],
        "ipc": float(rest[12]), "host": rest[13], "logger": float(rest[14]), "fields": len(rest),
    }
