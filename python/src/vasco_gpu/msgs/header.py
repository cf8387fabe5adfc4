"""A message header's two parts as the adapters use them: the stamp (whole nanoseconds, seconds,
exact text) and the frame name; and the closest of known names to a mistyped one."""

from __future__ import annotations

import difflib

import numpy as np

NS = 1_000_000_000


def stamp_text(ns: int) -> str:
    """A header stamp in whole nanoseconds as exact seconds text: 12.000000001."""
    sec, nsec = divmod(int(ns), NS)
    return f"{sec}.{nsec:09d}"


def stamp_seconds(ns) -> np.ndarray | float:
    """Seconds of stamps in nanoseconds as ``sec + nanosec * 1e-9`` in float64 (as documented)."""
    ns = np.asarray(ns, dtype=np.int64)
    sec, nsec = np.divmod(ns, NS)
    out = sec.astype(np.float64) + nsec.astype(np.float64) * 1e-9
    return float(out) if out.ndim == 0 else out


def stamp_ns(stamp) -> int:
    """Whole nanoseconds of a ROS time (sec, nanosec; ROS 1 times are read the same way)."""
    return int(stamp.sec) * NS + int(stamp.nanosec)


def frame_name(name: str) -> str:
    """A frame name without ROS 1's leading '/'."""
    return name[1:] if name.startswith("/") else name


def did_you_mean(name: str, names) -> str:
    """': did you mean '/scan'?' for the closest of names to a mistyped one, else ''."""
    close = difflib.get_close_matches(name, list(names), n=1, cutoff=0.6)
    return f": did you mean {close[0]!r}?" if close else ""
