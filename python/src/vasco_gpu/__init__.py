"""vasco_gpu: CARMEN-compatible occupancy-grid mapping with known poses, from NumPy.

The mapping session of the C++ library (``vasco::Mapper``) with NumPy arrays in and out::

    import vasco_gpu as vg

    log = vg.load_log("logs/fr079-complete.gfs.log.gz")      # scans, params, frame
    mapper = vg.Mapper(log.params, backend="cuda")            # or cpu_double, cpu_threads, cpu_float
    mapper.insert(log.scans)
    poses = log.poses                                         # (n, 3) float64: x, y, theta
    poses[len(poses) // 2:, 2] += 0.01                        # ... a back end moves the poses
    mapper.render(poses)                                      # the whole map, recomputed
    m = mapper.finish()                                       # Map: .cells (size_x, size_y), x-major
    vg.write_map("fr079.png", m)

Arrays: ``Map.cells`` is a float32 view of shape (size_x, size_y) indexed ``cells[x, y]`` as
CARMEN stores maps (-1 unknown, else the occupancy probability); ``Map.image`` is the same
memory as a picture (``cells.T[::-1]``, row 0 at the top). ``Scans`` arrays are views too;
``poses`` properties are new (n, 3) arrays. Errors in files raise :class:`FileError` with
``.file`` and ``.line``; bad arguments ValueError or TypeError; a backend that cannot run
here RuntimeError.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from ._errors import FileError
from ._core import (
    Comparison,
    Frame,
    Log,
    Map,
    Mapper,
    Params,
    Scans,
    backends,
    compare,
    cuda_available,
    has_cuda,
    load_log,
    write_map,
)
from . import _core

__version__: str = _core.__version__

__all__ = [
    "Comparison",
    "FileError",
    "Frame",
    "Log",
    "Map",
    "Mapper",
    "Params",
    "Scans",
    "__version__",
    "backends",
    "compare",
    "cuda_available",
    "gridmap_sha256",
    "has_cuda",
    "load_log",
    "read_map",
    "write_map",
]


def read_map(path: str | os.PathLike) -> Map:
    """Reads a map: CARMEN ``.map`` / ``.map.gz`` (exact), a ROS ``.pgm`` with its ``.yaml``, or a ``.png``.

    Images hold less than a CARMEN map: a PGM is read the way map_server reads it (trinary:
    occupied 1.0, free 0.0, unknown -1; scale: ``(255 - v) / 255`` with 205 unknown; raw:
    ``v / 100`` with 255 unknown), with the YAML's resolution and origin; a PNG as written by
    :func:`write_map` (``1 - v / 255``, 128 unknown), without resolution or origin (0).
    Raises :class:`FileError` naming the file.
    """
    p = os.fspath(path)
    if p.lower().endswith(".pgm"):
        return _read_pgm(p)
    return _core._read_map(p)


def gridmap_sha256(m: Map) -> str:
    """SHA-256 (hex) of a map's CARMEN GRIDMAP payload, as the golden ``SHA256SUMS`` hold it."""
    return m.sha256()


def _yaml_path(pgm: str) -> str:
    head, tail = os.path.split(pgm)
    dot = tail.rfind(".")
    return os.path.join(head, (tail[:dot] if dot > 0 else tail) + ".yaml")


def _read_pgm(path: str) -> Map:
    yaml = _yaml_path(path)
    meta: dict[str, str] = {}
    try:
        with open(yaml, encoding="utf-8") as f:
            for line in f:
                line = line.split("#", 1)[0].strip()
                if ":" in line:
                    k, v = line.split(":", 1)
                    meta[k.strip()] = v.strip()
    except OSError as e:
        raise FileError(f"{yaml}: cannot read the YAML beside the PGM: {e.strerror}", yaml, None,
                        f"cannot read the YAML beside the PGM: {e.strerror}") from None
    try:
        resolution = float(meta["resolution"])
        origin = tuple(float(v) for v in meta.get("origin", "[0, 0, 0]").strip("[] ").split(","))
        if len(origin) != 3:
            raise ValueError("origin needs three numbers")
        negate = int(meta.get("negate", "0"))
        occupied = float(meta.get("occupied_thresh", "0.65"))
        free = float(meta.get("free_thresh", "0.196"))
        mode = meta.get("mode", "trinary").strip("'\"")
    except (KeyError, ValueError) as e:
        raise FileError(f"{yaml}: bad or missing key: {e}", yaml, None, f"bad or missing key: {e}") from None
    try:
        data = Path(path).read_bytes()
    except OSError as e:
        raise FileError(f"{path}: {e.strerror}", path, None, str(e.strerror)) from None
    m = re.match(rb"P5(?:\s+|#[^\n]*\n)+(\d+)(?:\s+|#[^\n]*\n)+(\d+)(?:\s+|#[^\n]*\n)+(\d+)\s", data)
    if not m or int(m.group(3)) != 255:
        raise FileError(f"{path}: not a binary 8-bit PGM (P5, maxval 255)", path, None,
                        "not a binary 8-bit PGM (P5, maxval 255)")
    w, h = int(m.group(1)), int(m.group(2))
    pixels = np.frombuffer(data, dtype=np.uint8, count=w * h, offset=m.end()) if len(data) >= m.end() + w * h else None
    if pixels is None:
        raise FileError(f"{path}: truncated PGM", path, None, "truncated PGM")
    v = pixels.reshape(h, w).astype(np.float32)
    if mode == "raw":
        cells = np.where(pixels.reshape(h, w) == 255, np.float32(-1), v / np.float32(100))
    else:
        p = (v if negate else np.float32(255) - v) / np.float32(255)
        unknown = pixels.reshape(h, w) == 205
        if mode == "scale":
            cells = np.where(unknown, np.float32(-1), p)
        else:
            cells = np.where(p > occupied, np.float32(1), np.where(p < free, np.float32(0), np.float32(-1)))
    # Image rows (row 0 at the top) -> x-major cells[x, y].
    return Map(np.ascontiguousarray(cells[::-1].T, dtype=np.float32), resolution, origin)
