"""Mapper(frame=..., frame_centre=(x, y)): a fixed frame at a given place, whatever the first
scan's pose, and the keyword's refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

import vasco_gpu as vg
from conftest import GOLDEN

EDGE = GOLDEN / "edge_cases.log.gz"


@pytest.fixture(scope="module")
def edge():
    return vg.load_log(EDGE)


def frame_of(log, theta_offset=0.0):
    return vg.Frame(400, 300, log.params.resolution, theta_offset)


def centre_of(log):
    """1.25 m east and 0.75 m south of the log's first scan: on no scan's pose."""
    return (float(log.scans.x[0]) + 1.25, float(log.scans.y[0]) - 0.75)


def at_centre(log, centre, heading):
    """One scan without beams at the centre: the first scan that centres CARMEN's fixed frame there."""
    return vg.Scans(np.array([[centre[0], centre[1], heading]]), np.zeros(0, np.float32), np.array([0]),
                    0.0, 0.01)


def test_the_frame_stays_at_the_centre(edge):
    centre = centre_of(edge)
    mp = vg.Mapper(edge.params, frame=frame_of(edge), frame_centre=centre)
    assert mp.frame.centre_given
    assert (mp.frame.x0, mp.frame.y0) == centre  # from construction on
    later = edge.scans.select(10, len(edge) - 10)  # a first scan elsewhere
    mp.insert(later)
    f = mp.frame
    assert (f.x0, f.y0, f.size_x, f.size_y, f.centre_given) == (*centre, 400, 300, True)
    # The grid's lower-left corner, as the ROS node places map_origin.
    assert f.world_x(0) == pytest.approx(centre[0] - 200 * f.resolution)
    assert f.world_y(0) == pytest.approx(centre[1] - 150 * f.resolution)

    # The same cells as CARMEN's fixed frame whose first scan stands at the centre, heading
    # theta_offset (exact backends: bit for bit).
    first_scan = vg.Mapper(edge.params, frame=frame_of(edge))
    first_scan.insert(at_centre(edge, centre, 0.0))
    first_scan.insert(later)
    assert not first_scan.frame.centre_given and (first_scan.frame.x0, first_scan.frame.y0) == centre
    want = first_scan.read()
    assert (want >= 0).sum() > 1000
    np.testing.assert_array_equal(mp.read(), want)
    # Centred on the first scan instead, the cells differ: the comparison can fail.
    plain = vg.Mapper(edge.params, frame=frame_of(edge))
    plain.insert(later)
    assert not np.array_equal(plain.read(), want)


def test_start_over_and_render_keep_the_centre(edge):
    centre = centre_of(edge)
    mp = vg.Mapper(edge.params, backend="cpu_threads", frame=frame_of(edge), frame_centre=centre)
    mp.insert(edge.scans.select(0, 30))
    mp.render(mp.poses + np.array([0.5, -0.25, 0.0]))
    assert (mp.frame.x0, mp.frame.y0, mp.frame.centre_given) == (*centre, True)
    mp.start_over(edge.params)
    assert (mp.frame.x0, mp.frame.y0, mp.frame.centre_given) == (*centre, True)
    mp.insert(edge.scans.select(40, 30))
    assert (mp.frame.x0, mp.frame.y0) == centre


def test_a_frame_read_back_keeps_its_centre(edge):
    centre = centre_of(edge)
    one = vg.Mapper(edge.params, frame=frame_of(edge), frame_centre=centre)
    assert "centre_given=True" in repr(one.frame)
    two = vg.Mapper(edge.params, frame=one.frame)
    two.insert(edge.scans.select(5, 20))
    assert (two.frame.x0, two.frame.y0, two.frame.centre_given) == (*centre, True)


def test_any_pair_of_numbers_is_a_centre(edge):
    for centre in ([1, 2], np.array([1.0, 2.0]), (np.float32(1.0), 2)):
        mp = vg.Mapper(edge.params, frame=frame_of(edge), frame_centre=centre)
        assert (mp.frame.x0, mp.frame.y0) == (1.0, 2.0)
    assert not vg.Mapper(edge.params, frame=frame_of(edge), frame_centre=None).frame.centre_given


def test_frame_centre_without_frame_is_refused(edge):
    with pytest.raises(TypeError, match="frame=Frame"):
        vg.Mapper(edge.params, frame_centre=(1.0, 2.0))


@pytest.mark.parametrize("bad", ["ab", b"ab", 5, (1.0,), (1.0, 2.0, 3.0), ("a", 1.0), (None, 1.0), {1: 2}])
def test_a_centre_that_is_not_two_numbers_is_refused(edge, bad):
    with pytest.raises(TypeError, match="two numbers"):
        vg.Mapper(edge.params, frame=frame_of(edge), frame_centre=bad)


@pytest.mark.parametrize("bad", [(math.nan, 0.0), (0.0, math.inf), (-math.inf, 1.0)])
def test_a_centre_not_finite_is_refused(edge, bad):
    with pytest.raises(ValueError, match="finite"):
        vg.Mapper(edge.params, frame=frame_of(edge), frame_centre=bad)
