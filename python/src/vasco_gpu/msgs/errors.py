"""The errors of the message adapters: BagError (a bag or message that cannot be read as asked)
and TfError (a tf lookup that cannot be answered, from a bag or from a live TfBuffer). Both are
:class:`vasco_gpu.Error` (the package's one root); ``vasco_gpu.bags`` exports them."""

from __future__ import annotations

import os

from .._errors import Error

__all__ = ["BagError", "TfError"]


class BagError(Error):
    """A bag that cannot be read as asked: missing, not a bag, no such topic, no pose at a stamp.

    ``str()`` names the file first; ``.file`` is the bag as given, ``.topic`` the topic the
    problem is on (or None), ``.stamp`` the header stamp in seconds it is at (or None).
    """

    code = "bad input"

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


def _make_bag_error(file, message, topic, stamp, cls=BagError):
    """Unpickles a BagError or TfError (their constructor takes keyword-only arguments)."""
    return cls(file, message, topic=topic, stamp=stamp)
