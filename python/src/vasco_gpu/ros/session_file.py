"""A LiveMap saved to a file and loaded back: the node's sessions that survive a restart.

:func:`save_session` writes every stored scan (stamp, laser pose, mount, angles, ranges), the
mapper parameters and the backend options; :func:`load_session` reads them back exactly, and
``LiveMap.restore`` maps them in one insert, so the restored grid is a fresh map of the saved
scans at their saved poses. That is the saved LiveMap's own map, bit for bit (exact backends),
once it was settled (``LiveMap.settle``) or last rendered (a Path, new parameters): a grid that
grew insert by insert differs from a fresh map's in a few cells until then (docs/sessions.md).

The format: a CARMEN log
========================

The file is a CARMEN log, read as it is by ``log2map`` (``log2map SESSION.log``, Python's
``vasco_gpu.load_log`` / ``map_logs``), which gives the session's map. Why a log and not an MCAP
bag with a pose topic: a bag carries a LaserScan's angles as float32 and a pose as a
quaternion, so neither a node's float64 beam angles (a scan made from a point cloud) nor a yaw
survives it, and ``bag2map``'s map of it would not be the session's; a log's ROBOTLASER1 line
carries the laser pose, the start angle and the angular resolution as decimal doubles, which
the package's log reader parses exactly (``std::from_chars``), and the ranges as text that
reads back to the same float32 (``range_texts``, as bag2carmen writes them). One file, not a
log plus a pose file, so that one rename commits the whole session.

Lines, in this order::

    # vasco_gpu session file: ...                                    (a comment)
    VASCO_SESSION 1 scans N backend B cuda_mode M device D threads T max_memory BYTES
    PARAM vasco_KEY VALUE 0.0 session 0.0                            (every key of Params)
    ROBOTLASER1 ...                                                  (scan i at its current pose)
    VASCO_SCAN i STAMP_NS BEAMS MOUNT_X MOUNT_Y MOUNT_YAW            (after scan i's line)
    ...
    VASCO_END N

* ``VASCO_SESSION``: the format version (1) first; the number of scans; the LiveMap's backend
  options as it was asked for them.
* ``PARAM``: CARMEN's parameter lines, which log2map takes as the log's parameters: every key
  of the mapper's table (``vasco_gpu.Params.keys()``), doubles as ``repr`` (exact), whole
  numbers as integers. log2map maps the file with them, so its map is the session's for any
  parameters, with one caveat: ``vasco_first_scan`` and ``vasco_num_scans`` select log2map's run
  of scans, while a LiveMap maps every scan it stores whatever they say; the two maps agree
  where they keep their defaults (0 and -1).
* ``ROBOTLASER1``: laser type 99, start angle = the first beam's angle, fov = step x (n - 1),
  angular resolution = the step, max range the whole metre above the longest finite reading
  (at least 80 m; CARMEN's meaning, which the mapper ignores), accuracy 0.01, no remissions;
  the laser pose; the robot pose = the laser pose with the mount undone (the laser pose where
  the mount is unknown), so ``log2map --poses ... --pose-frame robot`` can use the line's mount;
  the timestamp is the stamp in seconds (a double: not exact for nanoseconds), host
  ``session``.
* ``VASCO_SCAN``: what a log cannot carry exactly: the stamp in nanoseconds, the beam count (a
  check), the mount (laser in base x, y, yaw; ``nan`` where unknown). log2map skips these
  lines (an unknown message, as CARMEN's readers skip one).
* ``VASCO_END``: the number of scans again, last: a file cut anywhere, even inside a number of
  its last line, lacks it.

Reading is strict: a line of another kind, a missing or repeated line, a count or beam count
that disagrees, a version other than 1 raise :class:`SessionFileError` (a ``vasco_gpu.FileError``)
naming the file and the line; no array is sized by a count the file states. A name ending in
``.gz`` is written and read gzipped, as log2map reads it.

The save is one transaction (``_core._OutputFile``, carmen_compat/atomic_file.h): a temporary
beside the target, renamed over it on success; a failed save leaves the old file as it was and
no temporary behind (the engine's signal handlers remove a live temporary too, where installed).
"""

from __future__ import annotations

import gzip
import math
import os
import re
import zlib
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._errors import Error, FileError
from ..bags.carmen_writer import range_texts
from ..msgs.geometry import planar_uncompose

__all__ = ["FORMAT_VERSION", "SavedSession", "SessionFileError", "load_session", "save_session",
           "write_session"]

#: The version VASCO_SESSION states; a file of another is refused.
FORMAT_VERSION = 1
_HOST = "session"
# The CARMEN max range a line states at least (the SICK of CARMEN's logs reaches ~80 m).
_MIN_MAX_RANGE = 80.0
# VASCO_SESSION's options after the version: name -> type.
_OPTIONS = {"scans": int, "backend": str, "cuda_mode": str, "device": int, "threads": int, "max_memory": int}
# A session file's first lines are short: a file whose first bytes hold no VASCO_SESSION line
# within this many is another kind, said without reading it all.
_HEAD_BYTES = 4096
_WHOLE = re.compile(r"[+-]?[0-9]+")


class SessionFileError(FileError):
    """A session file that cannot be written or read: ``str()`` is ``FILE:LINE: what`` (``FILE:
    what`` where no line applies); ``.file``, ``.line`` as FileError's."""

    def __init__(self, path, line: int | None, message: str, code: str = "bad input"):
        path = os.fspath(path)
        where = f"{path}:{line}" if line else path
        super().__init__(f"{where}: {message}", path, line, message, code)


@dataclass
class SavedSession:
    """A LiveMap's stored scans and settings, as saved: n scans with stamps (int64 ns), laser
    poses (n, 3), mounts (n, 3; a NaN row: unknown), first_angle and angle_step (float64),
    beam_counts (int64) and ranges (float32, every scan's concatenated); the mapper's params
    and the options LiveMap was made with (backend, cuda_mode, device, threads, max_memory)."""

    stamps: np.ndarray
    poses: np.ndarray
    mounts: np.ndarray
    first_angle: np.ndarray
    angle_step: np.ndarray
    beam_counts: np.ndarray
    ranges: np.ndarray
    params: _core.Params
    options: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.stamps)

    def ranges_of(self, i: int) -> np.ndarray:
        start = int(self.beam_counts[:i].sum())
        return self.ranges[start:start + int(self.beam_counts[i])]

    @classmethod
    def of(cls, live) -> "SavedSession":
        """A copy of what a LiveMap stores now (its current poses: a Path's moves included)."""
        n = len(live)
        return cls(stamps=np.array(live.stamps, dtype=np.int64),
                   poses=np.frombuffer(live.poses, dtype=np.float64).reshape(n, 3).copy(),
                   mounts=np.frombuffer(live.mounts, dtype=np.float64).reshape(n, 3).copy(),
                   first_angle=np.array(live.first_angle, dtype=np.float64),
                   angle_step=np.array(live.angle_step, dtype=np.float64),
                   beam_counts=np.array(live.beam_counts, dtype=np.int64),
                   ranges=live.stored_ranges(),
                   params=live.mapper.params,
                   options={**live.options, "max_memory": int(live.max_memory)})


# -- writing ------------------------------------------------------------------------------------------
def save_session(live, path) -> SavedSession:
    """Writes a LiveMap's session to path (module docstring), whole or not at all; returns what
    was written. SessionFileError naming the file when it cannot be written (the old file, if
    any, as it was, and no temporary left)."""
    saved = SavedSession.of(live)
    write_session(saved, path)
    return saved


def write_session(saved: SavedSession, path) -> None:
    """save_session's writing part, for a copy taken with SavedSession.of (so that the writing
    may run apart from the LiveMap, e.g. in another thread)."""
    path = os.fspath(path)
    _check_writable(saved, path)
    try:
        target = _core._OutputFile(path)
    except Error as e:
        raise SessionFileError(path, None, f"cannot be written: {_reason(e)}", "I/O") from None
    try:
        with os.fdopen(target.take_fd(), "wb") as raw:
            if path.endswith(".gz"):
                with gzip.GzipFile(fileobj=raw, mode="wb", compresslevel=6, mtime=0) as f:
                    _write_lines(saved, f)
            else:
                _write_lines(saved, raw)
        target.commit()
    except Error as e:  # the transaction's FileError (also an OSError): its reason, said as this file's
        raise SessionFileError(path, None, f"cannot be written: {_reason(e)}", "I/O") from None
    except OSError as e:
        raise SessionFileError(path, None, f"cannot be written: {e.strerror or e}", "I/O") from None
    finally:
        target.abandon()


def _reason(e: Exception) -> str:
    return getattr(e, "message", None) or str(e)


def _check_writable(saved: SavedSession, path: str) -> None:
    """A CARMEN line needs finite poses and angles, VASCO_SESSION one word a value: refused
    before any file is touched."""
    for k in _OPTIONS.keys() - {"scans"}:
        text = str(saved.options.get(k, ""))
        if len(text.split()) != 1 or not text.isascii():
            raise SessionFileError(path, None, f"the option {k} = {text!r} cannot be saved: one ASCII word expected")
    finite = np.isfinite(saved.poses).all(axis=1) & np.isfinite(saved.first_angle) & np.isfinite(saved.angle_step)
    bad = np.flatnonzero(~finite)
    if bad.size:
        s = int(bad[0])
        raise SessionFileError(path, None, f"scan {s} (stamp {int(saved.stamps[s])} ns) has a pose or angle that "
                                           f"is not finite ({saved.poses[s].tolist()}, first angle "
                                           f"{saved.first_angle[s]!r}, step {saved.angle_step[s]!r}): not saved")


def _write_lines(saved: SavedSession, f) -> None:
    n = len(saved)
    f.write(b"# vasco_gpu session file: a CARMEN log of the stored scans at their current poses (log2map maps "
            b"it); VASCO_SESSION and VASCO_SCAN lines carry what a restart needs\n")
    options = {"scans": n, **{k: saved.options[k] for k in _OPTIONS if k != "scans"}}
    f.write(("VASCO_SESSION %d " % FORMAT_VERSION + " ".join(f"{k} {v}" for k, v in options.items())
             + "\n").encode("ascii"))
    for key, value in zip(_core.Params.keys(), saved.params.to_dict().values()):
        text = str(value) if isinstance(value, int) else repr(float(value))
        f.write(f"PARAM {key} {text} 0.0 {_HOST} 0.0\n".encode("ascii"))
    robots = _robot_poses(saved.poses, saved.mounts)
    offsets = np.concatenate([[0], np.cumsum(saved.beam_counts)])
    for s in range(n):
        ranges = saved.ranges[offsets[s]:offsets[s + 1]]
        f.write(_robotlaser_line(saved, s, ranges, robots[s]).encode("ascii"))
        mount = " ".join(repr(float(v)) for v in saved.mounts[s])
        f.write(f"VASCO_SCAN {s} {int(saved.stamps[s])} {len(ranges)} {mount}\n".encode("ascii"))
    f.write(f"VASCO_END {n}\n".encode("ascii"))


def _robot_poses(poses: np.ndarray, mounts: np.ndarray) -> np.ndarray:
    """The robot pose a ROBOTLASER1 line states: the laser pose with a known mount undone."""
    known = np.isfinite(mounts).all(axis=1)
    out = poses.copy()
    if known.any():
        out[known] = planar_uncompose(poses[known], mounts[known])
    return out


def _robotlaser_line(saved: SavedSession, s: int, ranges: np.ndarray, robot: np.ndarray) -> str:
    """Scan s as CARMEN's ROBOTLASER1 (fields as bag2carmen writes them: carmen_writer)."""
    n = len(ranges)
    step = float(saved.angle_step[s])
    finite = ranges[np.isfinite(ranges)]
    max_range = max(_MIN_MAX_RANGE, math.floor(float(finite.max())) + 1.0) if finite.size else _MIN_MAX_RANGE
    stamp = repr(int(saved.stamps[s]) / 1e9)
    config = [repr(float(saved.first_angle[s])), repr(step * (n - 1) if n else 0.0), repr(step),
              repr(max_range), "0.01", "0"]
    fields = ["ROBOTLASER1", "99", *config, str(n), *range_texts(ranges), "0",
              *(repr(float(v)) for v in saved.poses[s]), *(repr(float(v)) for v in robot),
              "0.0", "0.0", "0.0", "0.0", "1000000.0", stamp, _HOST, stamp]
    return " ".join(fields) + "\n"


# -- reading ------------------------------------------------------------------------------------------
@dataclass
class _Layout:
    """What one pass over a session file's lines finds besides the scans' own lines."""

    options: dict = field(default_factory=dict)
    session_line: int = 0
    params: dict = field(default_factory=dict)   # key -> (value text, line)
    laser_lines: list = field(default_factory=list)
    scan_lines: list = field(default_factory=list)
    stamps: list = field(default_factory=list)
    beams: list = field(default_factory=list)
    mounts: list = field(default_factory=list)
    end: tuple | None = None                     # (count, line)


def load_session(path) -> SavedSession:
    """Reads a file save_session wrote (module docstring): every value exactly as saved.
    SessionFileError (a vasco_gpu.FileError) naming the file and the line for a file that is
    not one, is cut short, of another version or inconsistent; a bad scan line is the log
    reader's FileError, naming its line too."""
    path = os.fspath(path)
    layout = _read_layout(path)
    n = len(layout.scan_lines)
    params = _params_of(path, layout)
    options = {k: v for k, v in layout.options.items() if k != "scans"}
    if n == 0:
        return SavedSession(np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0),
                            np.zeros(0, np.int64), np.zeros(0, np.float32), params, options)
    # The scans through the log reader log2map uses (every scan: a run set by the PARAM lines
    # is log2map's selection, not the session's).
    log = _core.load_log(path, overrides={"first_scan": 0, "num_scans": -1})
    scans = log.scans
    _check_scans(path, layout, scans)
    return SavedSession(stamps=np.array(layout.stamps, dtype=np.int64), poses=scans.poses,
                        mounts=np.array(layout.mounts, dtype=np.float64).reshape(n, 3),
                        first_angle=np.array(scans.first_angle, dtype=np.float64),
                        angle_step=np.array(scans.angle_step, dtype=np.float64),
                        beam_counts=np.array(scans.beam_counts, dtype=np.int64),
                        ranges=np.array(scans.ranges, dtype=np.float32), params=params, options=options)


def _check_scans(path: str, layout: _Layout, scans) -> None:
    """The log reader's scans are the lines the layout paired with VASCO_SCAN lines."""
    lines = np.asarray(scans.lines, dtype=np.int64)
    if len(lines) != len(layout.laser_lines) or not np.array_equal(lines, layout.laser_lines):
        raise SessionFileError(path, None, f"the log reader finds {len(lines)} scans, the session's lines "
                                           f"{len(layout.laser_lines)}")
    counts = np.asarray(scans.beam_counts, dtype=np.int64).tolist()
    # compared as Python ints: a corrupt count may not fit 64 bits
    bad = [s for s, (count, said) in enumerate(zip(counts, layout.beams)) if count != said]
    if bad:
        s = bad[0]
        raise SessionFileError(path, layout.scan_lines[s], f"VASCO_SCAN {s} says {layout.beams[s]} beams, its "
                                                           f"ROBOTLASER1 line {layout.laser_lines[s]} has {counts[s]}")


def _open(path: str):
    try:
        return gzip.open(path, "rb") if path.endswith(".gz") else open(path, "rb")
    except OSError as e:
        raise SessionFileError(path, None, f"cannot be read: {e.strerror or e}", "I/O") from None


def _read_layout(path: str) -> _Layout:
    layout = _Layout()
    no = 0
    try:
        with _open(path) as f:
            _check_kind(path, f.read(_HEAD_BYTES))
            f.seek(0)
            for no, raw in enumerate(f, 1):
                _take_line(path, no, raw, layout)
    except SessionFileError:  # a FileError is an OSError too: said as it is
        raise
    except (OSError, EOFError, zlib.error) as e:
        raise SessionFileError(path, no + 1 if no else None, f"cannot be read: {e.strerror or e}"
                               if isinstance(e, OSError) else f"cannot be read: {e}", "I/O") from None
    if layout.end is None:
        at = f"after scan {len(layout.scan_lines) - 1}" if layout.scan_lines else "before any scan"
        raise SessionFileError(path, no, f"the file ends {at} without its VASCO_END line (cut short?)")
    _check_counts(path, layout)
    return layout


def _check_kind(path: str, head: bytes) -> None:
    """The first line that is not a comment is VASCO_SESSION, within the file's first bytes."""
    for line in head.split(b"\n")[:-1]:
        if line.startswith(b"#") or not line.strip():
            continue
        if line.split()[0] == b"VASCO_SESSION":
            return
        break
    raise SessionFileError(path, None, "is not a vasco_gpu session file: no VASCO_SESSION line at its start "
                                       "(a CARMEN log from elsewhere is mapped with log2map, not loaded as a session)")


def _check_counts(path: str, layout: _Layout) -> None:
    n, end_line = layout.end
    found = len(layout.scan_lines)
    if layout.options["scans"] != found:
        raise SessionFileError(path, layout.session_line, f"VASCO_SESSION says {layout.options['scans']} scans, "
                                                          f"the file has {found}")
    if n != found:
        raise SessionFileError(path, end_line, f"VASCO_END says {n} scans, the file has {found}")


def _take_line(path: str, no: int, raw: bytes, layout: _Layout) -> None:
    """One line into the layout, in the order the module docstring gives."""
    tokens = raw.split()
    if not tokens or tokens[0].startswith(b"#"):
        return
    try:
        # a scan's own line is the log reader's to read: only its name here
        words = [t.decode("ascii") for t in (tokens[:1] if tokens[0] == b"ROBOTLASER1" else tokens)]
    except UnicodeDecodeError:
        raise SessionFileError(path, no, "is not ASCII text") from None
    kind = words[0]
    waiting = len(layout.laser_lines) > len(layout.scan_lines)
    if layout.end is not None:
        raise SessionFileError(path, no, f"a {kind} line after VASCO_END")
    if waiting and kind != "VASCO_SCAN":
        raise SessionFileError(path, no, f"expected scan {len(layout.scan_lines)}'s VASCO_SCAN line after its "
                                         f"ROBOTLASER1 line {layout.laser_lines[-1]}, not {kind}")
    if kind != "VASCO_SESSION" and not layout.session_line:
        raise SessionFileError(path, no, f"a {kind} line before VASCO_SESSION")
    if kind == "VASCO_SESSION":
        _take_session(path, no, words, layout)
    elif kind == "PARAM":
        _take_param(path, no, words, layout)
    elif kind == "ROBOTLASER1":
        layout.laser_lines.append(no)
    elif kind == "VASCO_SCAN":
        _take_scan(path, no, words, layout)
    elif kind == "VASCO_END":
        if len(tokens) != 2:
            raise SessionFileError(path, no, "VASCO_END takes one number, the scans")
        layout.end = (_int(path, no, words[1], "VASCO_END's scans"), no)
    else:
        raise SessionFileError(path, no, f"a {kind} line: a session file holds VASCO_SESSION, PARAM, ROBOTLASER1, "
                                         "VASCO_SCAN and VASCO_END lines")


def _take_session(path: str, no: int, words: list, layout: _Layout) -> None:
    if layout.session_line:
        raise SessionFileError(path, no, f"a second VASCO_SESSION line (the first: line {layout.session_line})")
    if len(words) < 2 or words[1] != str(FORMAT_VERSION):
        version = words[1] if len(words) > 1 else "none"
        raise SessionFileError(path, no, f"session format version {version}: this vasco_gpu reads version "
                                         f"{FORMAT_VERSION}")
    pairs = words[2:]
    if len(pairs) % 2:
        raise SessionFileError(path, no, "VASCO_SESSION: the version, then names each with a value")
    given = dict(zip(pairs[::2], pairs[1::2]))
    unknown = sorted(set(given) - set(_OPTIONS))
    missing = [k for k in _OPTIONS if k not in given]
    if unknown or missing or len(given) != len(pairs) // 2:
        raise SessionFileError(path, no, f"VASCO_SESSION must give each of {', '.join(_OPTIONS)} once "
                                         f"(unknown: {unknown or 'none'}; missing: {missing or 'none'})")
    layout.options = {k: _int(path, no, given[k], k) if kind is int else given[k] for k, kind in _OPTIONS.items()}
    if layout.options["scans"] < 0:
        raise SessionFileError(path, no, f"VASCO_SESSION: scans {layout.options['scans']} is negative")
    layout.session_line = no


def _take_param(path: str, no: int, words: list, layout: _Layout) -> None:
    if layout.laser_lines:
        raise SessionFileError(path, no, "a PARAM line after the first scan (the parameters come first)")
    if len(words) < 3:
        raise SessionFileError(path, no, "PARAM needs a name and a value")
    key = words[1]
    if key in layout.params:
        raise SessionFileError(path, no, f"{key} again (first on line {layout.params[key][1]})")
    layout.params[key] = (words[2], no)


def _take_scan(path: str, no: int, words: list, layout: _Layout) -> None:
    s = len(layout.scan_lines)
    if len(layout.laser_lines) != s + 1:
        raise SessionFileError(path, no, "a VASCO_SCAN line without its scan's ROBOTLASER1 line before it")
    if len(words) != 7:
        raise SessionFileError(path, no, "VASCO_SCAN takes 6 fields: index, stamp (ns), beams, mount x, y, yaw")
    index = _int(path, no, words[1], "VASCO_SCAN's index")
    if index != s:
        raise SessionFileError(path, no, f"VASCO_SCAN {index} where scan {s}'s was expected")
    stamp = _int(path, no, words[2], "the stamp")
    if not -2**63 <= stamp < 2**63:
        raise SessionFileError(path, no, f"the stamp {stamp} ns does not fit 64 bits")
    beams = _int(path, no, words[3], "the beam count")
    layout.scan_lines.append(no)
    layout.stamps.append(stamp)
    layout.beams.append(beams)
    layout.mounts.extend(_float(path, no, w, "the mount") for w in words[4:7])


def _params_of(path: str, layout: _Layout) -> _core.Params:
    """The mapper's parameters from the PARAM lines: every key of the table, exactly."""
    defaults = _core.Params().to_dict()
    values = {}
    for key, name in zip(_core.Params.keys(), defaults):
        if key not in layout.params:
            raise SessionFileError(path, layout.session_line, f"no PARAM line for {key}")
        text, no = layout.params[key]
        values[name] = _int(path, no, text, key) if isinstance(defaults[name], int) else _float(path, no, text, key)
    try:
        params = _core.Params(**values)
        params.validate()
    except (TypeError, ValueError) as e:
        key = next((k for k in _core.Params.keys() if str(e).startswith(k)), None)
        raise SessionFileError(path, layout.params[key][1] if key else layout.session_line, str(e)) from None
    return params


def _int(path: str, no: int, text: str, what: str) -> int:
    # int() would take "1_000" and " 1" too: a file of ours writes plain digits
    if not _WHOLE.fullmatch(text):
        raise SessionFileError(path, no, f"{what} {text!r} is not a whole number")
    return int(text)


def _float(path: str, no: int, text: str, what: str) -> float:
    try:
        if "_" in text:
            raise ValueError
        return float(text)
    except ValueError:
        raise SessionFileError(path, no, f"{what} {text!r} is not a number") from None
