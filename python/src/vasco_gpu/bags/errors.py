"""The errors of the bag reader: BagError (a bag that cannot be read as asked) and TfError (a
tf lookup that cannot be answered), the message adapters' (:mod:`vasco_gpu.msgs.errors`);
BagWarning (scans left out at the ends of the poses' time span, a fixed frame chosen, scans
whose angles were taken despite a rounding); and :func:`words`, how a message names an option."""

from __future__ import annotations

from ..msgs.errors import BagError, TfError

__all__ = ["BagError", "BagWarning", "TfError", "WORDINGS", "words"]

#: Whom a message speaks to: "cli" (bag2map, bag2carmen: option names such as --poses FILE) or
#: "python" (read_bag, load_bag: keyword names such as poses=FILE).
WORDINGS = ("cli", "python")


class BagWarning(UserWarning):
    """What load_bag warns of and reads on: scans before the first or after the last pose of the
    chain, left out and counted (a localisation stack's tf starts after the laser and its
    odometry may end before it); the tf root taken as the fixed frame of a bag without 'map';
    LaserScans whose angle_max disagrees with their ranges by rounding; tf links left out (a
    self transform, a link that would close a cycle), one warning of each kind."""


def words(wording: str, cli: str, python: str) -> str:
    """The option's name as the reader of the message knows it: cli on the command line, python
    in the Python API; a ValueError for a wording not in WORDINGS."""
    if wording not in WORDINGS:
        raise ValueError(f"wording must be one of {WORDINGS}, not {wording!r}")
    return cli if wording == "cli" else python
