""":func:`align_sessions`: several sessions (logs, bags) of one place put into one frame without
given transforms, by aligning each session's map to the map of the sessions before it (the
engine's correlative search, ``vasco_gpu._core._align_maps``).

The first session is the shared frame. Each next one is mapped on its own, aligned to the
map of every session before it (their scans at the transforms already found or given), and
its scans then join that map. A session that cannot be placed (no overlap, or two distinct
candidates nearly as good) is refused rather than guessed.
"""

from __future__ import annotations

import copy
import math
import os
from dataclasses import dataclass
from typing import Any, Sequence

from . import _core
from ._errors import BadInputError, UsageError

# Inputs read by load_bag: ROS 1 bags, ROS 2 bag directories and their storage files.
_BAG_SUFFIXES = (".bag", ".mcap", ".db3")


@dataclass
class _Session:
    name: str            # the input as errors and results name it
    scans: _core.Scans   # the session's own copy, moved into the shared frame when placed
    params: _core.Params
    transform: Any       # (x, y, theta), or "auto"


def is_bag(path: str | os.PathLike) -> bool:
    """True for what load_bag reads (a .bag, .mcap, .db3 or a ROS 2 bag directory)."""
    p = os.fspath(path)
    return os.path.isdir(p) or p.lower().endswith(_BAG_SUFFIXES)


def _load(session, index: int, params: _core.Params | None) -> tuple[str, _core.Scans, _core.Params]:
    """The session's name, scans (the caller's: not yet copied) and parameters."""
    if isinstance(session, _core.Log):
        return f"sessions[{index}]", session.scans, session.params
    if isinstance(session, _core.Scans):
        return f"sessions[{index}]", session, params if params is not None else _core.Params()
    if isinstance(session, (str, os.PathLike)):
        path = os.fspath(session)
        if is_bag(path):
            from .bags.load import load_bag
            log = load_bag(path)
        else:
            log = _core.load_log(path)
        return path, log.scans, log.params
    raise TypeError(f"sessions[{index}]: expected a Log, Scans, a path or (session, transform), "
                    f"not {type(session).__name__}")


def _transform_of(t, name: str):
    """'auto', or (x, y, theta) as three finite floats."""
    if isinstance(t, str):
        if t != "auto":
            raise UsageError(f"{name}: a transform is (x, y, theta) or 'auto', not {t!r}")
        return t
    values = tuple(float(v) for v in t)
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise UsageError(f"{name}: a transform is three finite numbers (x, y, theta), not {t!r}")
    return values


def _session(entry, index: int, params: _core.Params | None) -> _Session:
    given = "auto" if index > 0 else None
    if isinstance(entry, tuple):
        if len(entry) != 2:
            raise UsageError(f"sessions[{index}]: a tuple is (session, transform)")
        entry, given = entry
    name, scans, session_params = _load(entry, index, params)
    transform = _transform_of(given, name) if given is not None else (0.0, 0.0, 0.0)
    if index == 0 and transform == "auto":
        raise UsageError(f"{name}: the first session is the shared frame: its transform is given or none")
    # A copy: placing a session moves its poses, never those of the caller's Log.
    return _Session(name, scans.select(0), session_params, transform)


def _cell_params(params: _core.Params, cell: float) -> _core.Params:
    """The session's parameters, mapped directly at `cell` (no downsampling): the maps aligned."""
    p = copy.copy(params)
    p.resolution = cell
    p.downsample = 1
    return p


def _refusal(r: dict, before: int) -> str:
    def candidate(t, score):
        return f"({t[0]:.3f}, {t[1]:.3f}, {t[2]:.4f}) score {score:.3f}"

    text = (f"{r['input']}: not aligned to the {before} session{'s' if before > 1 else ''} before it: "
            f"{r['verdict']} ({r['reason']}); best candidate {candidate(r['transform'], r['score'])}")
    if r["second_transform"] is not None:
        text += f", second {candidate(r['second_transform'], r['second_score'])}"
    return text + "; give its transform (x, y, theta) or a hint near it"


def _hint_of(hints, k: int, count: int):
    if hints is None:
        return None
    if len(hints) != count:
        raise UsageError(f"hints: one per added session ({count}), None where there is none; got {len(hints)}")
    return None if hints[k] is None else tuple(float(v) for v in hints[k])


def _search_of(backend: str) -> str:
    """Where the alignment's search runs for a Mapper backend: the CPU for the CPU backends."""
    return "cpu" if backend.startswith("cpu") else "gpu" if backend.startswith("cuda") else "auto"


def _given_result(s: _Session) -> dict:
    return {"input": s.name, "aligned": "given", "verdict": "given", "reason": "", "transform": s.transform,
            "score": None, "second_transform": None, "second_score": None, "overlap": None, "matched": None}


def place_sessions(sessions: list[_Session], *, backend: str, cell: float, threads: int, refuse: bool,
                   hints, align_options: dict) -> list[dict]:
    """Takes every session's scans into the shared frame, in order (each 'auto' one by aligning it
    to the map of the sessions before it); returns one dict per session after the first."""
    first = sessions[0]
    first.scans.transform(*first.transform)
    shared = _core.Mapper(_cell_params(first.params, cell), backend=backend, threads=threads)
    shared.insert(first.scans)
    placed, results = 1, []
    for k, s in enumerate(sessions[1:]):
        if s.transform != "auto":
            r = _given_result(s)
        else:
            own = _core.Mapper(_cell_params(s.params, cell), backend=backend, threads=threads)
            own.insert(s.scans)
            r = {"input": s.name, "aligned": "auto",
                 **_core._align_maps(shared.finish(), own.finish(), hint=_hint_of(hints, k, len(sessions) - 1),
                                     threads=threads, search=_search_of(backend), **align_options)}
            if r["verdict"] != "aligned":
                if refuse:
                    e = BadInputError(_refusal(r, placed))
                    e.results = results + [r]
                    raise e
                results.append(r)
                continue  # left out of the shared map: later sessions align to the placed ones
        s.scans.transform(*r["transform"])
        shared.insert(s.scans)
        placed += 1
        results.append(r)
    return results


def align_sessions(sessions: Sequence[Any], *, backend: str = "auto", resolution: float | None = None,
                   match_resolution: float = 0.1, hints: Sequence[Any] | None = None,
                   min_score: float | None = None, ambiguity: float | None = None,
                   min_matched: int | None = None, threads: int = 0, refuse: bool = True,
                   params: _core.Params | None = None) -> list[dict]:
    """The transforms that take each session after the first into the first one's frame.

    ``sessions``: each a :class:`Log` (from :func:`load_log` or :func:`load_bag`), :class:`Scans`
    (mapped with ``params``, vasco's defaults when None), a path (a CARMEN log is read with
    load_log, a ``.bag``, ``.mcap``, ``.db3`` or bag directory with load_bag), or
    ``(session, (x, y, theta))`` for one whose transform is known (``(session, 'auto')`` is the
    default). In order, each session is mapped alone and aligned to the map of all sessions before
    it at their transforms; the transform is (x, y, theta) as ``load_log(add=[(path, (x, y,
    theta))])`` and ``Scans.transform`` take it. The Logs and Scans given are not changed.

    The maps are made with ``backend`` (a :class:`Mapper` backend; the search runs on the GPU for
    ``cuda``, on the CPU for the ``cpu_*`` backends, for ``auto`` where one is usable) at ``resolution`` metres a cell
    (default ``match_resolution``) and matched at ``match_resolution`` (the accuracy is a fraction
    of it). ``hints``: one per added session, None or (x, y, theta) or (x, y, theta, radius_m,
    radius_rad): search only near that guess. ``min_score``, ``ambiguity``, ``min_matched``: the
    refusal's thresholds (None: the engine's; see ``vasco_gpu._core._align_maps``). ``threads``: 0
    for every core.

    Returns one dict per added session: 'input' (its path, or ``sessions[i]``), 'aligned' ('auto' or
    'given'), 'verdict' ('aligned', 'no_overlap', 'ambiguous'; 'given'), 'reason', 'transform',
    'score', 'second_transform' and 'second_score' (the best distinct other candidate, None when
    there is none), 'overlap', 'matched' and the search's counts. A session that is not aligned
    raises :class:`BadInputError` naming it and its best candidates (``.results``: the dicts so
    far, its own last); with ``refuse=False`` its dict is returned instead, and the sessions after
    it are aligned to those placed.
    """
    if len(sessions) < 1:
        raise UsageError("align_sessions: no session given")
    cell = match_resolution if resolution is None else float(resolution)
    if not (math.isfinite(cell) and cell > 0):
        raise UsageError(f"align_sessions: resolution must be finite and positive, not {resolution!r}")
    options = {k: v for k, v in (("match_resolution", match_resolution), ("min_score", min_score),
                                 ("ambiguity", ambiguity), ("min_matched", min_matched)) if v is not None}
    loaded = [_session(s, i, params) for i, s in enumerate(sessions)]
    return place_sessions(loaded, backend=backend, cell=cell, threads=threads, refuse=refuse, hints=hints,
                          align_options=options)
