"""Runs a console script of the package from a build tree, where no entry point is installed:
python run_tool.py PYPROJECT NAME [ARG...] runs NAME as pyproject.toml's [project.scripts]
names it (help2man makes the Python tools' man pages through it)."""

import contextlib
import importlib
import io
import re
import sys


def entry_point(pyproject: str, name: str) -> str:
    """NAME's "module:function" from the [project.scripts] table (read without tomllib, which
    Python 3.8 lacks)."""
    with open(pyproject, encoding="utf-8") as f:
        table = re.search(r"^\[project\.scripts\]\n(.*?)(?=^\[|\Z)", f.read(), re.M | re.S)
    found = re.search(rf'^{re.escape(name)}\s*=\s*"([^"]+)"', table.group(1) if table else "", re.M)
    if not found:
        sys.exit(f"run_tool: {name} is not in {pyproject}'s [project.scripts]")
    return found.group(1)


if __name__ == "__main__":
    module, function = entry_point(sys.argv[1], sys.argv[2]).split(":")
    sys.argv = sys.argv[2:]
    main = getattr(importlib.import_module(module), function)
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed):
            status = main()
    except SystemExit as e:  # argparse's --help and --version end this way
        status = e.code
    # help2man finds the synopsis after "Usage:"; argparse writes "usage:"
    sys.stdout.write(re.sub(r"^usage:", "Usage:", printed.getvalue(), flags=re.M))
    sys.exit(status)
