"""sensor_msgs/LaserScan and MultiEchoLaserScan (one echo a beam) as the mapper's scan: its
frame, beam geometry and ranges by REP 117. The one adapter of bags and the live node (beside
:mod:`.cloud` for PointCloud2).

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
from dataclasses import dataclass

import numpy as np

from .header import frame_name
from .scan_options import ScanSettings

__all__ = ["ANGLES_OFF", "COUNT_KEYS", "LaserReading", "NO_RETURN_FREE", "angle_check", "apply_rep117", "read_laser",
           "read_laser_scan", "read_multi_echo"]

#: The range stored for a +inf reading with ``no_return="free"``: the largest float32 below 50.
NO_RETURN_FREE = np.nextafter(np.float32(50.0), np.float32(0.0))

COUNT_KEYS = ("messages", "nan", "pos_inf", "neg_inf", "below_min", "above_max")


def apply_rep117(v: np.ndarray, rmin: float, rmax: float, no_return: str, counts: dict) -> np.ndarray:
    """A float32 copy of one scan's ranges after the policy in the module docstring; counts updated."""
    out = np.asarray(v).astype(np.float32, copy=True)
    # the beams not finite or outside [range_min, range_max] first (an infinite range_max does
    # not take +inf in), then what each of those few is: a live node reads 40 scans a second
    bad = np.flatnonzero(~(np.isfinite(out) & (out >= rmin) & (out <= rmax)))
    if len(bad) == 0:
        return out
    b = out[bad]
    finite = np.isfinite(b)
    nan, pos, neg = np.isnan(b), b == np.inf, b == -np.inf
    below, above = finite & (b < rmin), finite & (b > rmax)
    masks = {"nan": nan, "pos_inf": pos, "neg_inf": neg, "below_min": below, "above_max": above}
    for key, mask in masks.items():
        counts[key] += int(mask.sum())
    out[bad[~pos]] = np.nan  # +inf (no return) stays, or becomes a free beam's range
    if no_return == "free":
        out[bad[pos]] = NO_RETURN_FREE
    return out


def pick_echoes(msg, echo: str, fail) -> np.ndarray:
    """One range a beam of a sensor_msgs/MultiEchoLaserScan, as float32: its first or last echo,
    or the echo of the largest intensity ("strongest"; ties: the first). A beam without an echo
    is +inf (REP 117: no return). fail(what) gives the BagError to raise."""
    echoes = [np.asarray(e.echoes, dtype=np.float32).ravel() for e in msg.ranges]
    n = len(echoes)
    lens = np.fromiter((len(e) for e in echoes), dtype=np.int64, count=n)
    out = np.full(n, np.inf, dtype=np.float32)
    has = lens > 0
    if not has.any():
        return out
    flat = np.concatenate(echoes)
    starts = np.concatenate([[0], np.cumsum(lens)[:-1]])
    if echo == "first":
        out[has] = flat[starts[has]]
    elif echo == "last":
        out[has] = flat[starts[has] + lens[has] - 1]
    else:
        power = [np.asarray(e.echoes, dtype=np.float64).ravel() for e in msg.intensities]
        if not power:
            raise fail("has no intensities: echo 'strongest' (--echo strongest) needs them; take the first "
                       "or last echo instead")
        plens = np.fromiter((len(e) for e in power), dtype=np.int64, count=len(power))
        if len(power) != n or not np.array_equal(plens, lens):
            raise fail(f"has intensities for {int(plens.sum())} echoes of {len(power)} beams, ranges for "
                       f"{int(lens.sum())} echoes of {n} beams: echo 'strongest' needs one intensity an echo")
        p = np.concatenate(power)
        p = np.where(np.isnan(p), -np.inf, p)
        seg = starts[has]
        best = np.maximum.reduceat(p, seg) if len(p) else p
        index = np.arange(len(p))
        first_best = np.where(p == np.repeat(best, lens[has]), index, len(p))
        out[has] = flat[np.minimum.reduceat(first_best, seg)]
    return out


@dataclass
class LaserReading:
    """One laser message as the mapper takes it: its frame, beam geometry, maximum range and
    float32 ranges after the range policy (module docstring)."""

    frame: str
    first_angle: float
    angle_step: float
    range_max: float
    ranges: np.ndarray


# The most beams a scan may have: a CARMEN log line's limit on a count (carmen::kMaxCount in
# carmen_compat/log_reader.h, which log2map and the mapper's Scans enforce). Checked as the
# message is read, so that the error names the bag, topic and stamp, and bag2carmen never
# writes a line that log2map refuses.
MAX_BEAMS = 100_000

# How far len(ranges) may be from the beam count that angle_min, angle_max and angle_increment
# imply, (angle_max - angle_min) / angle_increment + 1, before the message is refused. Drivers
# compute angle_max in float32, from the device's nominal field of view, or count one beam more
# or less at an edge; and some give a nominal increment rounded to a few digits, whose error
# grows with the count: velodyne_laserscan publishes 897 ranges with angle_min -3.14159274,
# angle_max 3.14159274 and increment 0.00700000022 (2 pi / 897 is 0.0070048), 898.6 beams by
# the angles. Such a scan is what RViz and laser_geometry draw, beam i at angle_min + i *
# angle_increment, and so is it taken here (with a warning, once a topic: the ANGLES_OFF count).
# The bound is BEAM_COUNT_SLACK beams or BEAM_COUNT_FRACTION of the count, whichever is more:
# 2 % holds a nominal increment given to three digits (0.07 % off for the velodyne scan, 1.6
# beams) many times over, while a scan whose ranges are not those angles' (truncated, or of
# another configuration: 180 ranges for 201 beams is 10 % off) is well beyond it.
BEAM_COUNT_SLACK = 1.5
BEAM_COUNT_FRACTION = 0.02
# Within this many beams the count is the angles' own, give or take float32 rounding: no warning.
BEAM_COUNT_EXACT = 0.5
#: The counts key of the scans taken although angle_max disagrees with len(ranges).
ANGLES_OFF = "angles_off"


def angle_check(n: int, a0: float, a1: float, da: float) -> str | None:
    """None for a scan whose n ranges fit its angles; "off" for one that fits within the bounds
    above (taken, with a warning); else why it cannot be a scan (a refusal naming the numbers)."""
    if da == 0 or not math.isfinite(a1) or n == 0:
        return None
    implied = (a1 - a0) / da + 1
    numbers = f"angle_min {a0:.9g} to angle_max {a1:.9g} by {da:.9g} makes {implied:.1f} beams"
    # One turn and one step: a full circle's scan may repeat its first angle at the end, no more.
    turn = 2 * math.pi + abs(da)
    if (n - 1) * abs(da) > turn or abs(a1 - a0) > turn:
        return (f"has {n} ranges, but angle_min {a0:.9g} by {da:.9g} spans {(n - 1) * abs(da):.4f} rad for them "
                f"and angle_max {a1:.9g} {abs(a1 - a0):.4f} rad, more than a turn and a step "
                f"({turn:.4f} rad): not one scan")
    off = abs(implied - n)
    if off <= BEAM_COUNT_EXACT:
        return None
    if off > max(BEAM_COUNT_SLACK, BEAM_COUNT_FRACTION * n):
        return (f"has {n} ranges, but {numbers} ({100 * off / n:.1f} % off, more than the "
                f"{100 * BEAM_COUNT_FRACTION:g} % or {BEAM_COUNT_SLACK:g} beams that rounding explains)")
    return "off"


def read_laser(msg, *, no_return: str, counts: dict, fail, echo: str | None = None) -> LaserReading:
    """A sensor_msgs/LaserScan (or, with echo, a MultiEchoLaserScan: that echo a beam) as a
    LaserReading. counts (COUNT_KEYS) are updated; fail(what) gives the exception to raise for a
    message that cannot be mapped, naming what."""
    rmin, rmax = float(msg.range_min), float(msg.range_max)
    if not rmin <= rmax:
        raise fail(f"has range_min {rmin!r} > range_max {rmax!r}")
    a0, da = float(msg.angle_min), float(msg.angle_increment)
    if not (math.isfinite(a0) and math.isfinite(da)):
        raise fail(f"has angle_min {a0!r}, angle_increment {da!r}")
    n = len(msg.ranges)
    if n > MAX_BEAMS:
        raise fail(f"has {n} beams, more than the {MAX_BEAMS} a CARMEN log line and the mapper take")
    raw = msg.ranges if echo is None else pick_echoes(msg, echo, fail)
    a1 = float(getattr(msg, "angle_max", math.nan))
    why = angle_check(n, a0, a1, da)
    if why == "off":  # beam i at a0 + i * da, as RViz and laser_geometry take it
        counts[ANGLES_OFF] = counts.get(ANGLES_OFF, 0) + 1
    elif why is not None:
        raise fail(why)
    r = apply_rep117(raw, rmin, rmax, no_return, counts)
    counts["messages"] += 1
    return LaserReading(frame_name(msg.header.frame_id), a0, da, rmax, r)


# The message table's readers (table.py): (msg, ScanSettings, counts, fail, mount) -> LaserReading.

def read_laser_scan(msg, settings: ScanSettings, counts: dict, fail, mount=None) -> LaserReading:
    """A sensor_msgs/LaserScan; options: no_return."""
    return read_laser(msg, no_return=settings.no_return, counts=counts, fail=fail)


def read_multi_echo(msg, settings: ScanSettings, counts: dict, fail, mount=None) -> LaserReading:
    """A sensor_msgs/MultiEchoLaserScan, one echo a beam; options: no_return, echo."""
    return read_laser(msg, no_return=settings.no_return, counts=counts, fail=fail, echo=settings.echo)
