"""load_log's pose and session keywords: poses from a SLAM back end's file, several logs into
one grid. The expected maps are those of logs written here with the poses in them."""

from __future__ import annotations

import gzip
import math
import subprocess
import sys

import numpy as np
import pytest

import vasco_gpu as vg
from conftest import ROOT

INTEL = ROOT / "logs" / "intel.gfs.log.gz"
FR101 = ROOT / "logs" / "fr101.carmen.log.gz"


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
        vg.load_log(INTEL, poses=tum, pose_tolerance=0, pose_max_gap=0.01)
    assert "traj.txt" in str(e.value) and "scan 1" in str(e.value) and "--pose-max-gap 0.01" in str(e.value)
    log = vg.load_log(INTEL, poses=tum, pose_tolerance=0, pose_max_gap=0.01, skip_unposed=True)
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
    with pytest.raises(vg.UsageError):
        vg.load_log(INTEL, pose_max_gap=2.0)  # without poses=
    with pytest.raises(vg.UsageError, match="pose_max_gap"):
        vg.load_log(INTEL, poses=tmp_path / "x.txt", pose_max_gap=-1.0)
    with pytest.raises(vg.UsageError, match="pose_max_gap"):
        vg.load_log(INTEL, poses=tmp_path / "x.txt", pose_max_gap=float("nan"))
    with pytest.raises(TypeError):
        vg.load_log(INTEL, pose_file="x.g2o")
    with pytest.raises(vg.UsageError):
        vg.load_log(INTEL, poses=tmp_path / "x.g2o", pose_frame="camera")
    with pytest.raises(vg.UsageError):
        vg.load_log(INTEL, transform=(0, 0, float("nan")))
    with pytest.raises(vg.FileError):
        vg.load_log(INTEL, poses=tmp_path / "missing.g2o")


# ---------------------------------------------------------------------------------------------
# Keyframes of a SLAM back end: a pose every 5th scan of fr101 (its scans are 0.2 to 0.85 s
# apart, so the keyframes about a second), in a TUM file.


@pytest.fixture(scope="module")
def fr101():
    return vg.load_log(FR101)


def keyframes(log, every=5):
    """(scan indices, stamps, poses (k, 3)) of the keyframes: every 5th scan and the last, moved a
    little as an optimizer might, headings wrapped into [-pi, pi] as a TUM yaw reads back."""
    idx = np.unique(np.append(np.arange(0, len(log), every), len(log) - 1))
    p = log.poses[idx].copy()
    a = idx.astype(float)
    p[:, 0] += 0.05 * np.sin(a)
    p[:, 1] -= 0.03 * np.cos(a)
    p[:, 2] = np.remainder(p[:, 2] + 0.01 * np.sin(0.5 * a) + math.pi, 2 * math.pi) - math.pi
    return idx, log.stamps[idx], p


def write_tum(path, stamps, poses):
    path.write_text("".join(f"{t!r} {x!r} {y!r} 0 0 0 {math.sin(th / 2)!r} {math.cos(th / 2)!r}\n"
                            for t, (x, y, th) in zip(stamps.tolist(), poses.tolist())))
    return path


def interpolated(stamps, key_stamps, key_poses):
    """Each stamp's pose between the keyframes around it, written out: u = (t - t0) / (t1 - t0),
    x and y linear, theta by the shorter arc; a keyframe's own stamp takes its pose."""
    i1 = np.clip(np.searchsorted(key_stamps, stamps), 1, len(key_stamps) - 1)
    i0 = i1 - 1
    t0, t1 = key_stamps[i0], key_stamps[i1]
    u = (stamps - t0) / (t1 - t0)
    p0, p1 = key_poses[i0], key_poses[i1]
    d = np.remainder(p1[:, 2] - p0[:, 2] + math.pi, 2 * math.pi) - math.pi
    out = np.stack([p0[:, 0] + u * (p1[:, 0] - p0[:, 0]), p0[:, 1] + u * (p1[:, 1] - p0[:, 1]), p0[:, 2] + u * d], 1)
    exact = np.isin(stamps, key_stamps)
    out[exact] = key_poses[np.searchsorted(key_stamps, stamps[exact])]
    return out


def test_keyframes_a_second_apart_interpolate_with_the_defaults(tmp_path, fr101):
    idx, kt, kp = keyframes(fr101)
    assert np.diff(kt).max() < 5 and np.median(np.diff(kt)) > 1  # about a second: well over the 0.1 s tolerance
    tum = write_tum(tmp_path / "keyframes.txt", kt, kp)
    log = vg.load_log(FR101, poses=tum)
    assert log.posed_from_file == len(fr101) and log.unposed_skipped == 0
    want = interpolated(fr101.stamps, kt, kp)
    d = log.poses - want
    d[:, 2] = np.remainder(d[:, 2] + math.pi, 2 * math.pi) - math.pi
    assert np.abs(d).max() < 1e-9  # the keyframes' yaws come back from the quaternions within ulps
    assert np.abs(log.poses - fr101.poses).max() > 0.01  # the file's poses, not the log's


def test_a_gap_over_pose_max_gap_names_the_distances(tmp_path, fr101):
    idx, kt, kp = keyframes(fr101)
    tum = write_tum(tmp_path / "keyframes.txt", kt, kp)
    with pytest.raises(vg.FileError) as e:
        vg.load_log(FR101, poses=tum, pose_max_gap=0.4)
    t, t0, t1 = float(fr101.stamps[1]), float(kt[0]), float(kt[1])
    gap, nearer = t1 - t0, min(t - t0, t1 - t)
    assert (f"(scan 1, stamp {t!r}): the poses around it ({t0!r} and {t1!r}) are {gap:.6g} s apart, "
            f"more than --pose-max-gap 0.4, and the nearer is {nearer:.6g} s away, more than --pose-tolerance 0.1"
            in str(e.value)), str(e.value)
    assert np.diff(kt).min() > 0.4  # every gap over the limit: only the keyframes' own scans have a pose
    log = vg.load_log(FR101, poses=tum, pose_max_gap=0.4, skip_unposed=True)
    assert len(log) == len(idx) and log.unposed_skipped == len(fr101) - len(idx)
    assert np.array_equal(log.stamps, kt)


def test_a_stamp_outside_the_trajectory_takes_its_end_within_pose_tolerance(tmp_path, fr101):
    idx, kt, kp = keyframes(fr101)
    cut = write_tum(tmp_path / "cut.txt", kt[1:-1], kp[1:-1])  # without the first and last keyframes
    stamps = fr101.stamps
    before = float(kt[1] - stamps[0])
    with pytest.raises(vg.FileError) as e:
        vg.load_log(FR101, poses=cut)
    assert f"(scan 0, stamp {float(stamps[0])!r}): {before:.6g} s before the first pose ({float(kt[1])!r}), more " \
           "than --pose-tolerance 0.1" in str(e.value), str(e.value)
    after = float(stamps[-1] - kt[-2])
    log = vg.load_log(FR101, poses=cut, pose_tolerance=max(before, after))
    assert log.posed_from_file == len(fr101)
    assert np.array_equal(log.poses[: idx[1]], np.repeat(log.poses[idx[1]][None], idx[1], 0))  # the end pose, unchanged
    assert np.array_equal(log.poses[idx[-2]:], np.repeat(log.poses[idx[-2]][None], len(fr101) - idx[-2], 0))
    tol = 0.3
    log = vg.load_log(FR101, poses=cut, pose_tolerance=tol, skip_unposed=True)
    outside = (kt[1] - stamps > tol) | (stamps - kt[-2] > tol)
    assert 0 < log.unposed_skipped == np.count_nonzero(outside) < len(idx)
    log = vg.load_log(FR101, poses=cut, pose_tolerance=before, skip_unposed=True)  # inclusive: scan 0 is in
    assert log.unposed_skipped == np.count_nonzero(stamps - kt[-2] > before)


def test_bag2map_takes_pose_max_gap(tmp_path, fr101):
    pytest.importorskip("rosbags")
    from bag_maker import write_bag

    n = 60
    sc = fr101.scans
    bag = write_bag(tmp_path / "fr101.bag", "rosbag1", fr101.stamps[:n].tolist(), [sc.ranges_of(i) for i in range(n)],
                    sc.first_angle[0], sc.angle_step[0], 0.0, 81.9)
    sub = vg.load_log(FR101, overrides={"num_scans": n})
    idx, kt, kp = keyframes(sub)
    tum = write_tum(tmp_path / "keyframes.txt", kt, kp)

    def bag2map(*args):
        code = "import sys; from vasco_gpu.bags.cli import bag2map_main; sys.exit(bag2map_main())"
        return subprocess.run([sys.executable, "-c", code, *map(str, args)], capture_output=True, text=True,
                              timeout=300)

    r = bag2map("--backend", "cpu_threads", "--poses", tum, "--pose-max-gap", "0.5", bag, tmp_path / "x.map")
    assert r.returncode == 1, r.stderr
    assert "keyframes.txt: no pose for" in r.stderr and "more than --pose-max-gap 0.5" in r.stderr, r.stderr
    assert not (tmp_path / "x.map").exists()
    r = bag2map("--backend", "cpu_threads", "--json", "--poses", tum, bag, tmp_path / "m.map")
    assert r.returncode == 0, r.stderr
    assert f'"posed_from_file":{n}' in r.stdout, r.stdout
