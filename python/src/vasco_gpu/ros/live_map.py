"""LiveMap: the node's mapping session. Every scan it is given stays stored (its ranges in the
Mapper only, also on the GPU for cuda; its stamp, pose and mount here); a Path of base poses moves
every stored scan in its span and the whole grid is rendered again. No rclpy here: the node
feeds it, and the tests drive it directly too.

Exactness: an exact backend's grid equals a fresh map of the stored scans after every
``render``; scans inserted one by one give the same bytes while the grid keeps its size, and a
grid that grew renders in a frame with a margin that differs from a fresh map's in a few cells
(docs/sessions.md). ``settle()`` renders the stored poses again when the grid grew since the
last full render, so that a quiet stream ends in the fresh map's bytes (log2map's).
"""

from __future__ import annotations

import math
from array import array

import numpy as np

from .. import _core
from .._errors import Error
from .grid import finished_grid

__all__ = ["LiveMap", "LiveMapError"]

# Bytes stored here per scan besides its ranges: stamp, pose (3), mount (3), first angle, step.
_SCAN_BYTES = 8 * 9

# LiveMap.reach's boxes: every cell may have changed (a render), and none has.
EVERYWHERE = (-math.inf, -math.inf, math.inf, math.inf)
NOWHERE = (math.inf, math.inf, -math.inf, -math.inf)

# The session's host-memory budget by default, in bytes (vasco_gpu/option_schema.h).
_DEFAULT_MAX_MEMORY = next(row["default"] for row in _core.option_schema("session") if row["name"] == "max_memory")


class LiveMapError(Error, RuntimeError):
    """A scan or render the session refused (memory, a frame too large); the session is as before."""


class LiveMap:
    """A Mapper plus what the node needs to move and re-render its scans.

    ``add`` stores one scan at its laser pose (with its mount in the base frame, when known, so a
    Path of base poses can move it); ``repose`` applies a Path; ``set_params`` re-renders every
    stored scan with new mapper parameters; ``finish`` gives the map to publish; ``restore`` maps a
    saved session (session_file) into a new one. ``frame`` (a fixed grid) and ``frame_centre``
    go to the Mapper only when given. ``reach``: a world box (x0, y0, x1, y1) that holds every
    cell changed since ``clear_reach`` (EVERYWHERE after a render): the publication compares
    only those cells with the map it sent."""

    def __init__(self, params: _core.Params, *, backend: str = "auto", cuda_mode: str = "float",
                 device: int = 0, threads: int = 0, max_memory: int = _DEFAULT_MAX_MEMORY,
                 frame: _core.Frame | None = None, frame_centre=None):
        self.max_memory = int(max_memory)
        # What the session was asked for (a saved session carries it: session_file); max_memory
        # is read from the attribute, which a caller may lower.
        self.options = {"backend": backend, "cuda_mode": cuda_mode, "device": int(device), "threads": int(threads)}
        # A fixed grid: passed only when given, so a Mapper without these keywords still works
        # for every caller that gives none.
        fixed = {k: v for k, v in (("frame", frame), ("frame_centre", frame_centre)) if v is not None}
        # cuda_mode and device are ignored by the CPU backends. A live map is a workload without
        # end (expected_renders=0): auto weighs the GPU's start-up against no known amount of work.
        self.mapper = _core.Mapper(params, backend=backend, cuda_mode=cuda_mode, threads=threads, cuda_device=device,
                                   max_memory_bytes=self.max_memory, expected_renders=0, **fixed)
        self.version = 0  # changes whenever the grid does
        self._clear()

    def _clear(self) -> None:
        self.stamps = array("q")
        self.poses = array("d")   # laser x, y, theta per scan
        self.mounts = array("d")  # laser in base x, y, yaw per scan; NaN: unknown
        self.first_angle = array("d")
        self.angle_step = array("d")
        self.beam_counts = array("q")
        self.bytes = 0
        self._renders_settled = self.mapper.renders
        self.reach = EVERYWHERE

    def __len__(self) -> int:
        return len(self.stamps)

    @property
    def backend(self) -> str:
        return self.mapper.backend

    def add(self, stamp_ns: int, pose, ranges: np.ndarray, first_angle: float, angle_step: float,
            mount=None) -> None:
        """Stores one scan at laser pose (x, y, theta) and applies it to the grid; LiveMapError
        (nothing stored) when max_memory would be exceeded or the mapper refuses it."""
        self.add_many([stamp_ns], [pose], [ranges], [first_angle], [angle_step], [mount])

    def add_many(self, stamps_ns, poses, ranges, first_angles, angle_steps, mounts) -> None:
        """Stores k scans (a list or array of k of each; a mount None: unknown) and applies them
        to the grid in one insert, in their order; LiveMapError (none stored) when max_memory
        would be exceeded or the mapper refuses them."""
        ranges = [np.ascontiguousarray(r, dtype=np.float32) for r in ranges]
        more = sum(r.nbytes for r in ranges) + _SCAN_BYTES * len(ranges)
        if self.max_memory and self.bytes + more > self.max_memory:
            raise LiveMapError(f"max_memory {self.max_memory} bytes reached: {len(self)} scans stored "
                               f"({self.bytes} bytes of ranges and poses, the grid besides)")
        poses = np.asarray(poses, dtype=np.float64).reshape(-1, 3)
        counts = [len(r) for r in ranges]
        scans = _core.Scans(poses, ranges[0] if len(ranges) == 1 else np.concatenate(ranges), counts,
                            np.asarray(first_angles, dtype=np.float64), np.asarray(angle_steps, dtype=np.float64))
        renders = self.mapper.renders
        try:
            self.mapper.insert(scans)
        except (RuntimeError, MemoryError) as e:
            raise LiveMapError(str(e)) from None
        finally:  # a refused insert that grew the grid rendered the stored scans again
            self._reached(poses if self.mapper.renders == renders else None)
        self.stamps.extend(int(ns) for ns in stamps_ns)
        self.poses.frombytes(poses.tobytes())
        for m in mounts:
            self.mounts.extend((np.nan,) * 3 if m is None else (float(v) for v in m))
        self.first_angle.extend(float(a) for a in first_angles)
        self.angle_step.extend(float(a) for a in angle_steps)
        self.beam_counts.extend(counts)
        self.bytes += more
        self.version += 1

    def _reached(self, poses) -> None:
        """Widens ``reach`` by the cells scans at laser poses (k, 3) can change: those within
        range_max of a laser's cell (egrid_math.h's sensor model stops a beam there), two fine
        cells of margin; poses None: a render, every cell."""
        if poses is None:
            self.reach = EVERYWHERE
            return
        p = self.mapper.params
        r = p.range_max + 2 * p.resolution
        x, y = poses[:, 0], poses[:, 1]
        b = self.reach
        self.reach = (min(b[0], float(x.min()) - r), min(b[1], float(y.min()) - r),
                      max(b[2], float(x.max()) + r), max(b[3], float(y.max()) + r))

    def clear_reach(self) -> None:
        """The grid as it is now was published: ``reach`` starts again from no cell."""
        self.reach = NOWHERE

    def restore(self, saved) -> None:
        """Stores a saved session's scans (session_file.load_session's SavedSession: stamps,
        laser poses, mounts, angles, ranges) in one insert, mapped with the saved mapper
        parameters, so that the grid is a fresh map of them: log2map's map of the saved file, and
        the saved LiveMap's own finish when it was settled (or last rendered) before the save.
        Only into a LiveMap that stores no scan; LiveMapError (nothing changed) otherwise, or
        when max_memory or the mapper refuses the scans."""
        if len(self):
            raise LiveMapError(f"restore: this session already stores {len(self)} scans; restore into a new one")
        old = self.mapper.params
        if saved.params.to_dict() != old.to_dict():
            self.set_params(saved.params)
        if len(saved) == 0:
            return
        ranges = np.split(saved.ranges, np.cumsum(saved.beam_counts)[:-1])
        try:
            self.add_many(saved.stamps, saved.poses, ranges, saved.first_angle, saved.angle_step, saved.mounts)
        except LiveMapError:
            if saved.params.to_dict() != old.to_dict():
                self.set_params(old)
            raise

    def stored_ranges(self) -> np.ndarray:
        """Every stored scan's ranges, float32, scan after scan: a copy of the Mapper's."""
        return self.mapper._stored_ranges()

    def _pose_array(self) -> np.ndarray:
        return np.frombuffer(self.poses, dtype=np.float64).reshape(-1, 3)

    def repose(self, stamps_ns, base_poses, max_gap_ns: int) -> dict:
        """A Path: base poses (k, 3) at stamps (k,). Every stored scan with a mount whose stamp
        lies within the Path's span, between two poses at most max_gap_ns apart (or on one),
        gets the interpolated base pose (linear x, y, shortest-arc yaw, as --poses interpolates)
        composed with its mount; then the whole grid is rendered. Returns counts: moved, outside
        (before or after the span), in_gap, no_mount."""
        counts = {"moved": 0, "outside": 0, "in_gap": 0, "no_mount": 0}
        if len(self) == 0 or len(stamps_ns) == 0:
            return counts
        # one C++ call (vasco_gpu/pose_series.h): in NumPy it took some 40 calls, each costing a
        # live node several times what it costs in a loop (fr079's Path: ~1.5 ms of the node's
        # 2.5 ms repose on the H100 machine)
        poses = self._pose_array().copy()
        mounts = np.frombuffer(self.mounts, dtype=np.float64).reshape(-1, 3)
        moved, outside, in_gap, no_mount = _core._repose(stamps_ns, base_poses, self.stamps, mounts, poses, max_gap_ns)
        counts.update(moved=moved, outside=outside, in_gap=in_gap, no_mount=no_mount)
        if moved or in_gap:
            self.render(poses)
        return counts

    def render(self, poses: np.ndarray) -> None:
        """Every stored scan at new laser poses (n, 3), the grid recomputed."""
        try:
            self.mapper.render(poses)
        except (RuntimeError, MemoryError) as e:
            raise LiveMapError(str(e)) from None
        self.poses = array("d")
        self.poses.frombytes(np.ascontiguousarray(poses, dtype=np.float64).tobytes())
        self._renders_settled = self.mapper.renders
        self.reach = EVERYWHERE
        self.version += 1

    def settle(self) -> bool:
        """Renders the stored poses again if the grid grew since the last full render (see the
        module docstring); True if it did."""
        if len(self) == 0 or self.mapper.renders == self._renders_settled:
            return False
        self.render(self._pose_array().copy())
        return True

    def set_params(self, params: _core.Params) -> None:
        """New mapper parameters: every stored scan mapped again with them (validated first: a
        refusal changes nothing)."""
        params.validate()
        old = self.mapper.params
        # the ranges live in the Mapper only: copied out before start_over drops them (twice
        # the ranges for the length of this call, once again after it)
        scans = None if len(self) == 0 else _core.Scans(
            self._pose_array(), self.stored_ranges(),
            np.frombuffer(self.beam_counts, dtype=np.int64).astype(np.float64),
            np.frombuffer(self.first_angle, dtype=np.float64), np.frombuffer(self.angle_step, dtype=np.float64))
        self.reach = EVERYWHERE
        self.mapper.start_over(params)
        if scans is None:
            self.version += 1
            self._renders_settled = self.mapper.renders
            return
        try:
            self.mapper.insert(scans)
        except (RuntimeError, MemoryError) as e:
            self.mapper.start_over(old)
            self.mapper.insert(scans)
            raise LiveMapError(str(e)) from None
        self._renders_settled = self.mapper.renders
        self.version += 1

    def reset(self) -> int:
        """Drops every stored scan and the grid; returns how many scans were dropped."""
        n = len(self)
        self.mapper.start_over(self.mapper.params)
        self._clear()
        self.version += 1
        return n

    def finish(self) -> _core.Map | None:
        """The map to publish (CARMEN's finish of the grid), None while no scan is stored."""
        if len(self) == 0:
            return None
        return self.mapper.finish()

    def finish_grid(self, mode: str, free_thresh: float, occupied_thresh: float, out=None):
        """The map to publish as OccupancyGrid data, ((size_x, size_y, resolution, origin), data)
        (grid.finished_grid: on the GPU for cuda), None while no scan is stored."""
        if len(self) == 0:
            return None
        return finished_grid(self.mapper, mode, free_thresh, occupied_thresh, out)
