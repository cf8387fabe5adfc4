"""The tf tree under links that are no tree's: a self transform (``map -> map``), which tf2 drops,
and a link that would close a cycle (a reversed ``base_link -> map`` while ``map -> base_link``
is there, or a longer loop). Each is left out as it arrives (TfLinkIgnored, a TfError) and the
links already there go on answering: a lookup after it gives what it gave before.

The subpackage is loaded by file path, without vasco_gpu's compiled extension (package_under_test).
"""

from __future__ import annotations

import pickle
from types import SimpleNamespace as NS

import numpy as np
import pytest

import package_under_test

bags = package_under_test.load("bags")
tf_module = package_under_test.load("msgs.tf")

SEC0 = 1_700_000_000
IDENTITY = (0.0, 0.0, 0.0, 1.0)


def ns(seconds_after: float) -> int:
    return (SEC0 + int(seconds_after)) * 1_000_000_000


def link(parent, child, after, t=(0.0, 0.0, 0.0)):
    return NS(header=NS(frame_id=parent, stamp=NS(sec=SEC0 + after, nanosec=0)), child_frame_id=child,
              transform=NS(translation=NS(x=t[0], y=t[1], z=t[2]),
                           rotation=NS(x=IDENTITY[0], y=IDENTITY[1], z=IDENTITY[2], w=IDENTITY[3])))


def message(*links):
    return NS(transforms=list(links))


def robot():
    """map -> base_link on /tf at 1 s (1, 0, 0) and 3 s (3, 0, 0), base_link -> laser (static,
    (0, 0.5, 0)): laser in map at 2 s is (2, 0.5, 0) by hand."""
    tf = bags.TfBuffer("run.bag")
    tf.add_message(message(link("base_link", "laser", 0, (0.0, 0.5, 0.0))), static=True)
    tf.add_message(message(link("map", "base_link", 1, (1.0, 0.0, 0.0))))
    tf.add_message(message(link("map", "base_link", 3, (3.0, 0.0, 0.0))))
    return tf


def laser_at_2s(tf):
    t, q = tf.lookup("map", "laser", ns(2))
    return t[0].tolist(), q[0].tolist()


def test_the_robot_answers_by_hand():
    assert laser_at_2s(robot()) == ([2.0, 0.5, 0.0], list(IDENTITY))


@pytest.mark.parametrize("frame", ["map", "base_link", "laser", "elsewhere"])
def test_a_self_transform_is_ignored_and_stores_nothing(frame):
    tf = robot()
    before = (len(tf), tf.frames(), laser_at_2s(tf))
    with pytest.raises(tf_module.TfLinkIgnored) as e:
        tf.add_message(message(link(frame, frame, 2)))
    assert e.value.kind == "self link" and isinstance(e.value, bags.TfError)
    assert f"tf {frame} -> {frame} at stamp {SEC0 + 2}.000000000 on /tf links a frame to itself" in str(e.value)
    assert str(e.value).startswith("run.bag: ") and e.value.topic == "/tf" and e.value.stamp == SEC0 + 2
    assert (len(tf), tf.frames(), laser_at_2s(tf)) == before
    assert tf.root("laser") == "map"


def test_a_self_transform_with_a_leading_slash_is_one_frame():
    tf = robot()
    with pytest.raises(tf_module.TfLinkIgnored, match="tf map -> map"):
        tf.add_message(message(link("/map", "map", 2)), static=True)
    assert laser_at_2s(tf) == ([2.0, 0.5, 0.0], list(IDENTITY))


def test_a_reversed_link_is_refused_and_the_tree_goes_on():
    tf = robot()
    with pytest.raises(tf_module.TfLinkIgnored) as e:
        tf.add_message(message(link("base_link", "map", 2)))  # map -> base_link is there
    assert e.value.kind == "cycle"
    assert ("tf base_link -> map at stamp 1700000002.000000000 on /tf would close a cycle: map -> base_link is "
            "already in tf") in str(e.value)
    assert len(tf) == 2 and laser_at_2s(tf) == ([2.0, 0.5, 0.0], list(IDENTITY))
    # the link that was there goes on taking samples and answering
    tf.add_message(message(link("map", "base_link", 5, (5.0, 0.0, 0.0))))
    assert tf.lookup("map", "laser", ns(4))[0][0].tolist() == [4.0, 0.5, 0.0]


def test_a_longer_loop_is_refused_naming_it():
    tf = robot()
    with pytest.raises(tf_module.TfLinkIgnored) as e:
        tf.add_message(message(link("laser", "map", 2)), static=True)  # map is above laser
    assert "would close a cycle: map -> base_link -> laser is already in tf" in str(e.value)
    assert e.value.topic == "/tf_static"
    assert tf.root("laser") == "map" and tf.up("laser") == ["laser", "base_link", "map"]
    assert laser_at_2s(tf) == ([2.0, 0.5, 0.0], list(IDENTITY))


def test_a_link_between_separate_trees_is_no_cycle():
    # the check refuses loops only: a new parent for a root joins two trees
    tf = robot()
    tf.add_message(message(link("world", "map", 2)), static=True)
    assert tf.root("laser") == "world"
    assert tf.lookup("world", "laser", ns(2))[0][0].tolist() == [2.0, 0.5, 0.0]


def test_a_message_goes_on_past_a_link_left_out():
    # tf2 takes each transform of a message on its own: the good ones after a self or loop link
    # are stored, and the first one left out is raised after them
    tf = robot()
    with pytest.raises(tf_module.TfLinkIgnored, match="map -> map") as e:
        tf.add_message(message(link("map", "map", 2), link("base_link", "map", 2),
                               link("map", "base_link", 5, (5.0, 0.0, 0.0))))
    assert e.value.kind == "self link"
    assert tf.lookup("map", "laser", ns(4))[0][0].tolist() == [4.0, 0.5, 0.0]


def test_a_long_loop_is_named_in_a_bounded_line():
    tf = bags.TfBuffer()
    frames = [f"f{k}" for k in range(500)]
    tf.add_message(message(*(link(a, b, 0) for a, b in zip(frames, frames[1:]))), static=True)
    with pytest.raises(tf_module.TfLinkIgnored) as e:
        tf.add_message(message(link("f499", "f0", 0)), static=True)
    text = str(e.value)
    assert len(text) < 600 and "f0 -> f1 -> " in text and "(480 more)" in text and "f498 -> f499 is" in text
    assert tf.root("f499") == "f0"


def test_the_error_survives_pickling():
    tf = robot()
    with pytest.raises(tf_module.TfLinkIgnored) as e:
        tf.add_message(message(link("laser", "laser", 2)))
    back = pickle.loads(pickle.dumps(e.value))
    assert type(back) is tf_module.TfLinkIgnored and back.kind == "self link" and str(back) == str(e.value)


def test_other_refusals_still_stop_the_message():
    # a second parent is refused as before, and the transforms after it are not taken
    tf = robot()
    with pytest.raises(bags.TfError, match="two parents") as e:
        tf.add_message(message(link("odom", "base_link", 2), link("map", "base_link", 5, (5.0, 0.0, 0.0))))
    assert not isinstance(e.value, tf_module.TfLinkIgnored)
    with pytest.raises(bags.TfError, match="outside the time span"):
        tf.lookup("map", "laser", np.array([ns(4)]))
