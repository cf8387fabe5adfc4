"""A LiveMap saved and loaded back (vasco_gpu.ros.session_file), without ROS: every value
exact, the restored map the saved one's bit for bit, log2map's map of the file the same, bad
files refused naming the file and the line, a failed save leaving nothing behind."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

import vasco_gpu as vg
from vasco_gpu.ros import session_file
from vasco_gpu.ros.live_map import LiveMap
from vasco_gpu.ros.session_file import SessionFileError, load_session, save_session

ROOT = Path(__file__).resolve().parents[2]
INTEL = ROOT / "logs" / "intel.gfs.log.gz"
MOUNT = (0.1, -0.05, 0.02)


@pytest.fixture(scope="module")
def intel():
    return vg.load_log(INTEL)


def same_bits(a, b) -> bool:
    """Arrays equal bit for bit (any NaN equal to any NaN: a text file keeps no NaN payload)."""
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    same = a.view(f"u{a.itemsize}") == b.view(f"u{b.itemsize}")
    if a.dtype.kind == "f":
        same |= np.isnan(a) & np.isnan(b)
    return bool(same.all())


def same_map(a: vg.Map, b: vg.Map, file_resolution: bool = False) -> bool:
    """Cells, origin and resolution equal; file_resolution: a map file's resolution, which a
    .map file holds as a float32."""
    res = (lambda r: np.float32(r)) if file_resolution else float  # noqa: E731
    return (a.cells.shape == b.cells.shape and a.cells.tobytes() == b.cells.tobytes()
            and res(a.resolution) == res(b.resolution) and tuple(a.origin) == tuple(b.origin))


def mounts_of(n):
    """Every third scan without a mount (NaN), the others MOUNT."""
    return [None if i % 3 == 0 else MOUNT for i in range(n)]


def feed(live, scans, stamps, mounts):
    for s in range(len(scans)):
        live.add(int(stamps[s]), scans.poses[s], scans.ranges_of(s), float(scans.first_angle[s]),
                 float(scans.angle_step[s]), mounts[s])


def tool_map(path: Path, out_dir: Path) -> vg.Map:
    """log2map's map of a file (vg.map_logs writes the bytes log2map writes)."""
    [result] = vg.map_logs([path], out_dir, formats=("map",), backend="cpu_double")
    assert result.ok, result.error
    [out] = result.outputs
    return vg.read_map(out)


def expected_mounts(mounts):
    return np.array([(math.nan,) * 3 if m is None else m for m in mounts], dtype=np.float64)


def test_a_logs_scans_come_back_exactly_and_map_as_before(intel, tmp_path):
    scans = intel.scans.select(0, 400)
    stamps = 1_700_000_000_123_456_789 + np.arange(400, dtype=np.int64) * 100_000_001
    live = LiveMap(intel.params, backend="cpu_double")
    feed(live, scans, stamps, mounts_of(400))
    live.settle()  # fed one at a time, the grid grew: settled, it is a fresh map's
    path = tmp_path / "site.session.log"
    save_session(live, path)
    back = load_session(path)
    # against the inputs, not against what the LiveMap stored
    assert same_bits(back.stamps, stamps)
    assert same_bits(back.poses, scans.poses)
    assert same_bits(back.mounts, expected_mounts(mounts_of(400)))
    assert same_bits(back.first_angle, np.asarray(scans.first_angle, np.float64))
    assert same_bits(back.angle_step, np.asarray(scans.angle_step, np.float64))
    assert same_bits(back.beam_counts, np.asarray(scans.beam_counts, np.int64))
    assert same_bits(back.ranges, np.asarray(scans.ranges, np.float32))
    assert back.params.to_dict() == intel.params.to_dict()
    assert back.options == {"backend": "cpu_double", "cuda_mode": "float", "device": 0, "threads": 0,
                            "max_memory": live.max_memory}
    restored = LiveMap(vg.Params(), backend="cpu_double")
    restored.restore(back)
    want = live.finish()
    assert same_map(restored.finish(), want)
    fresh = vg.Mapper(intel.params, backend="cpu_double")
    fresh.insert(scans)
    assert same_map(fresh.finish(), want)  # the map the file must give, found without it
    assert same_map(tool_map(path, tmp_path / "maps"), want, file_resolution=True)
    assert list(restored.stamps) == stamps.tolist() and len(restored) == 400


def synthetic_scans(rng, n):
    """Scans as a node makes them from clouds: float64 angles that no float32 holds, stamps no
    double holds in seconds, mounts some unknown, ranges with NaN and inf."""
    counts = rng.integers(1, 60, n)
    first = rng.uniform(-math.pi, 0, n) + 1e-13
    step = rng.uniform(0.004, 0.05, n) / 3
    assert not np.any(first.astype(np.float32).astype(np.float64) == first)
    ranges = rng.uniform(0.2, 9.0, counts.sum()).astype(np.float32)
    ranges[rng.integers(0, len(ranges), 20)] = np.nan
    ranges[rng.integers(0, len(ranges), 20)] = np.inf
    poses = np.column_stack([rng.uniform(-3, 3, n), rng.uniform(-3, 3, n), rng.uniform(-math.pi, math.pi, n)])
    stamps = 1_754_000_000_000_000_001 + np.cumsum(rng.integers(1, 10**8, n))
    mounts = [None if i % 4 == 1 else tuple(rng.normal(0, 0.3, 3)) for i in range(n)]
    return stamps, poses, np.split(ranges, np.cumsum(counts)[:-1]), first, step, mounts


# Non-default values that a decimal text with few digits would not carry (0.05 / 3, 0.1 + 0.2).
ODD_PARAMS = dict(resolution=0.05 / 3, p_prior=0.5, p_occ=0.7, p_emp=0.35, range_sure=3.3, range_max=4.1 / 0.7,
                  wall_size=0.1 + 0.2, downsample=3, border=7)


@pytest.mark.parametrize("name", ["s.log", "s.log.gz"])
def test_synthetic_scans_and_odd_parameters_come_back_exactly(tmp_path, name):
    stamps, poses, ranges, first, step, mounts = synthetic_scans(np.random.default_rng(5), 80)
    params = vg.Params(**ODD_PARAMS)
    live = LiveMap(params, backend="cpu_threads", threads=2, cuda_mode="exact", max_memory=10**8)
    live.add_many(stamps, poses, ranges, first, step, mounts)
    path = tmp_path / name
    save_session(live, path)
    back = load_session(path)
    assert same_bits(back.stamps, stamps) and same_bits(back.poses, poses)
    assert same_bits(back.first_angle, first) and same_bits(back.angle_step, step)
    assert same_bits(back.mounts, expected_mounts(mounts))
    assert same_bits(back.ranges, np.concatenate(ranges)) and back.beam_counts.tolist() == [len(r) for r in ranges]
    assert back.params.to_dict() == {**vg.Params().to_dict(), **ODD_PARAMS}
    assert back.options == {"backend": "cpu_threads", "cuda_mode": "exact", "device": 0, "threads": 2,
                            "max_memory": 10**8}
    restored = LiveMap(vg.Params(), backend="cpu_double")
    restored.restore(back)
    assert restored.mapper.params.to_dict() == params.to_dict()
    assert same_map(restored.finish(), live.finish())
    # the PARAM lines carry the parameters to log2map: no option given
    assert same_map(tool_map(path, tmp_path / "maps"), live.finish(), file_resolution=True)


def test_after_a_path_the_saved_poses_are_the_moved_ones(intel, tmp_path):
    scans = intel.scans.select(0, 120)
    stamps = np.arange(120, dtype=np.int64) * 10**9
    live = LiveMap(intel.params, backend="cpu_double")
    feed(live, scans, stamps, [MOUNT] * 120)
    k = np.arange(20, 101, 4)
    base = scans.poses[k] + [0.3, -0.2, 0.05]
    assert live.repose(stamps[k], base, max_gap_ns=5 * 10**9)["moved"] == 81
    save_session(live, tmp_path / "moved.log")
    back = load_session(tmp_path / "moved.log")
    moved = live.mapper.poses
    assert not np.array_equal(moved, scans.poses)
    assert same_bits(back.poses, moved)
    assert np.array_equal(back.poses[:20], scans.poses[:20])  # before the Path: as they came
    restored = LiveMap(intel.params, backend="cpu_double")
    restored.restore(back)
    assert same_map(restored.finish(), live.finish())  # a repose renders afresh: no settle needed
    assert same_map(tool_map(tmp_path / "moved.log", tmp_path / "maps"), live.finish(),
                    file_resolution=True)


def test_an_empty_session_round_trips(tmp_path):
    live = LiveMap(vg.Params(p_occ=0.6), backend="cpu_double")
    save_session(live, tmp_path / "empty.log")
    back = load_session(tmp_path / "empty.log")
    assert len(back) == 0 and back.params.to_dict() == vg.Params(p_occ=0.6).to_dict()
    restored = LiveMap(vg.Params(), backend="cpu_double")
    restored.restore(back)
    assert len(restored) == 0 and restored.finish() is None and restored.mapper.params.p_occ == 0.6


# -- bad files ------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def good_text(intel, tmp_path_factory):
    """A saved session of 4 scans as text lines (1: comment, 2: VASCO_SESSION, 3-13: PARAM,
    then per scan ROBOTLASER1 and VASCO_SCAN from line 14, VASCO_END on line 22)."""
    live = LiveMap(intel.params, backend="cpu_double")
    feed(live, intel.scans.select(0, 4), [10, 20, 30, 40], mounts_of(4))
    path = tmp_path_factory.mktemp("good") / "good.log"
    save_session(live, path)
    lines = path.read_text().splitlines(keepends=True)
    assert lines[1].startswith("VASCO_SESSION 1 ") and lines[13].startswith("ROBOTLASER1 ")
    assert lines[14].startswith("VASCO_SCAN 0 10 180 nan nan nan") and lines[21] == "VASCO_END 4\n"
    return lines


def edited(lines, line_no, old, new):
    lines = list(lines)
    assert old in lines[line_no - 1], (old, lines[line_no - 1][:80])
    lines[line_no - 1] = lines[line_no - 1].replace(old, new, 1)
    return "".join(lines)


def bad_files(lines):
    """name -> (file text, the line the error must name, words it must say)."""
    text = "".join(lines)
    return {
        "cut inside the last line": (text[:-2], 22, "VASCO_END takes one number"),
        "cut inside the last scan line": (text[:text.index("VASCO_SCAN 3")] + "VASCO_SCAN 3 40 1", 21,
                                          "takes 6 fields"),
        "cut after a scan line": ("".join(lines[:19]), 19, "without its VASCO_END"),
        "cut inside a ROBOTLASER1 line": ("".join(lines[:15]) + lines[15][:200], 16, ""),
        "version 2": (edited(lines, 2, "VASCO_SESSION 1 ", "VASCO_SESSION 2 "), 2, "version 2"),
        "beam count of VASCO_SCAN": (edited(lines, 17, "VASCO_SCAN 1 20 180", "VASCO_SCAN 1 20 181"), 17,
                                     "181 beams"),
        "beam count of ROBOTLASER1": (edited(lines, 18, " 0.01 0 180 ", " 0.01 0 179 "), 18, ""),
        "a huge scan count": (edited(lines, 2, "scans 4 ", f"scans {10**30} "), 2, "the file has 4"),
        "a huge beam count": (edited(lines, 15, "VASCO_SCAN 0 10 180", f"VASCO_SCAN 0 10 {10**30}"), 15, "beams"),
        "a stamp past 64 bits": (edited(lines, 15, "VASCO_SCAN 0 10 ", f"VASCO_SCAN 0 {2**63} "), 15, "64 bits"),
        "scans out of order": (edited(lines, 17, "VASCO_SCAN 1 ", "VASCO_SCAN 2 "), 17, "scan 1's"),
        "a missing VASCO_SCAN": ("".join(lines[:16] + lines[17:]), 17, "expected scan 1's VASCO_SCAN"),
        "a mount that is no number": (edited(lines, 17, "0.1 -0.05", "0.1 -0,05"), 17, "not a number"),
        "a missing PARAM": ("".join(lines[:4] + lines[5:]), 2, "no PARAM line for vasco_p_occ"),
        "a PARAM twice": ("".join(lines[:5] + lines[4:]), 6, "first on line 5"),
        "a PARAM out of range": (edited(lines, 5, "vasco_p_occ 0.55", "vasco_p_occ 1.5"), 5, "vasco_p_occ"),
        "a whole number with a point": (edited(lines, 10, "vasco_downsample 4 ", "vasco_downsample 4.0 "), 10,
                                        "not a whole number"),
        "an option missing": (edited(lines, 2, " threads 0", ""), 2, "missing: ['threads']"),
        "a line of another kind": ("".join(lines[:13] + ["ODOM 0 0 0 0 0 0 1.0 h 1.0\n"] + lines[13:]), 14,
                                   "a session file holds"),
        "a line after the end": (text + "VASCO_SCAN 4 50 1 0 0 0\n", 23, "after VASCO_END"),
        "the end's count": (edited(lines, 22, "VASCO_END 4", "VASCO_END 5"), 22, "VASCO_END says 5"),
    }


CASES = ["cut inside the last line", "cut inside the last scan line", "cut after a scan line",
         "cut inside a ROBOTLASER1 line", "version 2", "beam count of VASCO_SCAN", "beam count of ROBOTLASER1",
         "a huge scan count", "a huge beam count", "a stamp past 64 bits", "scans out of order",
         "a missing VASCO_SCAN", "a mount that is no number", "a missing PARAM", "a PARAM twice",
         "a PARAM out of range", "a whole number with a point", "an option missing", "a line of another kind",
         "a line after the end", "the end's count"]


@pytest.mark.parametrize("case", CASES)
def test_a_bad_file_is_refused_naming_the_file_and_the_line(good_text, tmp_path, case):
    text, line, words = bad_files(good_text)[case]
    path = tmp_path / "bad.log"
    path.write_text(text)
    with pytest.raises(vg.Error) as e:
        load_session(path)
    assert isinstance(e.value, vg.FileError)
    assert e.value.file == str(path) and e.value.line == line, str(e.value)
    assert str(e.value).startswith(f"{path}:{line}: ") and words in str(e.value)


def test_the_cases_are_every_bad_file(good_text):
    assert sorted(CASES) == sorted(bad_files(good_text))


def test_a_file_of_another_kind_is_refused(tmp_path, good_text):
    binary = tmp_path / "bag.mcap"
    binary.write_bytes(b"\x89MCAP0\r\n" + bytes(range(256)) * 64)
    empty = tmp_path / "empty.log"
    empty.write_text("")
    for path in (INTEL, binary, empty):
        with pytest.raises(SessionFileError, match="is not a vasco_gpu session file") as e:
            load_session(path)
        assert e.value.file == str(path) and str(e.value).startswith(f"{path}: ")
    gz = tmp_path / "cut.log.gz"
    save_session(_small_live(), gz)
    gz.write_bytes(gz.read_bytes()[:-40])  # a gzip stream cut short
    with pytest.raises(SessionFileError, match="cannot be read") as e:
        load_session(gz)
    assert e.value.file == str(gz)
    with pytest.raises(SessionFileError, match="cannot be read") as e:
        load_session(tmp_path / "missing.log")


def _small_live():
    stamps, poses, ranges, first, step, mounts = synthetic_scans(np.random.default_rng(1), 30)
    live = LiveMap(vg.Params(), backend="cpu_double")
    live.add_many(stamps, poses, ranges, first, step, mounts)
    return live


# -- a failed save ------------------------------------------------------------------------------------
def test_a_save_that_fails_while_writing_keeps_the_old_file_and_leaves_no_temporary(tmp_path, monkeypatch):
    live = _small_live()
    path = tmp_path / "site.log"
    path.write_text("the previous session\n")
    calls = []
    real = session_file._robotlaser_line

    def failing(saved, s, ranges, robot):
        calls.append(s)
        if s == 20:
            raise OSError(28, "No space left on device")
        return real(saved, s, ranges, robot)

    monkeypatch.setattr(session_file, "_robotlaser_line", failing)
    with pytest.raises(SessionFileError, match="cannot be written: No space left on device") as e:
        save_session(live, path)
    assert isinstance(e.value, vg.Error) and e.value.file == str(path)
    assert calls[-1] == 20  # it failed half way through
    assert path.read_text() == "the previous session\n"
    assert sorted(os.listdir(tmp_path)) == ["site.log"]


def test_a_save_where_no_file_can_be_made_leaves_nothing(tmp_path):
    live = _small_live()
    not_a_dir = tmp_path / "plain"
    not_a_dir.write_text("")
    for path in (tmp_path / "missing" / "s.log", not_a_dir / "s.log", tmp_path):
        with pytest.raises(SessionFileError, match="cannot be written") as e:
            save_session(live, path)
        assert isinstance(e.value, vg.Error) and e.value.file == str(path)
    assert sorted(os.listdir(tmp_path)) == ["plain"]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a read-only directory")
def test_a_save_into_a_read_only_directory_leaves_the_old_file(tmp_path):
    live = _small_live()
    path = tmp_path / "site.log"
    path.write_text("the previous session\n")
    tmp_path.chmod(0o500)
    try:
        with pytest.raises(SessionFileError, match="cannot be written"):
            save_session(live, path)
    finally:
        tmp_path.chmod(0o700)
    assert path.read_text() == "the previous session\n" and os.listdir(tmp_path) == ["site.log"]


def test_a_pose_a_log_cannot_hold_is_refused_before_any_file_is_touched(tmp_path):
    live = _small_live()
    live.poses[3 * 7] = math.inf  # scan 7's x, as no Mapper would take it: the store's copy
    path = tmp_path / "site.log"
    with pytest.raises(SessionFileError, match="scan 7 .* not finite"):
        save_session(live, path)
    assert os.listdir(tmp_path) == []


def test_an_option_that_is_not_one_word_is_refused_before_any_file_is_touched(tmp_path):
    live = _small_live()
    live.options["cuda_mode"] = "exact mode"
    with pytest.raises(SessionFileError, match="cuda_mode = 'exact mode' cannot be saved"):
        save_session(live, tmp_path / "site.log")
    del live.options["cuda_mode"]
    with pytest.raises(SessionFileError, match="cuda_mode = '' cannot be saved"):
        save_session(live, tmp_path / "site.log")
    assert os.listdir(tmp_path) == []
