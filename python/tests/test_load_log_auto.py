"""Sessions placed by alignment: load_log(add=[(path, "auto")]) and bag2map INPUT --add INPUT@auto.
intel is split into two sessions sharing part of the route, the second written in a frame
moved by a transform chosen here; the alignment must give it back, and the map must be that of
the same sessions with the found transform given."""

from __future__ import annotations

import gzip
import json
import math

import pytest

import vasco_gpu as vg
from conftest import ROOT
from test_carmen2bag import run_script

INTEL = ROOT / "logs" / "intel.gfs.log.gz"
FR079 = ROOT / "logs" / "fr079-complete.gfs.log.gz"
TRUTH = (3.5, -7.25, 2.0)


def flaser_lines(path):
    with gzip.open(path, "rt") as f:
        return [line.split() for line in f if line.startswith("FLASER ")]


def moved(tokens, t):
    """A FLASER line's laser and robot poses taken by t = (x, y, theta)."""
    tokens = list(tokens)
    at = 2 + int(tokens[1])
    c, s = math.cos(t[2]), math.sin(t[2])
    for p in (at, at + 3):
        x, y, th = (float(v) for v in tokens[p:p + 3])
        tokens[p:p + 3] = ["%.17g" % (t[0] + c * x - s * y), "%.17g" % (t[1] + s * x + c * y), "%.17g" % (th + t[2])]
    return tokens


def inverse(t):
    c, s = math.cos(t[2]), math.sin(t[2])
    return (-(c * t[0] + s * t[1]), -(-s * t[0] + c * t[1]), -t[2])


def write_log(path, lines, frame=(0.0, 0.0, 0.0)):
    path.write_text("".join(" ".join(moved(t, frame)) + "\n" for t in lines))
    return path


@pytest.fixture(scope="module")
def sessions(tmp_path_factory):
    """intel's scans [0, 0.65 n) and [0.35 n, n), the second recorded in a frame moved by TRUTH^-1."""
    d = tmp_path_factory.mktemp("sessions")
    lines = flaser_lines(INTEL)
    n = len(lines)
    return (write_log(d / "first.log", lines[:n * 65 // 100]),
            write_log(d / "second.log", lines[n * 35 // 100:], inverse(TRUTH)))


def angle_error(a, b):
    return abs(math.remainder(a - b, 2 * math.pi))


def finished_sha(log):
    m = vg.Mapper(log.params, "cpu_double")
    m.insert(log.scans)
    return m.finish().sha256()


def test_load_log_finds_the_transform(sessions):
    first, second = sessions
    log = vg.load_log(first, add=[(second, "auto")])
    (added,) = log.added_sessions
    assert added["aligned"] == "auto" and added["input"] == str(second)
    x, y, th = added["transform"]
    assert abs(x - TRUTH[0]) <= 0.1 and abs(y - TRUTH[1]) <= 0.1
    assert angle_error(th, TRUTH[2]) <= math.radians(0.5)
    assert added["score"] > added["second_score"] and 0 < added["overlap"] <= 1
    given = vg.load_log(first, add=[(second, (x, y, th))])
    assert given.added_sessions[0]["aligned"] == "given" and given.added_sessions[0]["score"] is None
    assert finished_sha(log) == finished_sha(given)


def test_a_hint_near_the_truth_finds_it(sessions):
    first, second = sessions
    guess = (TRUTH[0] + 0.5, TRUTH[1] - 0.5, TRUTH[2] + 0.05)
    log = vg.load_log(first, add=[(second, ("auto", guess + (1.0, 0.1)))])
    x, y, th = log.added_sessions[0]["transform"]
    assert abs(x - TRUTH[0]) <= 0.1 and abs(y - TRUTH[1]) <= 0.1


def test_bad_session_forms_are_usage_errors(sessions):
    first, second = sessions
    for what in ("automatic", ("auto", (1.0, 2.0)), ("auto", (1.0, 2.0, 3.0, -1.0, 0.1))):
        with pytest.raises(vg.UsageError):
            vg.load_log(first, add=[(second, what)])


@pytest.mark.skipif(not FR079.is_file(), reason="fr079 is not in logs/")
def test_another_building_is_refused_naming_the_log(sessions, tmp_path):
    first, _ = sessions
    lines = flaser_lines(FR079)
    other = write_log(tmp_path / "fr079.log", lines[len(lines) // 2:])
    with pytest.raises(vg.FileError, match="not placed by alignment") as e:
        vg.load_log(first, add=[(other, "auto")])
    assert e.value.file == str(other)


def test_bag2map_aligns_an_added_bag(sessions, tmp_path):
    first, second = sessions
    for log, bag in ((first, tmp_path / "first.mcap"), (second, tmp_path / "second.mcap")):
        r = run_script("carmen2bag", "-q", log, bag)
        assert r.returncode == 0, r.stderr
    r = run_script("bag2map", "--json", tmp_path / "first.mcap", "--add", f"{tmp_path / 'second.mcap'}@auto",
                   tmp_path / "auto.pgm")
    assert r.returncode == 0, r.stderr
    added = json.loads(r.stdout)["added_sessions"]
    x, y, th = added[0]["transform"]
    assert added[0]["aligned"] == "auto"
    assert abs(x - TRUTH[0]) <= 0.1 and abs(y - TRUTH[1]) <= 0.1
    assert angle_error(th, TRUTH[2]) <= math.radians(0.5)
    assert "second.mcap: aligned (@auto): transform" in r.stderr
