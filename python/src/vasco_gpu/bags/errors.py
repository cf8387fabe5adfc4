"""The errors of the bag reader: BagError (a bag that cannot be read as asked) and TfError (a
tf lookup that cannot be answered), the message adapters' (:mod:`vasco_gpu.msgs.errors`);
BagWarning (scans left out at the ends of the poses' time span)."""

from __future__ import annotations

from ..msgs.errors import BagError, TfError

__all__ = ["BagError", "BagWarning", "TfError"]


class BagWarning(UserWarning):
    """What load_bag warns of and reads on: scans before the first or after the last pose of the
    chain, left out and counted (a localisation stack's tf starts after the laser and its
    odometry may end before it)."""
