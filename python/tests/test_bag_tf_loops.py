"""A bag whose /tf carries, in the middle of the recording, a self transform (``map -> map``,
which tf2 drops) or a link that would close a cycle (``base_link -> map`` while ``map ->
base_link`` comes on): bag2map, read_for_engine and load_bag leave the link out with one
warning and map the bag as the same bag without it, bit for bit."""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")

import vasco_gpu as vg  # noqa: E402
import vasco_gpu.bags as vb  # noqa: E402
from vasco_gpu.bags.load import read_for_engine  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bag_maker as bm  # noqa: E402

T0 = 1000.0
N = 12
RANGES = np.linspace(2.0, 6.0, 90)


def robot_bag(tmp_path, name, extra=(), fmt="mcap"):
    """Scans in 'laser' every 0.1 s, base_link -> laser on /tf_static, map -> base_link on /tf
    at each scan; extra: (t, parent, child, static) links added, each in a /tf message of its own."""
    rec = bm.Recording(fmt)
    rec.tf(T0, "base_link", "laser", 0.1, 0.0, 0.0, static=True)
    for k in range(N):
        t = T0 + 0.1 * k
        rec.scan("/scan", t, "laser", RANGES, -1.5, 3.0 / 89, 0.1, 20.0)
        rec.tf(t, "map", "base_link", 0.2 * k, 0.05 * k, 0.03 * k)
    for t, parent, child, static in extra:
        rec.tf(t, parent, child, 0.5, -0.25, 0.1, static=static)
    return rec.write(bm.bag_path(tmp_path, fmt, name))


def bag2map(*args):
    """bag2map as installed beside this interpreter, else its entry point."""
    exe = Path(sys.executable).parent / "bag2map"
    cmd = [str(exe)] if exe.exists() else [
        sys.executable, "-c", "import sys; from vasco_gpu.bags.cli import bag2map_main; sys.exit(bag2map_main())"]
    return subprocess.run(cmd + [str(a) for a in args], capture_output=True, text=True, timeout=300)


MIDDLE = T0 + 0.55  # between the sixth and the seventh scan
BAD_LINKS = {
    "self": ([(MIDDLE, "map", "map", False)], "tf map -> map at stamp 1000.550000000 on /tf links a frame to itself"),
    "reversed": ([(MIDDLE, "base_link", "map", False)],
                 "tf base_link -> map at stamp 1000.550000000 on /tf would close a cycle: map -> base_link"),
    "loop": ([(MIDDLE, "laser", "map", True)],
             "tf laser -> map at stamp 1000.550000000 on /tf_static would close a cycle: map -> base_link -> laser"),
}


@pytest.mark.parametrize("case", sorted(BAD_LINKS))
def test_bag2map_maps_past_a_bad_link_as_without_it(tmp_path, case):
    extra, text = BAD_LINKS[case]
    clean, bad = robot_bag(tmp_path, "clean"), robot_bag(tmp_path, "bad", extra)
    r = bag2map("--backend", "cpu_double", clean, tmp_path / "clean.map")
    assert r.returncode == 0, r.stderr
    assert "warning" not in r.stderr
    r = bag2map("--backend", "cpu_double", bad, tmp_path / "bad.map")
    assert r.returncode == 0, r.stderr
    warned = [line for line in r.stderr.splitlines() if "bag2map: warning:" in line]
    assert len(warned) == 1 and text in warned[0] and str(bad) in warned[0], r.stderr
    assert vg.read_map(tmp_path / "bad.map").sha256() == vg.read_map(tmp_path / "clean.map").sha256()


def test_the_reader_counts_the_links_it_left_out(tmp_path):
    # two self links and two reversed links: one warning of each kind, counting the rest
    extra = [(T0 + 0.25, "map", "map", False), (T0 + 0.35, "base_link", "map", False),
             (T0 + 0.45, "/map", "map", False), (T0 + 0.65, "base_link", "map", False)]
    clean, bad = robot_bag(tmp_path, "clean"), robot_bag(tmp_path, "bad", extra)
    d, want = read_for_engine(bad), read_for_engine(clean)
    assert len(d["warnings"]) == 2, d["warnings"]
    self_text, loop_text = sorted(d["warnings"], key=lambda w: "itself" not in w)
    assert "tf map -> map at stamp 1000.250000000" in self_text and "(1 more self links left out)" in self_text
    assert "tf base_link -> map at stamp 1000.350000000" in loop_text and "(1 more cycles left out)" in loop_text
    np.testing.assert_array_equal(d["bag"].poses, want["bag"].poses)
    np.testing.assert_array_equal(d["stamps"], want["stamps"])


def test_load_bag_warns_once_and_maps_as_without(tmp_path):
    clean, bad = robot_bag(tmp_path, "clean"), robot_bag(tmp_path, "bad", BAD_LINKS["reversed"][0])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        log = vg.load_bag(bad)
    texts = [str(w.message) for w in caught if issubclass(w.category, vb.BagWarning)]
    assert len(texts) == 1 and "would close a cycle" in texts[0]
    np.testing.assert_array_equal(log.scans.poses, vg.load_bag(clean).scans.poses)


def test_a_second_parent_still_stops_the_bag(tmp_path):
    # unlike a self or loop link, two parents leave which pose is right open: refused as before
    bad = robot_bag(tmp_path, "two", [(MIDDLE, "odom", "base_link", False)])
    r = bag2map(bad, tmp_path / "x.map")
    assert r.returncode == 1 and "frame 'base_link' has two parents" in r.stderr
    assert not (tmp_path / "x.map").exists()
