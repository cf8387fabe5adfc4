"""sensor_msgs/PointCloud2 read as scans (vasco_gpu.bags.cloud): the bundled intel log written as
clouds maps as the log does, and read_cloud on clouds built here point by point: layouts, the
height band through the mount, the nearest point per bin, what it refuses."""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("rosbags")

import vasco_gpu as vg  # noqa: E402
from vasco_gpu.bags.bag_writer import write_bag  # noqa: E402
from vasco_gpu.msgs import cloud as vc  # noqa: E402
from vasco_gpu.msgs.errors import BagError  # noqa: E402
from vasco_gpu.msgs.laser import COUNT_KEYS  # noqa: E402
from vasco_gpu.msgs.scan_options import SCAN_DEFAULTS, check_cloud_options  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_bags import ANGLE_BOUND, INTEL, assert_within_angle_bound, finished, run_script  # noqa: E402


@pytest.fixture(scope="module")
def intel():
    """The log at a bag's default map cell (ROS's 0.05 m; the log's own keys give 0.1)."""
    return vg.load_log(INTEL, map_resolution=0.05)


@pytest.fixture(scope="module")
def cloud_bag(tmp_path_factory, intel):
    out = tmp_path_factory.mktemp("clouds") / "cloud.mcap"
    write_bag(intel, out, log_path=str(INTEL), cloud=True)
    return out


def load(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scans beyond the tf span: counted, tested in test_bags
        return vg.load_bag(path, **kw)


@pytest.mark.parametrize("step", [1.0, None])  # intel's own 1 degree, and the default 0.25
def test_the_log_as_clouds_maps_as_the_log(intel, cloud_bag, step):
    got = finished(load(cloud_bag, z_band=(0.25, 1.0), cloud_angle_step=step))
    c = assert_within_angle_bound(finished(intel), got)
    assert c.class_agreement == 1.0, c.table()


def test_the_band_leaves_the_floor_and_the_ceiling_out(intel, cloud_bag):
    # A band with the floor in: the floor points halfway along each beam are nearer than the
    # walls, so every beam ends half way and the map is not the log's.
    floor = finished(load(cloud_bag, z_band=(-0.1, 1.0)))
    c = vg.compare(finished(intel), floor)
    assert c.differing_cells > 10 * ANGLE_BOUND * c.cells


def test_the_docs_command(tmp_path, cloud_bag):
    out = tmp_path / "cloud.map.gz"
    r = run_script("bag2map", "--z-band", "0.25,1.0", str(cloud_bag), str(out))  # docs/bags-and-poses.md
    assert r.returncode == 0, r.stderr
    want = finished(load(cloud_bag, z_band=(0.25, 1.0)))
    assert vg.read_map(out).sha256() == want.sha256()
    bad = run_script("bag2map", "--z-band", "1.0,0.25", str(cloud_bag), str(tmp_path / "x.map.gz"))
    assert bad.returncode != 0 and "z_band (--z-band MIN,MAX)" in bad.stderr
    assert not (tmp_path / "x.map.gz").exists()


def cloud(points, *, dtype="<f4", pad=0, row_pad=0, height=1, frame="lidar", fields="xyz"):
    """A PointCloud2 shaped object of (n, 3) points: float32 or float64, point padding, row padding."""
    pts = np.asarray(points, dtype=np.float64)
    size = np.dtype(dtype).itemsize
    step = 3 * size + pad
    width = len(pts) // height
    rows = []
    for h in range(height):
        rec = np.zeros((width, step), dtype=np.uint8)
        for j in range(3):
            rec[:, j * size:(j + 1) * size] = pts[h * width:(h + 1) * width, j].astype(dtype).view(np.uint8).reshape(width, size)
        rows.append(np.concatenate([rec.ravel(), np.full(row_pad, 0xAB, dtype=np.uint8)]))
    kind = 7 if size == 4 else 8
    return SimpleNamespace(
        header=SimpleNamespace(frame_id=frame, stamp=SimpleNamespace(sec=1, nanosec=0)), height=height, width=width,
        fields=[SimpleNamespace(name=n, offset=j * size, datatype=kind, count=1) for j, n in enumerate(fields)],
        is_bigendian=dtype.startswith(">"), point_step=step, row_step=width * step + row_pad,
        data=np.concatenate(rows) if rows else np.zeros(0, np.uint8))


def read(msg, **kw):
    counts = dict.fromkeys(COUNT_KEYS, 0)
    kw.setdefault("no_return", "skip")
    r = vc.read_cloud(msg, counts=counts, fail=lambda what: BagError(None, what), **kw)
    return r, counts


def beam(r, angle_deg):
    """The range of the beam at this angle (degrees) of a reading."""
    k = int(round((math.radians(angle_deg) - r.first_angle) / r.angle_step)) % len(r.ranges)
    return float(r.ranges[k])


@pytest.mark.parametrize("layout", [dict(), dict(dtype="<f8"), dict(dtype=">f4"), dict(pad=4, row_pad=6),
                                    dict(height=2, row_pad=3)])
def test_layouts_nearest_point_per_bin_and_nan_skipped(layout):
    pts = [(2.0, 0.0, 0.5), (3.0, 0.0, 0.5),            # 0 degrees: the nearer one
           (0.0, 4.0, 0.5), (math.nan, 1.0, 0.5),        # 90 degrees; a NaN point
           (-1.0, 0.0, 0.0), (-5.0, 0.0, 1.0)]           # 180 degrees: floor out, wall in
    r, counts = read(cloud(pts, **layout), z_band=(0.2, 1.8), angle_step=math.radians(1.0))
    assert r.frame == "lidar" and len(r.ranges) == 360 and r.first_angle == -math.pi
    assert beam(r, 0) == 2.0 and beam(r, 90) == 4.0 and beam(r, 180) == 5.0
    assert counts["points"] == 4 and counts["bins_empty"] == 357 and counts["messages"] == 1
    assert np.isinf(r.ranges).sum() == 357  # no return: +inf, skipped by the mapper


def test_the_band_is_in_the_base_frame_through_the_mount():
    # The lidar 1 m above the base, pitched 90 degrees down about y: its x axis points down.
    half = math.sqrt(0.5)
    mount = (np.array([0.0, 0.0, 1.0]), np.array([0.0, half, 0.0, half]))
    pts = [(0.5, 0.0, 0.0),   # 0.5 m along x: down, at base height 0.5 -> in the band
           (1.5, 2.0, 0.0)]   # 1.5 m down: base height -0.5 -> out
    r, counts = read(cloud(pts), z_band=(0.2, 1.8), angle_step=math.radians(1.0), mount=mount)
    assert counts["points"] == 1 and beam(r, 0) == 0.5


def test_range_max_and_free_bins():
    pts = [(10.0, 0.0, 0.5), (60.0, 1.0, 0.5)]
    r, counts = read(cloud(pts), range_max=50.0, no_return="free", angle_step=math.radians(1.0))
    assert beam(r, 0) == 10.0
    assert counts["points"] == 1 and counts["pos_inf"] == 359
    assert r.ranges[np.isfinite(r.ranges) & (r.ranges != 10.0)].max() < 50  # free: just below 50


def test_what_read_cloud_refuses():
    with pytest.raises(BagError, match="has no field 'z'"):
        read(cloud([(1, 0, 0)], fields="xyq"))
    bad = cloud([(1, 0, 0), (2, 0, 0)])
    bad.data = bad.data[:10]
    with pytest.raises(BagError, match="bytes"):
        read(bad)
    bad = cloud([(1, 0, 0)])
    bad.fields[2].datatype = 2  # uint8
    with pytest.raises(BagError, match="datatype 2"):
        read(bad)
    for kw, word in [(dict(z_band=(1.0, 0.5)), "z_band"), (dict(angle_step=0.0), "cloud_angle_step"),
                     (dict(range_max=-1.0), "cloud_range_max")]:
        opts = {"z_band": SCAN_DEFAULTS["z_band"], "angle_step": math.radians(SCAN_DEFAULTS["cloud_angle_step"]),
                "range_max": SCAN_DEFAULTS["cloud_range_max"], **kw}
        with pytest.raises(ValueError, match=word):
            check_cloud_options(opts["z_band"], opts["angle_step"], opts["range_max"])


def test_a_cloud_frame_without_a_mount_is_an_error_that_says_what_to_do(cloud_bag):
    with pytest.raises(vg.FileError) as e:
        load(cloud_bag, base_frame="body")
    text = str(e.value)
    assert "no static chain body -> 'laser'" in text and "--base-frame laser" in text
    load(cloud_bag, base_frame="laser", z_band=(0.25, 1.0))  # heights in the cloud's own frame


def test_errors_name_the_bag_once_and_guess_a_mistyped_name(tmp_path, cloud_bag):
    r = run_script("bag2map", "--scan-topic", "/pointz", str(cloud_bag), str(tmp_path / "x.map"))
    assert r.returncode == 1
    assert r.stderr.count(str(cloud_bag)) == 1, r.stderr
    assert "no topic '/pointz' in the bag: did you mean '/points'?" in r.stderr
    r = run_script("bag2map", "--fixed-frame", "mapp", str(cloud_bag), str(tmp_path / "x.map"))
    assert r.returncode == 1 and "did you mean 'map'?" in r.stderr, r.stderr
    assert r.stderr.count(str(cloud_bag)) == 1, r.stderr


def test_a_cloud_without_points_is_empty_whatever_its_layout_claims():
    # (the node fuzzer's finding) a point_step past NumPy's int limit once raised ValueError
    # from np.dtype even with no point to read
    fields = [SimpleNamespace(name=n, offset=o, datatype=7, count=1) for n, o in (("x", 0), ("y", 4), ("z", 8))]
    msg = SimpleNamespace(fields=fields, is_bigendian=False, width=0, height=1, point_step=2**32 - 1, row_step=0,
                          data=b"")
    assert vc.cloud_points_xyz(msg, lambda what: BagError("t", what)).shape == (0, 3)
