"""The bag options' values, given as numbers (read_bag's keywords) or as text (bag2map's and
bag2carmen's options: "0.2,1.8"), checked before any bag is opened: what no bag could make
valid is a ValueError naming the option, which the command lines turn into a usage error
(exit 2) before they read a bag. Needs neither rosbags nor the compiled extension."""

from __future__ import annotations

import numpy as np

from ..msgs.geometry import check_mount
from ..msgs.scan_options import SCAN_DEFAULTS, ScanSettings, check_choice, check_cloud_options
from ..msgs.tf import MAX_TRANSLATION
from .scans import STAMP_MODES

__all__ = ["STATIC_POSE", "checked_pose", "numbers", "option_error", "scan_settings"]

#: How the errors name static_pose: the keyword and bag2map's option.
STATIC_POSE = "static_pose (--static-pose X,Y,THETA)"


def numbers(value, what: str) -> list[float]:
    """A number, or text of numbers separated by commas, as floats; ValueError naming what."""
    try:
        return [float(v) for v in value.split(",")] if isinstance(value, str) else [float(value)]
    except ValueError:
        raise ValueError(f"{what}: {value!r} is not a number") from None


def checked_pose(pose, what: str) -> np.ndarray | None:
    """A planar pose a user gives (x, y, yaw; text "X,Y,THETA" too) as a float64 (3,) array, or
    None; a ValueError naming what for one that is not three finite numbers, or whose x or y lies
    beyond tf's bound on a translation (MAX_TRANSLATION): there float64 no longer resolves a
    beam's cells, and further out the map's origin is no number a map file can hold."""
    if pose is None:
        return None
    if isinstance(pose, str):
        pose = numbers(pose, what)
    m = check_mount(pose, what)
    if not (np.abs(m[:2]) <= MAX_TRANSLATION).all():
        raise ValueError(f"{what}: x and y must be within {MAX_TRANSLATION:g} m of the origin (tf's bound on "
                         f"a translation), not {tuple(m.tolist())!r}")
    return m


def scan_settings(no_return, echo, z_band, angle_step, range_max) -> ScanSettings:
    """The scan adapters' options from read_bag's keywords: the cloud options as numbers, or as
    text (bag2map's options: "0.2,1.8"); None takes the default."""
    if isinstance(z_band, str):
        z_band = numbers(z_band, "z_band (--z-band MIN,MAX)")
    settings = ScanSettings(
        no_return=no_return, echo=echo,
        z_band=tuple(float(v) for v in (SCAN_DEFAULTS["z_band"] if z_band is None else z_band)),
        cloud_angle_step=SCAN_DEFAULTS["cloud_angle_step"] if angle_step is None else
        numbers(angle_step, "cloud_angle_step (--cloud-angle-step DEGREES)")[0],
        cloud_range_max=SCAN_DEFAULTS["cloud_range_max"] if range_max is None else
        numbers(range_max, "cloud_range_max (--cloud-range-max M)")[0])
    check_cloud_options(settings.z_band, settings.angle_step, settings.cloud_range_max)
    return settings


def _check_cloud_option(keyword: str, text: str) -> None:
    """One cloud option's text, the others at their defaults."""
    given = dict.fromkeys(("z_band", "cloud_angle_step", "cloud_range_max"))
    given[keyword] = text
    scan_settings(SCAN_DEFAULTS["no_return"], SCAN_DEFAULTS["echo"], *given.values())


def _check_stamp(text: str) -> None:
    if text not in STAMP_MODES:
        raise ValueError(f"stamp must be one of {STAMP_MODES}, not {text!r}")


# The options whose text alone can be wrong: (flag, its check, a ValueError naming it).
CHECKS = (
    ("static-pose", lambda text: checked_pose(text, STATIC_POSE)),
    ("laser-mount", lambda text: checked_pose(text, "laser_mount (--laser-mount X,Y,THETA)")),
    ("no-return", lambda text: check_choice("no_return", text)),
    ("echo", lambda text: check_choice("echo", text)),
    ("stamp", _check_stamp),
    ("z-band", lambda text: _check_cloud_option("z_band", text)),
    ("cloud-angle-step", lambda text: _check_cloud_option("cloud_angle_step", text)),
    ("cloud-range-max", lambda text: _check_cloud_option("cloud_range_max", text)),
)


def option_error(values: dict) -> str | None:
    """Why the first of the options given (text by flag, without '--') is wrong whatever the bag:
    one line naming the option and its value; None when every one may be right."""
    for flag, check in CHECKS:
        text = values.get(flag)
        if text is None:
            continue
        try:
            check(text)
        except ValueError as e:
            said = str(e)
            return said if f"--{flag}" in said and repr(text) in said else f"--{flag} {text!r}: {said}"
    return None
