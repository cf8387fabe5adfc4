"""The errors of the bag reader: BagError (a bag that cannot be read as asked) and TfError (a
tf lookup that cannot be answered, from a bag or from a live TfBuffer); BagWarning (scans left
out at the ends of the poses' time span)."""

from __future__ import annotations

import os

__all__ = ["BagError", "BagWarning", "TfError"]


class BagError(Exception):
    """A bag that cannot be read as asked: missing, not a bag, no such topic, no pose at a stamp.

    ``str()`` names the file first; ``.file`` is the bag as given, ``.topic`` the topic the
    problem is on (or None), ``.stamp`` the header stamp in seconds it is at (or None).
    """

    def __init__(self, file, message: str, *, topic: str | None = None, stamp: float | None = None):
        self.file = None if file is None else os.fspath(file)
        self.topic = topic
        self.stamp = stamp
        self.message = message
        super().__init__(message if self.file is None else f"{self.file}: {message}")

    def __reduce__(self):
        return (_make_bag_error, (self.file, self.message, self.topic, self.stamp, type(self)))


class TfError(BagError):
    """A tf tree that does not answer a lookup or refuses a transform: no chain between two
    frames, a stamp outside a link's samples, a frame with two parents, a bad quaternion.

    A BagError too, with the same attributes: ``.file`` is the bag the transforms came from, or
    None for a :class:`TfBuffer` fed live (``str()`` is then the message alone).
    """


class BagWarning(UserWarning):
    """What load_bag warns of and reads on: scans before the first or after the last pose of the
    chain, left out and counted (a localisation stack's tf starts after the laser and its
    odometry may end before it)."""


def _make_bag_error(file, message, topic, stamp, cls=BagError):
    """Unpickles a BagError or TfError (their constructor takes keyword-only arguments)."""
    return cls(file, message, topic=topic, stamp=stamp)
