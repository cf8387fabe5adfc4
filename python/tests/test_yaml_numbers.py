"""The map_server YAML the tools write, read by PyYAML (YAML 1.1): every number a float equal to
the double written. YAML 1.1 takes "-1e+02", "1e+01" or "10" as a string or an int, not a float;
a gmapping map with origin [-100, -100, 0] came back as strings after a round trip.

Expected values come from the YAML given as input (PyYAML's own reading of it), not from the
writer. Two routes: the package (vasco_gpu.read_map / write_map) and the mapconvert tool.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from conftest import ROOT

yaml = pytest.importorskip("yaml", reason="PyYAML is not installed: no YAML 1.1 reader to check against")

# A 2 x 1 map_server image: one occupied cell, one free.
PGM = b"P5\n2 1\n255\n" + bytes([0, 254])
GMAPPING = "image: g.pgm\nresolution: 10\norigin: [-100, -100, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
# An origin that needs 17 significant digits, and one past a float's 7 (a UTM northing).
LONG = "image: g.pgm\nresolution: 0.05\norigin: [-13.499734000000002, 5400000.123456789, 0.0]\n"
NUMBERS = ("resolution", "occupied_thresh", "free_thresh")


def given(path: Path, text: str) -> dict:
    """Writes the image and its YAML; returns the YAML as PyYAML reads it, as numbers."""
    path.with_name("g.pgm").write_bytes(PGM)
    path.write_text(text)
    return {k: (v if k == "origin" else float(v)) for k, v in yaml.safe_load(text).items() if k != "image"}


def assert_floats_equal(written: Path, expected: dict) -> None:
    text = written.read_text()
    back = yaml.safe_load(text)
    for key in NUMBERS:
        if key in expected:
            assert type(back[key]) is float, f"{key}: {back[key]!r} in\n{text}"
            assert back[key] == expected[key], text
    assert all(type(v) is float for v in back["origin"]), text
    assert back["origin"] == [float(v) for v in expected["origin"]], text


@pytest.mark.parametrize("text", [GMAPPING, LONG], ids=["gmapping", "long_origin"])
def test_package_writes_yaml_floats(tmp_path, text):
    vg = pytest.importorskip("vasco_gpu")
    expected = given(tmp_path / "g.yaml", text)
    vg.write_map(tmp_path / "out.pgm", vg.read_map(tmp_path / "g.yaml"))
    written_as_given = {k: v for k, v in expected.items() if not k.endswith("_thresh")}  # write_map's own thresholds
    assert_floats_equal(tmp_path / "out.yaml", written_as_given)


def built_mapconvert() -> Path | None:
    """mapconvert of a build of this checkout (VASCO_BIN, build/bin, PATH), or None."""
    for d in (os.environ.get("VASCO_BIN"), ROOT / "build" / "bin"):
        if d and (Path(d) / "mapconvert").is_file():
            return Path(d) / "mapconvert"
    found = shutil.which("mapconvert")
    return Path(found) if found else None


@pytest.mark.parametrize("text", [GMAPPING, LONG], ids=["gmapping", "long_origin"])
def test_mapconvert_round_trip_keeps_floats(tmp_path, text):
    mapconvert = built_mapconvert()
    if mapconvert is None:
        pytest.skip("no mapconvert built (set VASCO_BIN)")
    expected = given(tmp_path / "g.yaml", text)
    for src, dst in (("g.yaml", "g.map"), ("g.map", "back.pgm")):
        run = subprocess.run([str(mapconvert), str(tmp_path / src), str(tmp_path / dst)],
                             capture_output=True, text=True, timeout=120)
        assert run.returncode == 0, run.stderr
    assert_floats_equal(tmp_path / "back.yaml", expected)
