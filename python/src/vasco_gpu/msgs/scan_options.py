"""The scan adapters' options, each defined once: its name (read_bag's keyword and the node's
parameter), default, choices, bag2map's flag and meaning. The bag reader, bag2map, bag2carmen
and the node take their defaults and checks from :data:`SCAN_OPTIONS`; which message type takes
which option is the message table's (:mod:`.table`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["ECHO_MODES", "NO_RETURN_MODES", "SCAN_DEFAULTS", "SCAN_OPTIONS", "ScanOption", "ScanSettings",
           "check_choice", "check_cloud_options"]

NO_RETURN_MODES = ("skip", "free")
ECHO_MODES = ("first", "last", "strongest")


@dataclass(frozen=True)
class ScanOption:
    """One option of the scan adapters."""

    name: str
    default: object
    meaning: str
    flag: str
    choices: tuple = ()  # the values it may take; empty: a number or numbers, checked by check_cloud_options


SCAN_OPTIONS = (
    ScanOption("no_return", "skip", "+inf ranges (REP 117 no return): skip, or free (clears up to range_max)",
               "--no-return", NO_RETURN_MODES),
    ScanOption("echo", "last", "the echo a MultiEchoLaserScan beam gives: first, last or strongest", "--echo",
               ECHO_MODES),
    ScanOption("z_band", (0.2, 1.8), "clouds: the heights kept, min and max, in metres in base_frame", "--z-band"),
    ScanOption("cloud_angle_step", 0.25, "clouds: the beams' angle step in degrees (nearest point per step)",
               "--cloud-angle-step"),
    ScanOption("cloud_range_max", 50.0, "clouds: points farther than this (m) are no return", "--cloud-range-max"),
)

#: name -> default, of every scan option.
SCAN_DEFAULTS = {o.name: o.default for o in SCAN_OPTIONS}


def check_choice(name: str, value) -> None:
    """ValueError for a value outside an option's choices (read_bag's wording)."""
    choices = next(o.choices for o in SCAN_OPTIONS if o.name == name)
    if value not in choices:
        raise ValueError(f"{name} must be one of {choices}, not {value!r}")


def check_cloud_options(z_band, angle_step, range_max) -> None:
    """ValueError naming the option for a band, step (radians) or range no cloud could make sense of."""
    if len(z_band) != 2 or not all(math.isfinite(v) for v in z_band) or not z_band[0] < z_band[1]:
        raise ValueError(f"z_band (--z-band MIN,MAX) must be two finite heights, MIN < MAX, not {tuple(z_band)!r}")
    if not (math.isfinite(angle_step) and math.radians(0.01) <= angle_step <= math.radians(10)):
        raise ValueError(f"cloud_angle_step (--cloud-angle-step) must be between 0.01 and 10 degrees, not "
                         f"{math.degrees(angle_step):g}")
    if not (math.isfinite(range_max) and 0 < range_max <= 1000):
        raise ValueError(f"cloud_range_max (--cloud-range-max) must be above 0 and at most 1000 m, not {range_max!r}")


@dataclass(frozen=True)
class ScanSettings:
    """The values of the scan options one reading takes (the defaults where none is given).
    cloud_angle_step in degrees, as given; ``angle_step`` is it in radians."""

    no_return: str = SCAN_DEFAULTS["no_return"]
    echo: str = SCAN_DEFAULTS["echo"]
    z_band: tuple = SCAN_DEFAULTS["z_band"]
    cloud_angle_step: float = SCAN_DEFAULTS["cloud_angle_step"]
    cloud_range_max: float = SCAN_DEFAULTS["cloud_range_max"]

    @property
    def angle_step(self) -> float:
        return math.radians(self.cloud_angle_step)
