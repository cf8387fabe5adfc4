"""Tests of vasco_gpu.bags.TfBuffer, tf's frame tree fed message by message as a ROS node would
(no bag, no rosbags): a static link below a dynamic one, lookups at a sample's stamp and
between two, in both directions, and the errors for what tf cannot answer. The expected
transforms are worked out by hand in the comments.

The subpackage is loaded by file path, without vasco_gpu's compiled extension (package_under_test).
"""

from __future__ import annotations

import math
from types import SimpleNamespace as NS

import numpy as np
import pytest

import package_under_test

bags = package_under_test.load("bags")

SEC0 = 1_700_000_000  # the stamps: SEC0 + 1 s, + 2 s, + 3 s
R = math.sqrt(0.5)  # sin 45 deg = cos 45 deg
YAW_90 = (0.0, 0.0, R, R)  # (x, y, z, w) of a turn by 90 deg about z
IDENTITY = (0.0, 0.0, 0.0, 1.0)


def ns(seconds_after: float) -> int:
    return (SEC0 + int(seconds_after)) * 1_000_000_000


def tf_message(*links):
    """A TFMessage-like message of (parent, child, whole seconds after SEC0, (x, y, z), (qx, qy, qz, qw))."""
    return NS(transforms=[
        NS(header=NS(frame_id=parent, stamp=NS(sec=SEC0 + after, nanosec=0)), child_frame_id=child,
           transform=NS(translation=NS(x=t[0], y=t[1], z=t[2]), rotation=NS(x=q[0], y=q[1], z=q[2], w=q[3])))
        for parent, child, after, t, q in links])


def make_buffer():
    """map -> base_link on /tf: at 1 s (1, 2, 0) heading 0, at 3 s (3, 2, 0) heading 90 deg (the
    later sample given first); base_link -> laser on /tf_static: (0.5, 0, 0.2) turned by 90 deg,
    given with a leading '/' as ROS 1 writes frames."""
    tf = bags.TfBuffer()
    tf.add_message(tf_message(("map", "base_link", 3, (3.0, 2.0, 0.0), YAW_90)))
    tf.add_message(tf_message(("/base_link", "/laser", 0, (0.5, 0.0, 0.2), YAW_90)), static=True)
    tf.add_message(tf_message(("map", "base_link", 1, (1.0, 2.0, 0.0), IDENTITY)))
    return tf


def assert_transform(got, want_t, want_q):
    t, q = got
    assert t.shape == (1, 3) and q.shape == (1, 4)
    np.testing.assert_allclose(t[0], want_t, rtol=0, atol=1e-12)
    sign = 1.0 if np.dot(q[0], want_q) >= 0 else -1.0  # q and -q are one rotation
    np.testing.assert_allclose(sign * q[0], want_q, rtol=0, atol=1e-12)


def test_the_tree():
    tf = make_buffer()
    assert len(tf) == 2
    assert tf.frames() == ["base_link", "laser", "map"]
    assert tf.up("laser") == ["laser", "base_link", "map"] and tf.root("laser") == "map"


def test_lookup_at_a_sample():
    # At 1 s the base is at (1, 2, 0) heading 0: the laser at (1, 2, 0) + (0.5, 0, 0.2), heading 90 deg.
    assert_transform(make_buffer().lookup("map", "laser", ns(1)), (1.5, 2.0, 0.2), YAW_90)
    # At 3 s the base is at (3, 2, 0) heading 90 deg: (0.5, 0, 0.2) turned by 90 deg is (0, 0.5, 0.2);
    # the laser heads 180 deg: (0, 0, sin 90 deg, cos 90 deg).
    assert_transform(make_buffer().lookup("map", "laser", ns(3)), (3.0, 2.5, 0.2), (0.0, 0.0, 1.0, 0.0))


def test_lookup_between_two_samples():
    # At 2 s, half way: the base at (2, 2, 0) heading 45 deg (slerp half way between 0 and 90 deg);
    # (0.5, 0, 0.2) turned by 45 deg is (0.5 cos 45, 0.5 sin 45, 0.2); the laser heads 135 deg.
    half = 0.5 * R
    want_q = (0.0, 0.0, math.sin(math.radians(67.5)), math.cos(math.radians(67.5)))
    assert_transform(make_buffer().lookup("map", "laser", ns(2)), (2.0 + half, 2.0 + half, 0.2), want_q)
    # Several stamps at once, in any order.
    t, q = make_buffer().lookup("map", "laser", np.array([ns(3), ns(2), ns(1)]))
    np.testing.assert_allclose(t, [(3.0, 2.5, 0.2), (2.0 + half, 2.0 + half, 0.2), (1.5, 2.0, 0.2)], atol=1e-12)


def test_lookup_the_other_way():
    # map in the laser frame at 1 s: the inverse of (1.5, 2, 0.2) heading 90 deg. Turning
    # (1.5, 2, 0.2) back by 90 deg gives (2, -1.5, 0.2); negated: (-2, 1.5, -0.2), heading -90 deg.
    assert_transform(make_buffer().lookup("laser", "map", ns(1)), (-2.0, 1.5, -0.2), (0.0, 0.0, -R, R))


def test_static_chain():
    tf = make_buffer()
    # A static link holds at every stamp, also with static_only.
    assert_transform(tf.lookup("base_link", "laser", 0, static_only=True), (0.5, 0.0, 0.2), YAW_90)
    with pytest.raises(bags.TfError, match="map -> base_link is on /tf"):
        tf.lookup("map", "laser", ns(1), static_only=True)


def test_incremental_samples_extend_the_span():
    tf = make_buffer()
    with pytest.raises(bags.TfError, match="outside the time span"):
        tf.lookup("map", "laser", ns(4))
    assert tf.covers("map", "laser", [ns(1), ns(4)]).tolist() == [True, False]
    # At 5 s the base is at (5, 2, 0) heading 90 deg: at 4 s, half way from 3 s, (4, 2, 0) heading 90 deg.
    tf.add_message(tf_message(("map", "base_link", 5, (5.0, 2.0, 0.0), YAW_90)))
    assert_transform(tf.lookup("map", "laser", ns(4)), (4.0, 2.5, 0.2), (0.0, 0.0, 1.0, 0.0))


def test_samples_given_in_order_look_up_as_those_given_out_of_order():
    # make_buffer gives base_link's samples 3 s, then 1 s (sorted on lookup); in order, the
    # buffer keeps them as they came: the same transforms at a sample and between two.
    tf = bags.TfBuffer()
    tf.add_message(tf_message(("/base_link", "/laser", 0, (0.5, 0.0, 0.2), YAW_90)), static=True)
    tf.add_message(tf_message(("map", "base_link", 1, (1.0, 2.0, 0.0), IDENTITY)))
    tf.add_message(tf_message(("map", "base_link", 3, (3.0, 2.0, 0.0), YAW_90)))
    stamps = np.array([ns(1), ns(2), ns(3)])
    for got, want in zip(tf.lookup("map", "laser", stamps), make_buffer().lookup("map", "laser", stamps)):
        np.testing.assert_array_equal(got, want)
    # a sample older than the newest afterwards: sorted again, the 2 s lookup now between 2 s and 3 s
    tf.add_message(tf_message(("map", "base_link", 2, (2.0, 3.0, 0.0), YAW_90)))
    assert_transform(tf.lookup("map", "laser", ns(2)), (2.0, 3.5, 0.2), (0.0, 0.0, 1.0, 0.0))


def test_waiting_for_a_link_without_a_sample_yet():
    tf = make_buffer()  # base_link's newest sample at 3 s
    assert not tf.waiting_for("map", "laser", ns(3))
    assert tf.waiting_for("map", "laser", ns(4))  # lookup would say: outside the time span
    assert not tf.waiting_for("base_link", "laser", ns(9))  # a static chain waits for nothing
    assert not tf.waiting_for("map", "nowhere", ns(1))  # no chain: lookup says why
    tf.add_message(tf_message(("map", "base_link", 5, (5.0, 2.0, 0.0), YAW_90)))
    assert not tf.waiting_for("map", "laser", ns(4))
    # stamps in an array (a live node's batch): each answered as alone
    stamps = np.array([ns(1), ns(5), ns(6), ns(9)])
    assert tf.waiting_for("map", "laser", stamps).tolist() == [False, False, True, True]
    assert tf.waiting_for("map", "nowhere", stamps).tolist() == [False] * 4


def test_many_samples_in_and_out_of_order_and_forgotten():
    # 1,000 samples of one link, x = the stamp's second: given in order, in reverse, and in order
    # to a buffer that keeps 100 s; each answers every stamp it holds with its sample, and the
    # interpolation half way between two with the mean (the samples grow the link's storage
    # many times over; the reversed ones are sorted, the kept ones are the newest).
    def sample(k):
        return ("map", "base_link", k, (float(k), 0.0, 0.0), IDENTITY)

    forward, backward, kept = bags.TfBuffer(), bags.TfBuffer(), bags.TfBuffer(keep=100.0)
    for k in range(1000):
        forward.add_message(tf_message(sample(k)))
        backward.add_message(tf_message(sample(999 - k)))
        kept.add_message(tf_message(sample(k)))
        if k == 499:  # a lookup before more samples come: it must not see later ones
            t, _ = forward.lookup("map", "base_link", np.array([ns(499)]))
            assert t[0, 0] == 499.0
    stamps = np.array([ns(k) for k in range(1000)])
    for tf in (forward, backward):
        t, q = tf.lookup("map", "base_link", stamps)
        np.testing.assert_array_equal(t[:, 0], np.arange(1000.0))
        np.testing.assert_array_equal(q, np.tile(IDENTITY, (1000, 1)))
    assert kept.span("map", "base_link")[0] >= ns(999 - 100 - 256)  # forgotten in steps of 256 samples
    t, _ = kept.lookup("map", "base_link", np.array([ns(899), ns(999)]))
    assert t[:, 0].tolist() == [899.0, 999.0]
    half = (ns(10) + ns(11)) // 2
    assert forward.lookup("map", "base_link", half)[0][0, 0] == 10.5


def test_missing_chain():
    tf = make_buffer()
    with pytest.raises(bags.TfError) as e:
        tf.lookup("map", "camera", ns(1))
    assert str(e.value) == ("no transform chain from 'map' to 'camera': 'camera' is not in tf "
                            "(frames in /tf: base_link, laser, map)")
    assert isinstance(e.value, bags.BagError) and e.value.file is None
    tf.add_message(tf_message(("odom", "wheel", 1, (0.0, 0.0, 0.0), IDENTITY)))
    with pytest.raises(bags.TfError, match="'wheel' reaches 'odom', 'laser' reaches 'map' via base_link"):
        tf.lookup("laser", "wheel", ns(1))


def test_refused_transforms():
    tf = make_buffer()
    with pytest.raises(bags.TfError, match="frame 'laser' has two parents in tf: 'base_link' on /tf_static and "
                                           "'odom' on /tf_static"):
        tf.add_message(tf_message(("odom", "laser", 1, (0.0, 0.0, 0.0), IDENTITY)), static=True)
    with pytest.raises(bags.TfError, match="is on both /tf and /tf_static"):
        tf.add_message(tf_message(("map", "base_link", 2, (0.0, 0.0, 0.0), IDENTITY)), static=True)
    with pytest.raises(bags.TfError, match="invalid rotation quaternion"):
        tf.add_message(tf_message(("map", "base_link", 2, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0))))


def test_a_translation_that_is_not_a_number_is_refused_naming_the_link():
    tf = bags.TfBuffer("run.bag")
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(bags.TfError) as e:
            tf.add_message(tf_message(("map", "base_link", 1, (bad, 0.0, 0.0), IDENTITY)))
        assert "tf map -> base_link at stamp" in str(e.value) and "on /tf has translation" in str(e.value)
    with pytest.raises(bags.TfError, match="/tf_static has translation"):
        tf.add_message(tf_message(("base_link", "laser", 0, (0.0, math.nan, 0.0), IDENTITY)), static=True)
    assert len(tf) == 0  # nothing half added


def test_two_different_samples_at_one_stamp():
    links = [("map", "base_link", 1, (1.0, 0.0, 0.0), IDENTITY), ("map", "base_link", 1, (1.5, 0.0, 0.0), IDENTITY),
             ("map", "base_link", 2, (2.0, 0.0, 0.0), IDENTITY)]
    strict = bags.TfBuffer("run.bag", refuse_repeats=True)
    strict.add_message(tf_message(*links))
    with pytest.raises(bags.TfError, match="two different samples at stamp"):
        strict.lookup("map", "base_link", [ns(1.5)])
    live = bags.TfBuffer()  # a live buffer goes on with the later one
    live.add_message(tf_message(*links))
    assert_transform(live.lookup("map", "base_link", [ns(1)]), (1.5, 0.0, 0.0), IDENTITY)
    same = bags.TfBuffer("run.bag", refuse_repeats=True)  # a message recorded twice is no conflict
    same.add_message(tf_message(links[0], links[0], links[2]))
    assert_transform(same.lookup("map", "base_link", [ns(1)]), (1.0, 0.0, 0.0), IDENTITY)


def test_a_deep_chain_is_looked_up_in_linear_time():
    # Two branches of 40,000 static links under one root, looked up leaf to leaf: the common
    # ancestor search was quadratic in the depth (a set of one branch built again for every
    # frame of the other: 1.6e9 insertions, ~30 s on the 2-core development machine).
    import time

    tf = bags.TfBuffer()
    depth = 40_000
    for side in "ab":
        tf.add_message(tf_message(*[(f"{side}{k}" if k else "root", f"{side}{k + 1}", 0, (0.0, 0.0, 0.0), IDENTITY)
                                    for k in range(depth)]), static=True)
    start = time.perf_counter()
    t, q = tf.lookup(f"a{depth}", f"b{depth}", [ns(1)])
    took = time.perf_counter() - start
    assert t.shape == (1, 3)
    # Linear: the lookup itself takes milliseconds; the bound is half the quadratic route's time,
    # so only that route fails it.
    assert took < 15.0, took


# Found by fuzz/fuzz_bag_tf.py: inputs the tree took with an exception other than a TfError, or
# answered with numbers that are not finite.


def test_a_stamp_beyond_ros_time_is_refused_and_leaves_no_link():
    # sec 1e19 overflowed the int64 history (OverflowError) after the link was made, and the
    # empty link then failed every lookup with an IndexError.
    tf = bags.TfBuffer()
    for sec, nanosec in ((10**19, 0), (-(2**63), 4294967295), (2**32 + 5, 0), (0, 2**63), (-(2**31) - 1, 0)):
        with pytest.raises(bags.TfError, match="the stamp is not a ROS time"):
            tf.add_transform(transform_at("map", "odom", sec, nanosec, 0.0))
    assert len(tf) == 0
    with pytest.raises(bags.TfError, match="neither 'odom' nor 'map' is in tf"):
        tf.lookup("map", "odom", 0)


def transform_at(parent, child, sec, nanosec, x):
    """A TransformStamped-like link at any (sec, nanosec), moved by x along x."""
    return NS(header=NS(frame_id=parent, stamp=NS(sec=sec, nanosec=nanosec)), child_frame_id=child,
              transform=NS(translation=NS(x=x, y=0.0, z=0.0), rotation=NS(x=0.0, y=0.0, z=0.0, w=1.0)))


def test_the_extreme_ros_times_and_an_unbounded_keep():
    # ROS 2's earliest (sec -2^31) and ROS 1's latest (sec 2^32 - 1) stamps: their difference is
    # below 2^63 ns, so spans, gaps and interpolation stay exact. keep=inf was an OverflowError.
    tf = bags.TfBuffer(max_gap=10.0)
    early, late = -(2**31) * 10**9, (2**32 - 1) * 10**9 + 999_999_999
    for stamp, x in ((early, 0.0), (late, 6.0)):
        tf.add_transform(transform_at("map", "odom", stamp // 10**9, stamp % 10**9, x))
    assert tf.span("map", "odom") == (early, late)
    with pytest.raises(bags.TfError, match="falls in a gap of 6442450944.000 s"):
        tf.lookup("map", "odom", 0)
    assert tf.covers("map", "odom", [early, 0, late]).tolist() == [True, False, True]
    t, q = bags.TfBuffer(keep=math.inf).lookup("a", "a", 0)  # any keep: as long as every stamp
    assert np.isfinite(t).all()


def test_a_translation_too_large_to_compose_is_refused():
    # 1e308 m passed the finiteness check and gave inf (and nan) in every lookup through it.
    tf = bags.TfBuffer("run.bag")
    for x in (1e308, -1e13, 1.5e12):
        with pytest.raises(bags.TfError, match=r"on /tf has translation .*: not a finite number of metres up to "
                                               r"1e\+12"):
            tf.add_message(tf_message(("map", "base_link", 1, (x, 0.0, 0.0), IDENTITY)))
    tf.add_message(tf_message(("map", "base_link", 1, (1e12, 0.0, 0.0), IDENTITY),
                              ("map", "base_link", 2, (-1e12, 0.0, 0.0), IDENTITY)))
    tf.add_message(tf_message(("base_link", "laser", 0, (1e12, 0.0, 0.0), YAW_90)), static=True)
    t, q = tf.lookup("map", "laser", [ns(1), (ns(1) + ns(2)) // 2, ns(2)])
    assert np.isfinite(t).all() and np.isfinite(q).all()
    np.testing.assert_allclose(t[:, 0], [2e12, 1e12, 0.0], rtol=0, atol=1e-3)


def test_an_error_the_caller_keeps_does_not_stop_new_samples():
    # The TfError about two samples at one stamp kept views of the link's history alive in its
    # traceback: the next sample of the link was a BufferError while the caller held the error.
    tf = bags.TfBuffer("run.bag", refuse_repeats=True)
    tf.add_message(tf_message(("map", "base_link", 1, (1.0, 0.0, 0.0), IDENTITY),
                              ("map", "base_link", 1, (2.0, 0.0, 0.0), IDENTITY)))
    with pytest.raises(bags.TfError, match="two different samples") as kept:
        tf.lookup("map", "base_link", [ns(1)])
    tf.add_message(tf_message(("map", "base_link", 2, (3.0, 0.0, 0.0), IDENTITY)))
    assert kept.value.topic == "/tf" and len(tf) == 1


def test_no_chain_among_thousands_of_frames_is_a_short_error():
    # A tree of 20,000 frames: the error listed every one (half a megabyte), and its "did you
    # mean" compared the missing name with each (half a second, in a lookup a node repeats).
    tf = bags.TfBuffer()
    name = "robot_{:06d}_laser_link".format
    tf.add_message(tf_message(*[(name((k - 1) // 2), name(k), 0, (1.0, 0.0, 0.0), IDENTITY)
                                for k in range(1, 20_000)]), static=True)
    with pytest.raises(bags.TfError) as e:
        tf.lookup(name(5), "robot_99999_laser_lnk", [0])
    text = str(e.value)
    assert len(text) < 1000, len(text)
    assert text.endswith(f"(frames in /tf: {', '.join(sorted(name(k) for k in range(20_000))[:20])}, ... "
                         "(19980 more))")
    assert "did you mean" not in text
    small = make_buffer()  # a few frames: all listed, and the closest named
    with pytest.raises(bags.TfError, match=r"'lazer' is not in tf: did you mean 'laser'\? \(frames in /tf: "
                                           r"base_link, laser, map\)"):
        small.lookup("map", "lazer", ns(1))
