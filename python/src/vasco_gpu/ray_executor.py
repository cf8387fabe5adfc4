"""RayExecutor: a :class:`concurrent.futures.Executor` on a fixed set of long-lived Ray actors.

Ray ships no ``concurrent.futures.Executor``; this one lets :func:`vasco_gpu.map_logs` (and
anything else that takes an Executor) run on a Ray cluster::

    import vasco_gpu as vg
    from vasco_gpu.ray_executor import RayExecutor   # or vg.RayExecutor

    with RayExecutor(num_gpus=1 / 3) as ex:          # three mappers per GPU
        results = vg.map_logs(logs, "maps", executor=ex)

Each actor is one Ray worker process that lives as long as the executor: ``map_logs``' tasks
keep one Mapper (and CUDA context) per process, so each actor pays the backend's start-up once
for all the logs it maps. Ray is imported when an executor is made, not with ``vasco_gpu``.
"""

from __future__ import annotations

import collections
import concurrent.futures as cf
import math
import os
import socket
import threading
from typing import Any, Callable, Deque, Dict, List, Mapping, Optional, Tuple

# How long the dispatcher waits on Ray for a finished task before it looks at its queue again
# (a task submitted while it waits starts at most this late).
_POLL_SECONDS = 0.05


def actor_count(resources: Mapping[str, float], num_cpus: float = 1, num_gpus: float = 0,
                custom: Optional[Mapping[str, float]] = None) -> int:
    """How many actors asking ``num_cpus``, ``num_gpus`` and ``custom`` resources each fit in
    ``resources`` (Ray's ``available_resources()``); at least 1 (Ray holds an actor that does
    not fit until the cluster has room). An actor asking for nothing counts as needing 1 CPU."""
    wanted = {"CPU": num_cpus, "GPU": num_gpus, **dict(custom or {})}
    fits = [resources.get(name, 0.0) / amount for name, amount in wanted.items() if amount > 0]
    if not fits:
        fits = [resources.get("CPU", 0.0)]
    # 1e-9: a GPU's thirds add up to 0.999... of it in floating point.
    return max(1, math.floor(min(fits) + 1e-9))


def _fail(failed: List[Tuple[cf.Future, BaseException]]) -> None:
    for future, e in failed:
        future.set_exception(e)


class _Worker:
    """The actor's class: runs one task at a time in its own process."""

    def run(self, fn: Callable[..., Any], args: Tuple[Any, ...], kwargs: Dict[str, Any]) -> Any:
        return fn(*args, **kwargs)

    def where(self) -> str:
        return f"{socket.gethostname()}:{os.getpid()}"


def _ray():
    try:
        import ray
    except ImportError as e:
        raise ImportError("RayExecutor needs Ray: pip install 'vasco_gpu[ray]' (or ray>=2.9)") from e
    return ray


class RayExecutor(cf.Executor):
    """Runs submitted calls on ``actors`` long-lived Ray actors, one call per actor at a time.

    Args:
        actors: how many actors (worker processes); None: as many as Ray's available
            resources hold with ``num_cpus``, ``num_gpus`` (and ``resources=``) each, at
            least 1 (:func:`actor_count`).
        num_cpus: CPUs Ray reserves per actor (give ``map_logs`` ``threads=`` to match on
            the CPU backends: ``threads=0`` uses every core of the host).
        num_gpus: GPUs per actor, fractional allowed: ``1/3`` puts three actors, so three
            mappers, on each GPU. Ray sets each actor's ``CUDA_VISIBLE_DEVICES``, so its GPU is
            device 0 (``map_logs``' default ``cuda_device=0``). With 0 the actor holds no GPU
            in Ray's accounting, yet recent Ray versions leave the host's GPUs visible to it
            (older ones hid them): give ``map_logs`` a CPU backend to keep it off them.
        **actor_options: passed to the actor class's ``.options()`` (``resources=``,
            ``runtime_env=``, ``scheduling_strategy=``, ...).

    Ray not initialized in this process: ``ray.init()`` is called with its defaults, as Ray
    itself does on first use (``RAY_ADDRESS`` or a cluster started on this host with
    ``ray start``, else a new local instance); call ``ray.init(...)`` first to choose. The
    executor does not shut Ray down.

    ``submit`` queues the call; the dispatcher hands it to an idle actor. A call not yet
    handed over can be cancelled (``Future.cancel()``: ``map_logs(fail_fast=True)`` cancels
    the logs not started); one running finishes. A call that raises gives its future that
    exception (Ray's ``RayTaskError``, carrying the remote traceback, as its ``__cause__``);
    a call whose actor died gives its future Ray's ``RayActorError`` and a new actor takes
    the dead one's place. ``shutdown()`` (also at the end of a ``with`` block) runs or
    cancels what is queued, then kills the actors, releasing their mappers and CUDA contexts.
    Functions and arguments travel pickled: the actors must be able to import them (a
    module's functions, not ``__main__``'s where the cluster has other hosts).
    """

    def __init__(self, actors: Optional[int] = None, *, num_cpus: float = 1, num_gpus: float = 0,
                 **actor_options: Any) -> None:
        ray = self._ray = _ray()
        if actors is not None and (isinstance(actors, bool) or int(actors) != actors or actors < 1):
            raise ValueError(f"RayExecutor: actors {actors!r}: expected a whole number >= 1, or None")
        if not ray.is_initialized():
            ray.init()
        self._options = dict(actor_options, num_cpus=num_cpus, num_gpus=num_gpus)
        self._actor_class = ray.remote(_Worker)
        if actors is None:
            actors = actor_count(ray.available_resources(), num_cpus, num_gpus, actor_options.get("resources"))
        self._lock = threading.Condition()
        self._queue: Deque[Tuple[cf.Future, Callable[..., Any], Tuple[Any, ...], Dict[str, Any]]] = \
            collections.deque()
        self._running: Dict[Any, Tuple[cf.Future, Any]] = {}  # ObjectRef -> (future, actor)
        self._actors: List[Any] = []
        try:
            for _ in range(int(actors)):
                self._actors.append(self._new_actor())
        except BaseException:
            self._kill_actors()  # those made before the failure: no actor outlives a failed constructor
            raise
        self._idle: List[Any] = list(self._actors)
        self._closing = False
        self._dispatcher = threading.Thread(target=self._dispatch, name="RayExecutor", daemon=True)
        self._dispatcher.start()

    @property
    def actors(self) -> int:
        """How many actors the executor runs."""
        return len(self._actors)

    def where(self) -> List[str]:
        """``"HOST:PID"`` of each actor's process (waits for each to start and end its call)."""
        return self._ray.get([a.where.remote() for a in list(self._actors)])

    def _new_actor(self):
        return self._actor_class.options(**self._options).remote()

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> cf.Future:
        with self._lock:
            if self._closing:
                raise RuntimeError("RayExecutor: cannot submit after shutdown")
            future: cf.Future = cf.Future()
            self._queue.append((future, fn, args, kwargs))
            failed = self._start_queued()  # an idle actor takes it now, not at the dispatcher's next look
            self._lock.notify()
        _fail(failed)
        return future

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        with self._lock:
            self._closing = True
            if cancel_futures:
                while self._queue:
                    self._queue.popleft()[0].cancel()
            self._lock.notify()
        if wait:
            self._dispatcher.join()

    # -----------------------------------------------------------------------------------------
    # The dispatcher thread: hands queued calls to idle actors and settles finished ones.

    def _dispatch(self) -> None:
        try:
            while True:
                with self._lock:
                    failed = self._start_queued()
                    done = self._closing and not self._queue and not self._running
                    refs = list(self._running)
                    if not refs and not done and not failed:
                        self._lock.wait(1.0)  # submit and shutdown wake it
                _fail(failed)
                if done:
                    return
                if not refs:
                    continue
                ready, _ = self._ray.wait(refs, num_returns=1, timeout=_POLL_SECONDS, fetch_local=False)
                for ref in ready:
                    self._settle(ref)
        except BaseException as e:
            self._fail_all(e)  # Ray gone under it: no call may wait for ever
            raise
        finally:
            self._kill_actors()

    def _fail_all(self, e: BaseException) -> None:
        with self._lock:
            self._closing = True
            pending = [item[0] for item in self._queue] + [f for f, _ in self._running.values()]
            self._queue.clear()
            self._running.clear()
        for future in pending:
            if future.done():
                continue
            if future.running() or future.set_running_or_notify_cancel():
                future.set_exception(e)

    def _start_queued(self) -> List[Tuple[cf.Future, BaseException]]:
        """Hands queued calls to idle actors; called with the lock held. Returns the calls
        that could not be handed over, for the caller to fail once it released the lock (a
        future's done-callbacks run where its result is set, and may submit or shut down)."""
        failed = []
        while self._queue and self._idle:
            future, fn, args, kwargs = self._queue.popleft()
            if not future.set_running_or_notify_cancel():
                continue  # cancelled while queued
            actor = self._idle.pop()
            try:
                ref = actor.run.remote(fn, args, kwargs)
            except BaseException as e:  # e.g. an argument that cannot be pickled
                self._idle.append(actor)
                failed.append((future, e))
                continue
            self._running[ref] = (future, actor)
        return failed

    def _settle(self, ref) -> None:
        ray = self._ray
        with self._lock:
            future, actor = self._running.pop(ref)
        try:
            result = ray.get(ref)
        except ray.exceptions.RayActorError as e:
            try:
                self._replace(actor)
            finally:  # the future is no longer in _running: it must be settled here, whatever happens
                future.set_exception(e)
            return
        except ray.exceptions.RayTaskError as e:
            cause = e.cause if isinstance(e.cause, BaseException) else e
            if cause is not e and cause.__cause__ is None:
                cause.__cause__ = e  # the remote traceback, as ProcessPoolExecutor chains it
            self._back(actor)
            future.set_exception(cause)
            return
        except BaseException as e:
            self._back(actor)
            future.set_exception(e)
            return
        self._back(actor)
        future.set_result(result)

    def _back(self, actor) -> None:
        with self._lock:
            self._idle.append(actor)

    def _replace(self, dead) -> None:
        try:
            self._ray.kill(dead, no_restart=True)
        except Exception:
            pass  # already gone
        with self._lock:
            self._actors.remove(dead)
            if self._closing and not self._queue:
                return
            fresh = self._new_actor()
            self._actors.append(fresh)
            self._idle.append(fresh)

    def _kill_actors(self) -> None:
        with self._lock:
            actors, self._actors, self._idle = list(self._actors), [], []
        for actor in actors:
            try:
                self._ray.kill(actor, no_restart=True)
            except Exception:
                pass  # Ray shut down first, or the actor is gone
