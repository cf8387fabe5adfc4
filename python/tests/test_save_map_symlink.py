"""A map target that is a symlink (the node's save_map_path, the tools' outputs): the commit's
rename replaces the link by a regular file and leaves what it pointed to as it was, a dangling
link too (docs/reliability.md): the same in every writer, since all go through one transaction."""

from __future__ import annotations

import os

import vasco_gpu as vg
from vasco_gpu import _core


def _a_map(intel):
    m = vg.Mapper(intel.params, backend="cpu_double")
    m.insert(intel.scans.select(0, 20))
    return m.finish()


def test_a_symlink_target_is_replaced_and_its_file_kept(intel, tmp_path):
    kept = tmp_path / "elsewhere.pgm"
    kept.write_bytes(b"not a map")
    link = tmp_path / "site.pgm"
    link.symlink_to(kept)
    dangling = tmp_path / "gone.map"
    dangling.symlink_to(tmp_path / "missing" / "nothing.map")
    _core._write_maps([str(link), str(dangling)], _a_map(intel), "trinary")
    assert not link.is_symlink() and link.read_bytes().startswith(b"P5")
    assert kept.read_bytes() == b"not a map"
    assert not dangling.is_symlink() and dangling.stat().st_size > 0
    assert not (tmp_path / "missing").exists()
    assert sorted(os.listdir(tmp_path)) == ["elsewhere.pgm", "gone.map", "site.pgm", "site.yaml"]
