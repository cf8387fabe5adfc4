"""sensor_msgs/LaserScan messages into the mapper's arrays, ranges by REP 117; BagScans, the
scans of one topic with their poses.

Range policy: REP 117 readings turned into CARMEN's semantics
---------------------------------------------------------------
CARMEN's mapper uses a beam only if its range is < 50.0 m (a float compare) and skips every
other beam entirely (NaN and +inf included). A beam below 50 m but beyond the mapper's
``range_max`` (``vasco_range_max``) clears free space up to ``range_max`` and marks no hit.
With ``v`` a value of ``msg.ranges`` (float32), ``rmin = msg.range_min``,
``rmax = msg.range_max``:

=============================  ==========================  ==============  ==============
reading ``v``                  meaning (REP 117)           stored          counted as
=============================  ==========================  ==============  ==============
finite, rmin <= v <= rmax      a hit                       v, bit for bit  (not counted)
NaN                            erroneous reading           NaN (skipped)   ``nan``
-inf                           object too close            NaN (skipped)   ``neg_inf``
finite, v < rmin               invalid                     NaN (skipped)   ``below_min``
finite, v > rmax               invalid                     NaN (skipped)   ``above_max``
+inf, ``no_return="skip"``     no return within range      +inf (skipped)  ``pos_inf``
+inf, ``no_return="free"``     no return within range      49.999996       ``pos_inf``
=============================  ==========================  ==============  ==============

``no_return="skip"`` (the default) is CARMEN's own treatment of max-range readings: they clear
nothing. ``no_return="free"`` stores the largest float32 below 50.0
(``np.nextafter(np.float32(50), np.float32(0))``), which the mapper treats as "free up to
range_max, no hit" — what ROS mappers (gmapping, slam_toolbox) do with "no return". A finite
``v > rmax`` stays invalid in both modes: the sensor says the value is not a measurement.
"""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass

import numpy as np

from .errors import BagError
from .header import frame_name, stamp_ns, stamp_seconds, stamp_text

__all__ = ["BagScans", "NO_RETURN_FREE"]

#: The range stored for a +inf reading with ``no_return="free"``: the largest float32 below 50.
NO_RETURN_FREE = np.nextafter(np.float32(50.0), np.float32(0.0))

NO_RETURN_MODES = ("skip", "free")
COUNT_KEYS = ("messages", "nan", "pos_inf", "neg_inf", "below_min", "above_max")


@dataclass
class BagScans:
    """The scans of one LaserScan topic with the laser pose at each, ready for the mapper.

    Scan ``s`` has ``beam_counts[s]`` beams, stored in ``ranges`` from
    ``beam_counts[:s].sum()``; beam ``i`` points at ``first_angle[s] + i * angle_step[s]`` in
    the laser frame. ``poses`` is the laser pose in the fixed frame, ``mounts`` the laser pose
    in the base frame. ``range_max`` (an addition to the interface, per scan ``msg.range_max``)
    is what :func:`write_carmen_log` writes as the device's maximum range.
    """

    path: str
    topic: str
    frame_id: str
    stamps: np.ndarray
    poses: np.ndarray
    mounts: np.ndarray | None
    ranges: np.ndarray
    beam_counts: np.ndarray
    first_angle: np.ndarray
    angle_step: np.ndarray
    counts: dict
    pose_source: str
    range_max: np.ndarray | None = None


def apply_rep117(v: np.ndarray, rmin: float, rmax: float, no_return: str, counts: dict) -> np.ndarray:
    """A float32 copy of one scan's ranges after the policy in the module docstring; counts updated."""
    out = np.asarray(v).astype(np.float32, copy=True)
    finite = np.isfinite(out)
    if finite.all() and (out >= rmin).all() and (out <= rmax).all():
        return out
    nan = np.isnan(out)
    pos = out == np.inf
    neg = out == -np.inf
    below = finite & (out < rmin)
    above = finite & (out > rmax)
    masks = {"nan": nan, "pos_inf": pos, "neg_inf": neg, "below_min": below, "above_max": above}
    for key, mask in masks.items():
        counts[key] += int(mask.sum())
    out[nan | neg | below | above] = np.nan
    if no_return == "free":
        out[pos] = NO_RETURN_FREE
    return out


class ScanAccumulator:
    """Collects the scans of the chosen topic in bag order, applying the range policy."""

    def __init__(self, path, topic: str, no_return: str):
        self.path, self.topic, self.no_return = path, topic, no_return
        self.frame_id: str | None = None
        self.ns = array("q")
        self.first_angle = array("d")
        self.angle_step = array("d")
        self.range_max = array("d")
        self.beam_counts = array("q")
        self.ranges: list[np.ndarray] = []
        self.counts = dict.fromkeys(COUNT_KEYS, 0)

    def _error(self, ns: int, what: str) -> BagError:
        """A BagError about the scan at stamp ns."""
        return BagError(self.path, f"scan at stamp {stamp_text(ns)} on {self.topic!r} {what}",
                        topic=self.topic, stamp=stamp_seconds(ns))

    def add(self, msg) -> None:
        ns = stamp_ns(msg.header.stamp)
        frame = frame_name(msg.header.frame_id)
        if self.frame_id is None:
            self.frame_id = frame
        elif frame != self.frame_id:
            raise self._error(ns, f"is in frame {frame!r}, the first scan in {self.frame_id!r}; all scans "
                                  "of a topic must share their frame")
        rmin, rmax = float(msg.range_min), float(msg.range_max)
        if not rmin <= rmax:
            raise self._error(ns, f"has range_min {rmin!r} > range_max {rmax!r}")
        a0, da = float(msg.angle_min), float(msg.angle_increment)
        if not (math.isfinite(a0) and math.isfinite(da)):
            raise self._error(ns, f"has angle_min {a0!r}, angle_increment {da!r}")
        r = apply_rep117(msg.ranges, rmin, rmax, self.no_return, self.counts)
        self.ns.append(ns)
        self.first_angle.append(a0)
        self.angle_step.append(da)
        self.range_max.append(rmax)
        self.beam_counts.append(len(r))
        self.ranges.append(r)
        self.counts["messages"] += 1
