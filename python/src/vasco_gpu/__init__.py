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

``vg.cuda_available()`` is true where ``backend="cuda"`` can run; its ``.reason`` says why not
("no GPU found (...)", a build without CUDA). ``vg.backends()`` lists the backend names this
build takes.

ROS bags (ROS 1 ``.bag``, ROS 2 sqlite3 and MCAP, read with ``rosbags``) give the same ``Log``:
``vg.load_bag("run.mcap")``; poses from a SLAM back end: ``vg.load_log(path, poses="opt.g2o")``.

Many logs to files, as log2map's batch mode, here or on the workers of any
``concurrent.futures.Executor`` (a Dask cluster, a process pool, Ray actors through
:class:`RayExecutor`), each worker keeping one mapper for all its logs::

    results = vg.map_logs(["a.log.gz", "b.clf"], "maps", formats=("map.gz", "png"),
                          executor=client.get_executor())     # maps/a.map.gz, maps/a.png, ...
    failed = [r for r in results if not r.ok]                 # r.error names the file

Arrays: ``Map.cells`` is a float32 view of shape (size_x, size_y) indexed ``cells[x, y]`` as
CARMEN stores maps (-1 unknown, else the occupancy probability); ``Map.image`` is the same
memory as a picture (``cells.T[::-1]``, row 0 at the top). ``Scans`` arrays are views too;
``poses`` properties are new (n, 3) arrays (``Scans.beam_offsets`` is read-only). Errors
in files raise :class:`FileError` with ``.file`` and ``.line``; other errors of the engine
one class per kind (:class:`UsageError`, :class:`BadInputError`, ... in ``_errors``), each
also the built-in exception of its kind: bad arguments ValueError (or TypeError), a backend
that cannot run here RuntimeError.
"""

from __future__ import annotations

import os

from ._errors import (
    BadInputError,
    Error,
    FileError,
    InternalError,
    IoError,
    NoGpuError,
    OutOfMemoryError,
    StateError,
    TooLargeError,
    UsageError,
)
from ._core import (
    Comparison,
    Frame,
    Log,
    Map,
    Mapper,
    Params,
    ROS_MAP_RESOLUTION,
    Scans,
    auto_choice,
    backend_names,
    backend_registry,
    backends,
    compare,
    estimated_cell_updates,
    has_cuda,
    load_log,
    map_formats,
    option_schema,
    output_stem,
    write_map,
)
from . import _core
from ._cuda import CudaStatus, cuda_available
from .bags.load import load_bag
from .bags.info import bag_info
from ._batch import BatchError, LogResult, map_logs
from .align import align_sessions

__version__: str = _core.__version__

__all__ = [
    "BadInputError",
    "BatchError",
    "Comparison",
    "CudaStatus",
    "Error",
    "FileError",
    "Frame",
    "InternalError",
    "IoError",
    "Log",
    "LogResult",
    "Map",
    "Mapper",
    "NoGpuError",
    "OutOfMemoryError",
    "Params",
    "ROS_MAP_RESOLUTION",
    "RayExecutor",
    "Scans",
    "StateError",
    "TooLargeError",
    "UsageError",
    "__version__",
    "align_sessions",
    "auto_choice",
    "backend_names",
    "backend_registry",
    "backends",
    "bag_info",
    "compare",
    "cuda_available",
    "estimated_cell_updates",
    "gridmap_sha256",
    "has_cuda",
    "load_bag",
    "load_log",
    "map_formats",
    "map_logs",
    "option_schema",
    "output_stem",
    "read_map",
    "write_map",
]


def __getattr__(name: str):
    # RayExecutor imports Ray only when asked for: ``import vasco_gpu`` works without it.
    if name == "RayExecutor":
        from .ray_executor import RayExecutor

        return RayExecutor
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def read_map(path: str | os.PathLike) -> Map:
    """Reads a map: CARMEN ``.map`` / ``.map.gz`` (exact), a ROS ``.pgm`` with its ``.yaml``, or a ``.png``.

    Images hold less than a CARMEN map: a PGM is read the way map_server reads it (trinary:
    occupied 1.0, free 0.0, unknown -1; scale: ``(255 - v) / 255`` with 205 unknown; raw:
    ``v / 100`` with 255 unknown), with the YAML's resolution and origin; a PNG as written by
    :func:`write_map` (grey ``1 - v / 255``, the colour #708986 unknown; an older grey picture's
    128 too), without resolution or origin (0); ``NAME.png+yaml`` and ``NAME.yaml`` as the
    map_server pair their YAML describes. The
    format is chosen by the name's extension, in any case (``x.PNG``). Raises
    :class:`FileError` naming the file.
    """
    return _core._read_map(os.fspath(path))


def gridmap_sha256(m: Map) -> str:
    """SHA-256 (hex) of a map's CARMEN GRIDMAP payload, as the golden ``SHA256SUMS`` hold it."""
    return m.sha256()
