"""Samples over time (tf links, pose topics): sorted by stamp, and stamps located among them."""

from __future__ import annotations

from array import array

import numpy as np


def sorted_samples(ns: array, values: array, width: int):
    """(stamps (k,), values (k, width)) of samples recorded in any order, sorted by stamp, with
    one sample per stamp (the last one recorded for a repeated stamp)."""
    times = np.frombuffer(ns, dtype=np.int64)
    vals = np.frombuffer(values, dtype=np.float64).reshape(-1, width)
    if (times[1:] > times[:-1]).all():  # already sorted, one a stamp (a Path's usual order)
        return times.copy(), vals.copy()  # copies: a view would keep an array.array from growing
    order = np.argsort(times, kind="stable")
    times, vals = times[order], vals[order]
    keep = np.append(times[1:] != times[:-1], True)
    return times[keep], vals[keep]


def first_outside(times: np.ndarray, ns: np.ndarray) -> int | None:
    """The first of the stamps ns outside [times[0], times[-1]], or None."""
    outside = (ns < times[0]) | (ns > times[-1])
    return int(ns[np.argmax(outside)]) if outside.any() else None


def bracket(times: np.ndarray, ns: np.ndarray):
    """(hit, hit index, lo, hi, fraction) locating stamps ns (within the span) among sorted
    times: an exact hit at times[index], else between times[lo] and times[hi] at fraction f."""
    i = np.searchsorted(times, ns, side="left")
    hit = times[i] == ns
    lo, hi = np.maximum(i - 1, 0), i
    span = (times[hi] - times[lo]).astype(np.float64)
    f = np.where(hit, 0.0, (ns - times[lo]).astype(np.float64) / np.where(span == 0, 1.0, span))
    return hit, i, lo, hi, f
