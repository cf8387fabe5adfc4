"""python -m vasco_gpu.ros [--ros-args ...]: the mapping node."""

import sys

from . import main

sys.exit(main())
