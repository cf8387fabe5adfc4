"""load_log's pose and session keywords: poses from a SLAM back end's file, several logs into
one grid. The expected maps are those of logs written here with the poses in them."""

from __future__ import annotations

import gzip
import math

import numpy as np
import pytest

import vasco_gpu as vg
from conftest import ROOT

INTEL = ROOT / "logs" / "intel.gfs.log.gz"


def flaser_lines():
    with gzip.open(INTEL, "rt") as f:
        return [line.split() for line in f if line.startswith("FLASER ")]


def write_log(path, lines):
    path.write_text("".join(" ".join(t) + "\n" for t in lines))
    return path


def with_poses(lines, poses):
    out = []
    for t, (x, y, th) in zip(lines, poses):
        t = list(t)
        at = 2 + int(t[1])
        t[at:at + 3] = ["%.17g" % x, "%.17g" % y, "%.17g" % th]
        out.append(t)
    return out


def finished(log):
    m = vg.Mapper(log.params, backend="cpu_double")
    m.insert(log.scans)
    return m.finish()


@pytest.fixture(scope="module")
def moved():
    """intel's poses as a back end might return them: moved a little, more towards the end."""
    p = vg.load_log(INTEL).poses
    u = np.arange(len(p)) / len(p)
    p[:, 0] += 0.05 * u * np.sin(0.1 * np.arange(len(p)))
    p[:, 1] -= 0.04 * u
    p[:, 2] += 0.01 * u
    return p


def test_g2o_poses_give_the_map_of_a_log_carrying_them(tmp_path, moved):
    g2o = tmp_path / "opt.g2o"
    g2o.write_text("".join(f"VERTEX_SE2 {i} {x!r} {y!r} {t!r}\n" for i, (x, y, t) in enumerate(moved.tolist())))
    log = vg.load_log(INTEL, poses=g2o)
    assert log.posed_from_file == len(moved) and np.array_equal(log.poses, moved)
    want = vg.load_log(write_log(tmp_path / "moved.log", with_poses(flaser_lines(), moved)))
    assert finished(log).sha256() == finished(want).sha256()


def test_tum_poses_by_stamp_and_skipping(tmp_path, moved):
    stamps = vg.load_log(INTEL).stamps
    tum = tmp_path / "traj.txt"
    rows = [f"{t!r} {x!r} {y!r} 0 0 0 {math.sin(th / 2)!r} {math.cos(th / 2)!r}\n"
            for t, (x, y, th) in zip(stamps.tolist(), moved.tolist())]
    tum.write_text("".join(rows[::2]))  # every other scan only
    with pytest.raises(vg.FileError) as e:
        vg.load_log(INTEL, poses=tum, pose_tolerance=0.01)
    assert "traj.txt" in str(e.value) and "scan 1" in str(e.value)
    log = vg.load_log(INTEL, poses=tum, pose_tolerance=0.01, skip_unposed=True)
    assert len(log) == (len(moved) + 1) // 2 and log.unposed_skipped == len(moved) // 2
    # The yaw came back from the quaternion within a few ulps, wrapped into (-pi, pi].
    d = log.poses - moved[::2]
    d[:, 2] = (d[:, 2] + math.pi) % (2 * math.pi) - math.pi
    assert np.abs(d).max() < 1e-14


def test_two_sessions_with_a_transform(tmp_path):
    lines = flaser_lines()
    a = write_log(tmp_path / "a.log", lines[:400])
    b = write_log(tmp_path / "b.log", lines[400:])
    whole = vg.load_log(INTEL)
    both = vg.load_log(a, add=[b])
    assert len(both) == len(whole)
    assert finished(both).sha256() == finished(whole).sha256()
    # b in a frame 3 m east, 1 m south, turned by 0.25 rad: the shared-frame log holds
    # compose((3, -1, 0.25), pose) for b's scans.
    tx, ty, ang = 3.0, -1.0, 0.25
    p = whole.poses
    shared = p.copy()
    c, s = math.cos(ang), math.sin(ang)
    for i in range(400, len(p)):
        x, y, th = p[i]
        shared[i] = (tx + c * x - s * y, ty + s * x + c * y, th + ang)
    want = vg.load_log(write_log(tmp_path / "shared.log", with_poses(lines, shared)))
    got = vg.load_log(a, add=[(b, (tx, ty, ang))])
    assert np.array_equal(got.poses, want.poses)
    assert finished(got).sha256() == finished(want).sha256()


def test_pose_keywords_are_checked(tmp_path):
    with pytest.raises(vg.UsageError):
        vg.load_log(INTEL, skip_unposed=True)  # without poses=
    with pytest.raises(TypeError):
        vg.load_log(INTEL, pose_file="x.g2o")
    with pytest.raises(vg.UsageError):
        vg.load_log(INTEL, poses=tmp_path / "x.g2o", pose_frame="camera")
    with pytest.raises(vg.UsageError):
        vg.load_log(INTEL, transform=(0, 0, float("nan")))
    with pytest.raises(vg.FileError):
        vg.load_log(INTEL, poses=tmp_path / "missing.g2o")
