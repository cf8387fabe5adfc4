"""The node's latency statistics stay bounded (latency.py): a reservoir of fixed size, exact
percentiles while it holds every value, a uniform sample after."""

import numpy as np

from vasco_gpu.ros.latency import Reservoir


def test_every_value_while_it_fits():
    r = Reservoir(capacity=8)
    for v in [5.0, 1.0, 3.0]:
        r.append(v)
    assert len(r) == 3 and sorted(r.values().tolist()) == [1.0, 3.0, 5.0]


def test_bounded_and_uniform_beyond():
    r = Reservoir(capacity=1000)
    for v in range(200_000):
        r.append(float(v))
    assert len(r) == 200_000 and len(r.values()) == 1000
    assert r._kept.nbytes == 8000  # the memory does not grow with the values seen
    # a uniform sample of 0..199999: its median near 100000 (the sample median's standard error
    # at n = 1000 is about 1.6 % of the range: 5 of them is 8 %), and values from the whole span
    assert abs(np.median(r.values()) - 100_000) < 16_000
    assert r.values().min() < 10_000 and r.values().max() > 190_000
