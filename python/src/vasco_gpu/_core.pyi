"""
vasco_gpu's C++ engine (see the package vasco_gpu for the documentation).
"""

import os
from typing import Annotated, Any

import numpy
import numpy.typing
from numpy.typing import NDArray


has_cuda: bool

def backends() -> list[str]:
    """
    Returns the names Mapper(backend=...) takes in this build:

      ['cpu_double', 'cpu_threads', 'cpu_float', 'auto']

    That is every backend compiled into this build, then 'auto', which is no backend of its own
    but picks one of them when the Mapper is made. Aliases are not listed; each follows its
    backend's line:

      cpu_double: CARMEN's arithmetic to the letter, one core: bit-identical to CARMEN
      cpu_threads: cpu_double's bytes on all cores (--threads)
      cpu_float: single precision on one core, fast; measured against CARMEN's maps
      auto: cuda when a GPU is usable, else cpu_threads
    """

def backend_registry() -> list[dict[str, Any]]:
    """
    Every backend of the engine's registry, compiled into this build or not, in the order the
    help lists them: a dict each with 'name', 'aliases' (a list of (alias, cuda mode), the mode
    None for an alias that keeps it), 'exactness' ('exact', 'float' or 'by_cuda_mode'),
    'grid_on_device', 'compiled', 'summary', and what the options mean for it: 'uses_gpus',
    'uses_threads', 'chooses' (auto: picks another per input).
    """

def backend_names() -> list[str]:
    """
    Every name and alias Mapper(backend=...) takes, compiled into this build or not.
    """

def map_formats() -> list[dict[str, str]]:
    """
    Every map format of the engine's table, in the order the help lists them: a dict each with
    'name' (what map_logs' formats and log2map --formats take: 'map.gz'), 'extension' ('.map.gz'),
    'what' and 'kind' ('carmen', 'map_server' or 'picture'). A path's extension (any case) picks
    its format in read_map and write_map.
    """

def output_stem(path: str | os.PathLike) -> str:
    """
    The name of an input's outputs, as log2map's batch mode makes it: the file name less a
    trailing ``.gz`` and then less one extension (``fr079-complete.gfs.log.gz`` ->
    ``fr079-complete.gfs``; a ROS 2 bag's directory ``run/`` -> ``run``).
    """

class Params:
    """
    The mapper's parameters: carmen.ini's ``vasco_*`` keys without the prefix.

    ``Params(p_occ=0.9, resolution=0.05)`` (the ``vasco_`` prefix is accepted
    too: ``Params(vasco_p_occ=0.9)``) starts from vasco's defaults and is
    validated; an unknown keyword is a TypeError, a value out of range a
    ValueError naming the key. Attributes may be changed afterwards; the Mapper
    validates them again.

    Keys:

      resolution: cell size (m); default 0.025; must be between 1e-6 and 1e6 m per cell.
      p_prior: prior occupancy; default 0.5; must be strictly between 0 and 1.
      p_occ: evidence of a hit; default 0.55; must be strictly between 0 and 1.
      p_emp: evidence of a free cell; default 0.45; must be strictly between 0 and 1.
      range_sure: full-confidence range (m); default 5; must satisfy 0 <= range_sure <= range_max.
      range_max: evidence ends here (m); default 10; must be > 0 and at most 100000 m (with 0 no cell is ever updated).
      wall_size: thickness marked occupied behind a hit (m); default 0.2; must be a finite number >= 0.
      downsample: finish: block size; default 4; must be between 1 and 1000000.
      border: finish: cells kept around the known area; default 20; must be between 0 and 1000000.
      first_scan: first laser message used; default 0; must be >= 0.
      num_scans: number of laser messages used; default -1 (all); must be >= 1 (or -1 for all).
    """

    def __init__(self, **params: float | int) -> None:
        """
        Parameters from keywords (ini key names, with or without ``vasco_``); the rest keep vasco's
        defaults. Validated.
        """

    @staticmethod
    def from_ini(path: str | os.PathLike, robot: str = '', **overrides: float | int) -> Params:
        """
        Parameters from a carmen.ini (sections [*], [expert] and the robot's, as CARMEN's param_daemon
        reads them), keywords overriding the file. Errors raise FileError naming FILE:LINE.
        """

    @staticmethod
    def keys() -> list[str]:
        """The ini keys the mapper understands (vasco_resolution, ...)."""

    def validate(self) -> None:
        """Raises ValueError naming the key when a value is out of range."""

    def to_dict(self) -> dict:
        """The parameters as a dict (keys without ``vasco_``)."""

    def __repr__(self) -> str: ...

    def __eq__(self, other: object) -> bool: ...

    def __copy__(self) -> Params: ...

    def __deepcopy__(self, memo: object) -> Params: ...

    @property
    def resolution(self) -> float:
        """vasco_resolution: cell size (m)."""

    @resolution.setter
    def resolution(self, arg: float, /) -> None: ...

    @property
    def p_prior(self) -> float:
        """vasco_p_prior: prior occupancy."""

    @p_prior.setter
    def p_prior(self, arg: float, /) -> None: ...

    @property
    def p_occ(self) -> float:
        """vasco_p_occ: evidence of a hit."""

    @p_occ.setter
    def p_occ(self, arg: float, /) -> None: ...

    @property
    def p_emp(self) -> float:
        """vasco_p_emp: evidence of a free cell."""

    @p_emp.setter
    def p_emp(self, arg: float, /) -> None: ...

    @property
    def range_sure(self) -> float:
        """vasco_range_sure: full-confidence range (m)."""

    @range_sure.setter
    def range_sure(self, arg: float, /) -> None: ...

    @property
    def range_max(self) -> float:
        """vasco_range_max: evidence ends here (m)."""

    @range_max.setter
    def range_max(self, arg: float, /) -> None: ...

    @property
    def wall_size(self) -> float:
        """vasco_wall_size: thickness marked occupied behind a hit (m)."""

    @wall_size.setter
    def wall_size(self, arg: float, /) -> None: ...

    @property
    def downsample(self) -> int:
        """vasco_downsample: finish: block size."""

    @downsample.setter
    def downsample(self, arg: int, /) -> None: ...

    @property
    def border(self) -> int:
        """vasco_border: finish: cells kept around the known area."""

    @border.setter
    def border(self, arg: int, /) -> None: ...

    @property
    def first_scan(self) -> int:
        """vasco_first_scan: first laser message used."""

    @first_scan.setter
    def first_scan(self, arg: int, /) -> None: ...

    @property
    def num_scans(self) -> int:
        """vasco_num_scans: number of laser messages used."""

    @num_scans.setter
    def num_scans(self, arg: int, /) -> None: ...

    __hash__: None = None

class Frame:
    """
    Where a full-resolution evidence grid lies: size in cells, resolution,
    the first scan's heading (theta_offset) and laser position (x0, y0); the
    grid is centred on (x0, y0). Pass one to Mapper(frame=...) for a fixed frame
    (size, resolution and theta_offset are used; x0 and y0 come from the first
    scan).
    """

    def __init__(self, size_x: int, size_y: int, resolution: float, theta_offset: float = 0.0) -> None: ...

    @property
    def size_x(self) -> int: ...

    @size_x.setter
    def size_x(self, arg: int, /) -> None: ...

    @property
    def size_y(self) -> int: ...

    @size_y.setter
    def size_y(self, arg: int, /) -> None: ...

    @property
    def resolution(self) -> float: ...

    @resolution.setter
    def resolution(self, arg: float, /) -> None: ...

    @property
    def theta_offset(self) -> float: ...

    @theta_offset.setter
    def theta_offset(self, arg: float, /) -> None: ...

    @property
    def x0(self) -> float: ...

    @x0.setter
    def x0(self, arg: float, /) -> None: ...

    @property
    def y0(self) -> float: ...

    @y0.setter
    def y0(self, arg: float, /) -> None: ...

    def world_x(self, gx: float) -> float:
        """World x of the lower-left corner of cell column gx."""

    def world_y(self, gy: float) -> float:
        """World y of the lower-left corner of cell row gy."""

    def __repr__(self) -> str: ...

class Scans:
    """
    Laser scans, stored as CARMEN reads them: a pose (x, y, theta of the laser, float64) and beam
    geometry (first_angle relative to theta, angle_step) per scan, ranges as float32, all scans'
    beams concatenated.

    ``ranges``, ``x``, ``y``, ``theta``, ``first_angle``, ``angle_step`` and ``lines`` are writable
    NumPy views of the object's memory (they keep it alive); ``beam_offsets`` is a read-only view
    (which beams are whose must stay consistent with the ranges); ``poses`` and ``beam_counts``
    are new arrays.
    """

    def __init__(self, poses: numpy.typing.ArrayLike, ranges: numpy.typing.ArrayLike, beam_counts: numpy.typing.ArrayLike, first_angle: float | numpy.typing.ArrayLike, angle_step: float | numpy.typing.ArrayLike) -> None:
        """
        Scans from arrays (copied): poses (n, 3), ranges (sum of beam_counts,), beam_counts (n,) whole
        numbers, first_angle and angle_step a number or one value per scan (radians; CARMEN's 181-beam
        SICK: first_angle=-pi/2, angle_step=pi/180).
        """

    def __len__(self) -> int: ...

    @property
    def num_beams(self) -> int: ...

    @property
    def ranges(self) -> Annotated[NDArray[numpy.float32], dict(shape=(None,), order='C')]:
        """All beams' ranges, float32, scan after scan (a view)."""

    @property
    def x(self) -> Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C')]:
        """Laser x per scan (a view)."""

    @property
    def y(self) -> Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C')]:
        """Laser y per scan (a view)."""

    @property
    def theta(self) -> Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C')]:
        """Laser heading per scan (a view)."""

    @property
    def first_angle(self) -> Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C')]:
        """Angle of beam 0 relative to theta, per scan (a view)."""

    @property
    def angle_step(self) -> Annotated[NDArray[numpy.float64], dict(shape=(None,), order='C')]:
        """Angle added after every beam, per scan (a view)."""

    @property
    def lines(self) -> Annotated[NDArray[numpy.int64], dict(shape=(None,), order='C')]:
        """Line of each scan in its log (a view)."""

    @property
    def beam_offsets(self) -> Annotated[NDArray[numpy.uint64], dict(shape=(None,), order='C', writable=False)]:
        """
        Scan s owns ranges[beam_offsets[s]:beam_offsets[s + 1]] (uint64, n + 1 entries, a read-only view).
        """

    @property
    def poses(self) -> NDArray[numpy.float64]:
        """(n, 3) float64 array of (x, y, theta): a new array."""

    @property
    def beam_counts(self) -> NDArray[numpy.int64]:
        """Beams per scan (int64): a new array."""

    def ranges_of(self, s: int) -> Annotated[NDArray[numpy.float32], dict(shape=(None,), order='C')]:
        """The ranges of scan s (a view)."""

    def transform(self, x: float, y: float, theta: float) -> None:
        """
        Takes every pose into another frame, in place: x' = x0 + cos(a) x - sin(a) y, y' = y0 + sin(a) x
        + cos(a) y, theta' = theta + a for the transform (x0, y0, a) of this session into the shared frame
        of several (the identity changes no bit).
        """

    def extend(self, other: Scans) -> None:
        """
        Appends other's scans (copied) after this batch's: several sessions into one batch.
        """

    def select(self, first: int, count: int = -1) -> Scans:
        """
        Scans [first, first + count) as new Scans (count -1: to the end), clipped to the batch.
        """

    def __repr__(self) -> str: ...

class Log:
    """
    A CARMEN log read by load_log: the selected scans, the effective parameters
    (keywords > ini > the log's PARAM lines > defaults), the PROTOCOL frame and
    what the reader counted.
    """

    @property
    def scans(self) -> Scans:
        """
        The selected scans (FLASER and ROBOTLASER1 lines, in log order); its arrays are views.
        """

    @property
    def params(self) -> Params:
        """The effective parameters (a copy)."""

    @property
    def frame(self) -> Frame:
        """
        The PROTOCOL frame of the selected scans (a copy): what Mapper uses by default.
        """

    @property
    def poses(self) -> NDArray[numpy.float64]:
        """(n, 3) float64 laser poses (x, y, theta): a new array."""

    @property
    def ranges(self) -> Annotated[NDArray[numpy.float32], dict(shape=(None,), order='C')]:
        """All ranges, float32 (a view; see Scans)."""

    @property
    def stamps(self) -> NDArray[numpy.float64]:
        """
        Each selected scan's timestamp in seconds, float64 (a new array; NaN where unknown).
        """

    @property
    def posed_from_file(self) -> int:
        """Scans whose pose came from ``poses`` (0 without)."""

    @property
    def unposed_skipped(self) -> int:
        """Scans left out for want of a pose (``skip_unposed``)."""

    @property
    def warnings(self) -> list[str]:
        """Unknown vasco_* keys and the like."""

    @property
    def stats(self) -> dict:
        """
        What the reader counted: lines, messages by type, bad lines by class (lenient mode), odd
        ranges, scans used.
        """

    def __len__(self) -> int: ...

    def __repr__(self) -> str: ...

def load_log(path: str | os.PathLike, param_file: str | os.PathLike | None = None, robot: str = '', overrides: dict[str, float | int] | None = None, lenient: bool = False, *, poses: str | os.PathLike | None = None, pose_format: str | None = None, pose_match: str | None = None, pose_tolerance: float | None = None, pose_max_gap: float | None = None, pose_ids: str | os.PathLike | None = None, skip_unposed: bool | None = None, pose_frame: str | None = None, laser_mount: tuple[float, float, float] | None = None, transform: tuple[float, float, float] | None = None, add: list[str | os.PathLike | tuple[str | os.PathLike, tuple[float, float, float]]] | None = None) -> Log:
    """
    Reads a CARMEN log (.log, .clf, gzipped if the name ends in .gz) as log2map does.

    Every FLASER and ROBOTLASER1 line is a scan; ``param_file`` is a carmen.ini (``robot`` its
    section), ``overrides`` keys as in Params (they win over the ini, which wins over the log's
    PARAM lines). Strict by default: a bad line raises FileError with ``.file`` and ``.line``;
    ``lenient=True`` skips bad lines and counts them in ``Log.stats['bad_lines']``. The GIL is
    released while the log is read.

    Poses from a SLAM back end (log2map --poses): ``poses`` a TUM trajectory, g2o file or CARMEN log;
    with it (None: the default) ``pose_format`` 'auto' | 'tum' | 'g2o' | 'carmen'; ``pose_match`` 'auto' |
    'order' | 'id' | 'time'; by time, a scan between two poses at most ``pose_max_gap`` seconds apart (5;
    math.inf: any) takes their interpolation, one before the first, after the last or in a wider gap the
    nearest pose if at most ``pose_tolerance`` seconds (0.1) away; ``pose_ids`` a file of 'id scan' pairs;
    ``skip_unposed`` leave out scans without a pose; ``pose_frame`` 'laser' | 'robot'; ``laser_mount``
    (x, y, theta) of the laser on the robot. Several sessions into one grid: ``transform`` (x, y, theta) of this log into the shared
    frame, ``add`` further logs, each a path or (path, (x, y, theta)).
    """

class Map:
    """
    A finished occupancy map (or one read from a file).

    ``cells`` is a writable 2-D float32 NumPy view of the map's memory, shape (size_x,
    size_y), x-major as CARMEN stores it: ``cells[x, y]`` is the cell x columns right of and y
    rows above the lower-left corner; -1 is unknown, else the occupancy probability.
    ``image`` is the same memory seen as a picture (``cells.T[::-1]``: row 0 at the top, +y up),
    also a view. ``origin`` is the world pose (x, y, theta) of the lower-left corner of cell
    (0, 0), as CARMEN's OFFSET chunk and map_server's YAML give it.

    ``Map(cells, resolution, origin)`` refuses the cells read_map would refuse (BadInputError, a
    ValueError, naming the first bad cell); values later written into the ``cells`` view are
    checked when the map is written (write_map) or compared (compare).
    """

    def __init__(self, cells: numpy.typing.ArrayLike, resolution: float, origin: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None:
        """
        A map from x-major cells (size_x, size_y), copied into the map. Each cell is -1 (unknown), a
        probability in [0, 1] or an off-limits value in [2, 3] (what read_map accepts); any other
        value (NaN and inf among them) is a BadInputError (a ValueError) naming the first such
        cell (x, y) and its value.
        """

    @property
    def cells(self) -> numpy.typing.NDArray[numpy.float32]:
        """
        (size_x, size_y) float32, x-major (cells[x, y]); a view of the map's memory.
        """

    @property
    def image(self) -> numpy.typing.NDArray[numpy.float32]:
        """
        (size_y, size_x) float32 view with row 0 at the top (``cells.T[::-1]``), for plotting.
        """

    @property
    def size_x(self) -> int: ...

    @property
    def size_y(self) -> int: ...

    @property
    def shape(self) -> tuple[int, int]: ...

    @property
    def resolution(self) -> float:
        """Metres per cell."""

    @resolution.setter
    def resolution(self, arg: float, /) -> None: ...

    @property
    def origin(self) -> tuple[float, float, float]:
        """
        World pose (x, y, theta) of the lower-left corner of cell (0, 0); (0, 0, 0) when unknown.
        """

    @origin.setter
    def origin(self, arg: tuple[float, float, float], /) -> None: ...

    @property
    def has_origin(self) -> bool:
        """False for a CARMEN map without an OFFSET chunk and for PNG images."""

    @property
    def downsample(self) -> int:
        """The block size finish used (1 for maps read from files)."""

    @property
    def offset_cells(self) -> tuple[int, int]:
        """finish's crop offset (min_x, min_y), in downsampled cells."""

    def sha256(self) -> str:
        """
        SHA-256 of the map's CARMEN GRIDMAP payload (what the golden SHA256SUMS hold).
        """

    def __repr__(self) -> str: ...

def write_map(path: str | os.PathLike, map: Map, mode: str = 'trinary', description: str = '') -> None:
    """
    Writes a map, the format chosen by the name: ``.map`` / ``.map.gz`` (CARMEN, with an OFFSET
    chunk when the map has an origin), ``.pgm`` (ROS map_server image plus a ``.yaml`` beside it;
    ``mode`` trinary, scale or raw) or ``.png`` (grey: white free, black occupied, mid grey
    unknown). Atomic: a failure leaves no file behind. Raises FileError naming the file, and
    BadInputError (a ValueError) for a map read_map would refuse: a cell that is not -1 or a
    probability (NaN among them), or, for .map and .pgm, a resolution that is not positive.
    """

class Comparison:
    """
    DESIGN section 4's agreement table of map B against map A (the reference), over their overlap.
    """

    @property
    def cells(self) -> int:
        """Cells compared (the overlap)."""

    @property
    def both_known(self) -> int: ...

    @property
    def status_differs(self) -> int:
        """Known in one map, unknown in the other."""

    @property
    def identical(self) -> int:
        """Bit-identical cells."""

    @property
    def max_abs_diff(self) -> float:
        """max |a - b| over cells known in both."""

    @property
    def large_diffs(self) -> int:
        """Cells known in both with |a - b| > 0.1."""

    @property
    def class_agree(self) -> int: ...

    @property
    def class_agreement(self) -> float:
        """
        Share of cells in the same class (occupied p > 0.5, free p < 0.5, unknown).
        """

    @property
    def occupied_ref(self) -> int: ...

    @property
    def occupied_agree(self) -> int: ...

    @property
    def free_ref(self) -> int: ...

    @property
    def free_agree(self) -> int: ...

    @property
    def unknown_ref(self) -> int: ...

    @property
    def unknown_agree(self) -> int: ...

    @property
    def shift_x(self) -> int:
        """B's cell (bx, by) lies on A's (bx + shift_x, by + shift_y)."""

    @property
    def shift_y(self) -> int: ...

    @property
    def outside(self) -> int:
        """Cells of A or B outside the overlap (they differ)."""

    @property
    def outside_known(self) -> int: ...

    @property
    def differing_cells(self) -> int: ...

    @property
    def same_cells(self) -> bool:
        """Bit-identical over the overlap and nothing outside it."""

    @property
    def largest(self) -> list[tuple[int, int, float, float]]:
        """
        Up to `top` cells known in both whose bits differ, largest |a - b| first: (x, y, a, b).
        """

    def table(self, title: str = 'B against A') -> str:
        """The table as text."""

    def to_dict(self) -> dict:
        """Every count as a dict."""

    def __str__(self) -> str: ...

    def __repr__(self) -> str: ...

def compare(a: Map, b: Map, align: bool = True, top: int = 0) -> Comparison:
    """
    Compares map B with map A (the reference): DESIGN section 4's table (class agreement,
    known/unknown differences, |dp| > 0.1, max |dp|, bit-identical cells). Maps whose origins
    are a whole number of cells apart are aligned by them (``align=False``: cell (0, 0) on cell
    (0, 0)). ``top``: how many of the largest differences to keep in ``.largest``. A map holding a
    cell that is not -1 or a probability (NaN among them) raises BadInputError (a ValueError).
    """

class Mapper:
    """
    A mapping session (DESIGN section 7): scans stored once (on the GPU for ``cuda``), poses
    replaceable as a whole, the evidence grid kept between calls.

        mapper = vasco_gpu.Mapper(params, backend='cuda', cuda_mode='exact')
        mapper.insert(log.scans)          # new scans continue the grid
        mapper.render(new_poses)          # a loop closure: every pose moved, recomputed
        m = mapper.finish()               # CARMEN's finish -> Map

    Backends: cpu_double (CARMEN's routine, bit-identical), cpu_threads (the same bytes on every
    core), cpu_float (single precision), cuda (cuda_mode 'float', the default, or 'exact':
    CARMEN's bytes), auto (cuda when a GPU is usable, else cpu_threads); 'cuda_exact' and
    'cuda_float' name the CUDA modes too. The GIL is released while the session maps; calls on
    one Mapper from several threads are serialised, and len, frame, last_stats, renders and
    repr answer at once even while another thread maps (as of the end of the last call).

    Ctrl-C during insert, render or finish runs Python's handler at once; a call cannot stop
    half-way, so KeyboardInterrupt is raised when the call has finished: the session then holds
    what the call did (the scans inserted, the poses rendered), or, if the call failed, what it
    held before.
    """

    def __init__(self, params: Params | None = None, backend: str = 'cpu_double', cuda_mode: str | None = None, threads: int = 0, frame: Frame | None = None, cuda_device: int = 0, max_memory_bytes: int = 2147483648) -> None:
        """
        A session with ``params`` (vasco's defaults when None) on ``backend``.

        cuda_mode: 'float' (default) or 'exact'. threads: cpu_threads' threads (0: all cores; at
        most 1024, as log2map's --threads). frame: a fixed Frame (cells outside it are skipped, as
        CARMEN does) instead of the PROTOCOL frame, which grows as scans arrive. max_memory_bytes:
        host memory the session may use (0: no limit). Raises ValueError for bad parameters or an
        unknown backend, RuntimeError when the backend cannot run here (e.g. cuda without a GPU).
        """

    def insert(self, scans: Scans) -> None:
        """
        Stores ``scans`` after those stored and applies them to the grid (exact backends: the bytes
        of mapping everything at once). Raises BadInputError (a ValueError) for a batch whose
        arrays disagree, RuntimeError when the frame would be too large or the session would
        exceed max_memory_bytes (nothing is stored then).
        """

    def render(self, poses: numpy.typing.ArrayLike) -> None:
        """
        New poses for every stored scan, an (n, 3) float64 array of (x, y, theta), and the grid
        recomputed from scratch with them (only the poses travel to the GPU).
        """

    def finish(self, downsample: int | None = None, border: int | None = None) -> Map:
        """
        CARMEN's finish of the current grid (block means, crop to the known area plus ``border``),
        on the GPU for cuda; ``downsample``/``border`` default to the params'. Returns a Map whose
        cells are moved, not copied, out of the session.
        """

    def start_over(self, params: Params) -> None:
        """
        A new session on the same backend: the stored scans, the frame and the grid dropped,
        ``params`` in force (validated first: a refusal raises ValueError and changes nothing; a
        fixed frame stays, and its resolution must equal the new one). The backend is kept, with
        its CUDA context and GPU scratch memory, so that many logs mapped in turn pay its start-up
        once (map_logs does this). ``renders`` keeps counting.
        """

    def read(self, window: tuple[int, int, int, int] | None = None) -> numpy.typing.NDArray[numpy.float32]:
        """
        The full-resolution grid, or the window (x0, y0, width, height) of it, as a (width, height)
        float32 array, x-major (a new array that owns the cells C++ returned; no further copy).
        """

    @property
    def poses(self) -> NDArray[numpy.float64]:
        """The stored scans' poses, (n, 3) float64 (a new array)."""

    def __len__(self) -> int: ...

    @property
    def num_scans(self) -> int:
        """Scans stored."""

    @property
    def frame(self) -> Frame:
        """The current frame (a copy)."""

    @property
    def params(self) -> Params:
        """The session's parameters (a copy; start_over replaces them)."""

    @property
    def backend(self) -> str:
        """
        The backend's name (cpu_double, cpu_threads, cpu_float, cuda_float, cuda_exact).
        """

    @property
    def last_stats(self) -> dict:
        """Counts and phase times of the last insert or render."""

    @property
    def renders(self) -> int:
        """
        Full renders since construction (each render(), each growth, the first insert).
        """

    def __repr__(self) -> str: ...
