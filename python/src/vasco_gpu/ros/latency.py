"""The node's latency statistics, bounded: a node runs for days, and a list of every Path's and
every scan's milliseconds grows without end (about 100 MB a day at 10 Hz Paths, far more at
1 kHz scans), outside max_memory. A reservoir keeps a uniform sample of fixed size instead
(Vitter's algorithm R): the exit summary's percentiles are exact up to CAPACITY values and a
sample's estimate beyond (p50's standard error is about 0.8 % of the ranks at 4,096)."""

from __future__ import annotations

import random

import numpy as np

__all__ = ["CAPACITY", "Reservoir", "percentiles_text", "steps_text"]

CAPACITY = 4096  # values kept: 32 KiB a statistic


class Reservoir:
    """Milliseconds seen (len: how many), a uniform sample of them kept (values())."""

    def __init__(self, capacity: int = CAPACITY, seed: int = 0):
        self.capacity = capacity
        self._kept = np.empty(capacity)
        self._seen = 0
        self._rng = random.Random(seed)  # seeded: a run's summary does not vary by chance alone

    def append(self, ms: float) -> None:
        if self._seen < self.capacity:
            self._kept[self._seen] = ms
        else:
            k = self._rng.randrange(self._seen + 1)
            if k < self.capacity:
                self._kept[k] = ms
        self._seen += 1

    def __len__(self) -> int:
        return self._seen

    def values(self) -> np.ndarray:
        """The sample: every value while at most capacity were seen."""
        return self._kept[:min(self._seen, self.capacity)]


def percentiles_text(what: str, ms: Reservoir) -> str:
    """"; what: p50 X ms, p99 Y ms (n)" of a reservoir of milliseconds; "" for none."""
    if not len(ms):
        return ""
    p50, p99 = np.percentile(ms.values(), [50, 99])
    return f"; {what}: p50 {p50:.2f} ms, p99 {p99:.2f} ms ({len(ms)})"


def steps_text(steps: dict, ranks: tuple) -> str:
    """"name P/P, ..." of named reservoirs (a Path's or a batch's steps) at the percentile ranks,
    those without a value left out."""
    return ", ".join(f"{k} " + "/".join(f"{np.percentile(v.values(), r):.2f}" for r in ranks)
                     for k, v in steps.items() if len(v))
