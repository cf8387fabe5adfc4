"""map_logs: many CARMEN logs mapped to files, in this process or through any Executor.

``map_logs(paths, out_dir)`` is log2map's batch mode (``log2map --out-dir DIR LOG...``) from
Python: each log is read, mapped and written to ``DIR/STEM.FORMAT`` for each format, its
outputs as one transaction, and a failed log is reported, not raised. With an ``executor``
(any :class:`concurrent.futures.Executor`: a ``ProcessPoolExecutor``, a Dask ``Client``'s
``get_executor()``, dask-cuda's cluster through its client, Ray actors through
:class:`vasco_gpu.RayExecutor`, ...) one task is submitted per log
and the logs are mapped where the executor runs them; each worker process keeps one
:class:`Mapper` per backend configuration for all the logs it maps, so it pays the backend's
start-up (a CUDA context, device memory) once.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import operator
import os
import pickle
import socket
import threading
import time
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from . import _core
from ._errors import Error, FileError

PathLike = Union[str, "os.PathLike[str]"]

@dataclasses.dataclass
class LogResult:
    """What became of one log of :func:`map_logs`.

    Attributes:
        path: the log, as given.
        outputs: the files written (or that would have been), one per format; a ``.pgm``
            has its ``.yaml`` beside it.
        ok: whether every output was written.
        error: why not (the exception's message, naming the file), or None.
        scans: scans mapped (0 when the log could not be read).
        backend: the backend that mapped it (``cpu_threads``, ``cuda_float``, ...; the name
            asked for when no mapper was made).
        seconds: ``{"read": ..., "map": ..., "write": ...}``: reading the log, mapping it
            (``start_over``, ``insert``, ``finish``) and writing the outputs.
        worker: ``"HOST:PID"`` of the process that mapped it.
        mapper_logs: how many logs that process's mapper has mapped, this one included (1:
            the mapper was made for it; more: it was reused).
    """

    path: str
    outputs: List[str]
    ok: bool = False
    error: Optional[str] = None
    scans: int = 0
    backend: str = ""
    seconds: Dict[str, float] = dataclasses.field(default_factory=lambda: {"read": 0.0, "map": 0.0, "write": 0.0})
    worker: str = ""
    mapper_logs: int = 0
    # The exception itself where it survives pickling (fail_fast chains it), else None.
    exception: Optional[BaseException] = dataclasses.field(default=None, repr=False, compare=False)


class BatchError(Error, RuntimeError):
    """:func:`map_logs` with ``fail_fast=True``: a log failed.

    ``str(error)`` is the failed log's error. Attributes: ``result``, that log's
    :class:`LogResult`; ``results``, one per path in the order given (logs not run because
    of the failure have ``ok`` False and say so). The log's own exception is the
    ``__cause__`` where it could travel back from the worker.
    """

    def __init__(self, result: LogResult, results: List[LogResult]) -> None:
        super().__init__(result.error)
        self.result = result
        self.results = results

    def __reduce__(self):
        return (type(self), (self.result, self.results))


# ---------------------------------------------------------------------------------------------
# The worker side: one Mapper per backend configuration per process.


class _CachedMapper:
    __slots__ = ("mapper", "lock", "logs")

    def __init__(self) -> None:
        self.mapper: Optional[_core.Mapper] = None
        self.lock = threading.Lock()  # held from start_over to finish: one log at a time
        self.logs = 0


_MAPPERS: Dict[Tuple[Any, ...], _CachedMapper] = {}
_MAPPERS_LOCK = threading.Lock()
_FORKED_AWAY: List[Dict[Tuple[Any, ...], _CachedMapper]] = []


def _forget_mappers_after_fork() -> None:
    # A forked child must not use its parent's sessions (a CUDA context does not survive a
    # fork, a lock may have been held by a thread that is gone) nor destroy them: they are kept,
    # unused, and the child makes its own.
    global _MAPPERS, _MAPPERS_LOCK
    _FORKED_AWAY.append(_MAPPERS)
    _MAPPERS = {}
    _MAPPERS_LOCK = threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_mappers_after_fork)


def _cached_mapper(key: Tuple[Any, ...]) -> _CachedMapper:
    with _MAPPERS_LOCK:
        entry = _MAPPERS.get(key)
        if entry is None:
            entry = _MAPPERS[key] = _CachedMapper()
        return entry


def _release_mappers() -> int:
    """Drops this process's cached mappers (their backends, CUDA contexts included, go when
    no log is mapping on them); returns how many there were."""
    with _MAPPERS_LOCK:
        entries = list(_MAPPERS.values())
        _MAPPERS.clear()
    for entry in entries:
        with entry.lock:
            entry.mapper = None
    return len(entries)


def _error_text(path: str, e: BaseException) -> str:
    text = str(e) or type(e).__name__
    return text if path in text else f"{path}: {text}"


def _travels(e: BaseException) -> Optional[BaseException]:
    """``e`` when it survives pickling (a result goes back from a worker pickled), else None."""
    try:
        pickle.loads(pickle.dumps(e))
    except Exception:
        return None
    return e


def _map_one(path: PathLike, outputs: Sequence[str], backend: str = "auto", cuda_mode: Optional[str] = None,
             threads: int = 0, cuda_device: int = 0, max_memory_bytes: Optional[int] = None,
             load_options: Optional[Dict[str, Any]] = None) -> LogResult:
    """One log of :func:`map_logs`, in the process that runs it: read, mapped on this
    process's mapper for (backend, cuda_mode, threads, cuda_device, max_memory_bytes), its
    outputs written as one transaction. Never raises for the log's failure: the result says."""
    path = os.fspath(path)
    result = LogResult(path=path, outputs=[os.fspath(o) for o in outputs], backend=backend,
                       worker=f"{socket.gethostname()}:{os.getpid()}")
    t = time.perf_counter()
    phase = "read"
    try:
        log = _core.load_log(path, **(load_options or {}))
        result.scans = len(log)
        now = time.perf_counter()
        result.seconds["read"], t, phase = now - t, now, "map"
        key = (backend, cuda_mode, threads, cuda_device, max_memory_bytes)
        entry = _cached_mapper(key)
        with entry.lock:
            if entry.mapper is None:
                kw = {} if max_memory_bytes is None else {"max_memory_bytes": max_memory_bytes}
                # Many logs on one mapper: its start-up is paid once, so auto weighs a workload
                # without end (expected_renders=0), as log2map's batch mode does.
                entry.mapper = _core.Mapper(backend=backend, cuda_mode=cuda_mode, threads=threads,
                                            cuda_device=cuda_device, expected_renders=0, **kw)
            mapper = entry.mapper
            result.backend = mapper.backend
            try:
                mapper.start_over(log.params)
                entry.logs += 1
                result.mapper_logs = entry.logs
                mapper.insert(log.scans)
                del log
                m = mapper.finish()
                mapper._check_mapped(m, path)  # as log2map: a map without a known cell is not written
            finally:
                try:
                    mapper.start_over(_core.Params())  # the scans' memory goes now, not at the next log
                except Exception:
                    pass
        now = time.perf_counter()
        result.seconds["map"], t, phase = now - t, now, "write"
        description = f"vasco_gpu {_core.__version__} {result.backend}"
        _core._write_maps(result.outputs, m, description=description)
        result.seconds["write"] = time.perf_counter() - t
        result.ok = True
    except Exception as e:
        result.seconds[phase] = time.perf_counter() - t
        result.error = _error_text(path, e)
        result.exception = _travels(e)
    return result


# ---------------------------------------------------------------------------------------------
# The caller's side.


def _check_formats(formats: Union[str, Sequence[str]]) -> List[str]:
    return _core._check_map_formats([formats] if isinstance(formats, str) else list(formats), "map_logs: formats")


def _check_options(backend: str, cuda_mode: Optional[str], threads: int, load_options: Dict[str, Any]) -> None:
    # The session's option table: its backend names (compiled here or not: the workers may have
    # what this process lacks), CUDA modes and threads' bounds.
    rows = {row["name"]: row for row in _core.option_schema("session")}
    for name, value in (("backend", backend), ("cuda_mode", cuda_mode)):
        choices = rows[name]["choices"]
        if value not in choices and not (name == "cuda_mode" and value is None):  # None: Mapper's default
            raise ValueError(f"map_logs: {name} {value!r}: expected one of {', '.join(choices)}")
    try:
        n = operator.index(threads)
    except TypeError:
        n = -1
    lo, hi = rows["threads"]["lo"], rows["threads"]["hi"]
    if isinstance(threads, bool) or not lo <= n <= hi:
        raise ValueError(f"map_logs: threads {threads!r}: {rows['threads']['help']}, {int(lo)} to {int(hi)}")
    # load_log's own checks of its options, before any work: a call on no file binds the
    # keywords (TypeError for an unknown one), reads the ini and the overrides (errors naming
    # them) and fails on the empty path, the one error expected here.
    try:
        _core.load_log("", **load_options)
    except FileError as e:
        if e.file != "":
            raise
    except TypeError as e:
        raise TypeError(f"map_logs: {e}") from None


def _plan(paths: Sequence[PathLike], out_dir: PathLike, formats: List[str]) -> List[Tuple[str, List[str]]]:
    if isinstance(paths, (str, bytes, os.PathLike)):
        raise TypeError("map_logs: paths: expected a list of logs, not one path")
    return _core._plan_outputs([os.fspath(p) for p in paths], os.fspath(out_dir), formats, "map_logs: ")


def _not_run(path: str, outputs: List[str], backend: str) -> LogResult:
    return LogResult(path=path, outputs=outputs, backend=backend,
                     error=f"{path}: not mapped: an earlier log failed and fail_fast is set")


def _lost(path: str, outputs: List[str], backend: str, e: BaseException) -> LogResult:
    # The task itself failed (a worker that died, a result that could not travel back).
    return LogResult(path=path, outputs=outputs, backend=backend,
                     error=f"{path}: the task failed: {type(e).__name__}: {e}", exception=e)


def _raise_fast(failed: LogResult, results: List[LogResult]) -> None:
    raise BatchError(failed, results) from failed.exception


def map_logs(paths: Sequence[PathLike], out_dir: PathLike, formats: Union[str, Sequence[str]] = ("map.gz",),
             backend: str = "auto", executor: Optional[cf.Executor] = None, *, cuda_mode: Optional[str] = None,
             threads: int = 0, cuda_device: int = 0, max_memory_bytes: Optional[int] = None,
             fail_fast: bool = False, **load_options: Any) -> List[LogResult]:
    """Maps many CARMEN logs to files, as ``log2map --out-dir OUT_DIR --formats ... LOG...`` does.

    Each log ``DIR/NAME.EXT[.gz]`` is read with ``load_log(path, **load_options)`` (its PARAM
    lines, ``param_file``, ``overrides``, ``lenient``, ``poses``, ... as load_log takes them),
    mapped with its parameters and written to ``out_dir/NAME.FORMAT`` for each of ``formats``
    (a name of :func:`map_formats`: ``map``, ``map.gz``, ``pgm`` with its ``.yaml``, ...): the bytes log2map writes for the
    log with the same backend (the GRIDMAP; the header's time differs). ``out_dir`` is made when
    missing. A log's outputs are one transaction: all are written under temporary names beside
    them and renamed at the end, so a failed log leaves no file behind and an existing output
    untouched.

    ``backend``: as Mapper's (``auto``: as log2map's batch mode, a workload without end whose
    start-up each worker pays once, so cuda when a GPU is usable where the log is mapped, else
    cpu_threads: :func:`auto_choice` with ``expected_renders=0``); ``cuda_mode``, ``threads``,
    ``cuda_device`` and ``max_memory_bytes`` are Mapper's too (None: its defaults).

    ``executor=None`` maps the logs here, one after the other. Any
    :class:`concurrent.futures.Executor` maps them where it runs tasks: one task a log
    (``executor.submit``), each returning its :class:`LogResult`. A Dask cluster::

        from dask.distributed import Client, LocalCluster
        with LocalCluster(n_workers=4, threads_per_worker=1) as cluster, Client(cluster) as client:
            results = vg.map_logs(logs, "maps", executor=client.get_executor())

    (dask-cuda's ``LocalCUDACluster`` gives each worker its own GPU the same way), a Ray
    cluster through :class:`vasco_gpu.RayExecutor` (Ray ships no Executor; this one runs
    the tasks on long-lived actors, one mapper each, ``num_gpus=1/3`` three to a GPU)::

        with vg.RayExecutor(num_gpus=1 / 3) as ex:
            results = vg.map_logs(logs, "maps", executor=ex)

    or ``ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("spawn"))`` (spawn or
    forkserver: a process that has used CUDA must not fork). Each process keeps one Mapper,
    and so one backend and CUDA context, for all the logs it maps (``Mapper.start_over``
    between them); threads of one process take turns on it. The paths travel to the workers
    made absolute: they must see the logs and ``out_dir`` at the same place.

    Returns one :class:`LogResult` per path, in their order. A log that fails (cannot be read,
    mapped or written) is reported in its result (``ok`` False, ``error`` naming the file) and
    the others go on; with ``fail_fast=True`` the first failure stops the batch: logs not yet
    started are cancelled, those running finish, then :class:`BatchError` is raised (its
    ``results`` say what became of each log). An executor that cancels running tasks too
    (Dask's) reports them as not mapped, though a task that was past its start still writes
    its outputs, whole.

    Raises before any work: ValueError for a format that is not a name of
    :func:`map_formats` (or one named twice, or two that write one file), two logs of the same output name (``a/x.log`` and ``b/x.log.gz``), an
    unknown backend or cuda_mode, threads outside 0..1024; TypeError for a keyword load_log
    does not take; load_log's errors for its options (a missing ``param_file``, a bad override).
    """
    fmts = _check_formats(formats)
    plan = _plan(paths, out_dir, fmts)
    _check_options(backend, cuda_mode, threads, load_options)
    threads = operator.index(threads)
    os.makedirs(os.fspath(out_dir), exist_ok=True)
    # As log2map: no output may be a log, the param_file or another output.
    inputs = [p for p, _ in plan] + ([os.fspath(load_options["param_file"])] if load_options.get("param_file") else [])
    _core._check_outputs(inputs, [o for _, outputs in plan for o in outputs], replaceable=False)
    args = (backend, cuda_mode, threads, cuda_device, max_memory_bytes, load_options)

    if executor is None:
        results: List[LogResult] = []
        for i, (path, outputs) in enumerate(plan):
            r = _map_one(path, outputs, *args)
            results.append(r)
            if fail_fast and not r.ok:
                results += [_not_run(p, o, backend) for p, o in plan[i + 1:]]
                _raise_fast(r, results)
        return results

    futures: List[cf.Future] = []
    try:
        for path, outputs in plan:
            futures.append(executor.submit(_map_one, os.path.abspath(path),
                                           [os.path.abspath(o) for o in outputs], *args))
    except BaseException:
        for f in futures:
            f.cancel()
        raise
    index = {f: i for i, f in enumerate(futures)}
    got: List[Optional[LogResult]] = [None] * len(plan)
    failed: Optional[LogResult] = None

    def collect(f: cf.Future) -> LogResult:
        path, outputs = plan[index[f]]
        if f.cancelled():
            return _not_run(path, outputs, backend)
        try:
            r = f.result()
        except Exception as e:
            return _lost(path, outputs, backend, e)
        # The caller's spelling of the paths, not the absolute ones the task was given.
        return dataclasses.replace(r, path=path, outputs=list(outputs))

    for f in cf.as_completed(futures):
        i = index[f]
        got[i] = collect(f)
        if fail_fast and not got[i].ok:
            failed = got[i]
            for g in futures:
                g.cancel()
            cf.wait(futures)
            break
    results = [r if r is not None else collect(futures[i]) for i, r in enumerate(got)]
    if failed is not None:
        _raise_fast(failed, results)
    return results
