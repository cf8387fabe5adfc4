"""vasco_gpu's pure-Python subpackages (bags, msgs) loaded by file path, without the compiled
extension: under a parent package whose ``__init__`` is not run (vasco_gpu's imports the
extension, which the tests that use this neither need nor build). Its subpackages import as
they do in the package (``from ..msgs import ...``)."""

from __future__ import annotations

import importlib
import sys
import types
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "src" / "vasco_gpu"
NAME = "vasco_gpu_under_test"

if NAME not in sys.modules:
    _parent = types.ModuleType(NAME)
    _parent.__path__ = [str(PACKAGE)]
    sys.modules[NAME] = _parent


def load(module: str):
    """vasco_gpu.<module> (e.g. "bags", "msgs.laser") from the source tree."""
    return importlib.import_module(f"{NAME}.{module}")
