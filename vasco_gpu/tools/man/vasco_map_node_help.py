"""The --help and --version text help2man makes vasco_map_node's man page from. The node takes
ROS 2 arguments only (running it with --help would start it), so its parameters are listed
here from the node's own rows (vasco_gpu.ros.settings), never from a copy."""

import sys

from vasco_gpu import __version__
from vasco_gpu.ros.settings import NODE_PARAMETERS, _default_text


def help_text() -> str:
    lines = ["Usage: vasco_map_node [--version] [--ros-args -p NAME:=VALUE ... --params-file FILE]", "",
             "The ROS 2 mapping node vasco_mapper: LaserScan, MultiEchoLaserScan and PointCloud2 scans posed",
             "by tf (and by an optimizer's nav_msgs/Path), the map republished on 'map'.", "",
             "Options:",
             "  --version            print the version and exit",
             "  --ros-args           everything after it is ROS 2's: -p NAME:=VALUE sets a parameter,",
             "                       --params-file FILE reads a parameter file, -r FROM:=TO remaps", "",
             "Parameters (-p NAME:=VALUE):"]
    for p in NODE_PARAMETERS:
        lines.append(f"  {p.name}:={_default_text(p.default)}")
        lines.append(f"      {p.help}; {p.check.rule()}" + ("" if p.dynamic else "; read-only once started"))
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(f"vasco_map_node (vasco_gpu) {__version__}" if "--version" in sys.argv[1:] else help_text(), end="")
