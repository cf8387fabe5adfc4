#!/usr/bin/env python3
"""The tree's structure, checked: (1) no include runs upward — each source may include
headers of its own layer or a lower one (carmen_compat < the engine, kernels included <
pipeline < the command line library < the tools' mains and the Python bindings); (2) no Python file of the package lists backend names
or map formats (they come from the C++ registries through _core); (3) no file of the Python
package is over 600 lines. Prints each violation with its file and line; exits 1 if any."""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent

# Folder -> layer, most specific first.
LAYERS = [
    ("carmen_compat/", 0, "carmen_compat"),
    ("vasco_gpu/pipeline/", 2, "pipeline"),
    ("vasco_gpu/app/", 3, "command line library"),
    ("vasco_gpu/tools/", 4, "tools"),
    ("vasco_gpu/", 1, "engine"),
    ("python/src/", 5, "Python bindings"),
]
# How an include names a header of a layer (the include roots of each).
INCLUDE_ROOTS = [
    ("carmen_compat/", "carmen_compat/include/"),
    ("vasco_gpu/pipeline/", "vasco_gpu/pipeline/include/"),
    ("vasco_gpu/", "vasco_gpu/include/"),
    ("carmen/egrid.h", "vasco_gpu/include/"),
    ("carmen/", "carmen_compat/include/"),
]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def layer_of(rel: str):
    for prefix, layer, name in LAYERS:
        if rel.startswith(prefix):
            return layer, name
    return None


def resolve(src: pathlib.Path, name: str):
    """The file an #include "name" in src reaches, relative to ROOT, or None."""
    local = src.parent / name
    if local.exists():
        return local.resolve().relative_to(ROOT).as_posix()
    for prefix, root in INCLUDE_ROOTS:
        if name.startswith(prefix) and (ROOT / root / name).exists():
            return root + name
    # A bare name found through a target's include folder: the one file of that name.
    found = [p.relative_to(ROOT).as_posix() for p in ROOT.glob("**/" + name)]
    found = [f for f in found if not f.startswith("build") and layer_of(f) is not None]
    return found[0] if len(found) == 1 else None


def include_violations():
    out = []
    for path in sorted(ROOT.glob("**/*")):
        rel = path.relative_to(ROOT).as_posix()
        if path.suffix not in (".h", ".cc", ".cu", ".cuh", ".hpp") or rel.startswith("build"):
            continue
        mine = layer_of(rel)
        if mine is None:
            continue
        for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            target = resolve(path, m.group(1))
            theirs = layer_of(target) if target else None
            if theirs and theirs[0] > mine[0]:
                out.append(f"{rel}:{n}: the {mine[1]} includes {target} of the {theirs[1]} (a layer above)")
    return out


BACKENDS = {"cpu_double", "cpu_threads", "cpu_float", "cuda_exact", "cuda_float"}
FORMATS = {"map.gz", "pgm", "png", "png+yaml", "yaml"}
DOCSTRING = re.compile(r'"""(?:.|\n)*?"""|\'\'\'(?:.|\n)*?\'\'\'')
LITERAL = re.compile(r"""(?<![\w.])(['"])([\w.+]+)\1""")


def package_violations():
    out = []
    for path in sorted((ROOT / "python/src/vasco_gpu").rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        text = path.read_text()
        lines = text.count("\n")
        if lines > 600:
            out.append(f"{rel}: {lines} lines (over 600): split it by job")
        code = DOCSTRING.sub("", text)  # examples in docstrings are not lists
        literals = {m.group(2) for m in LITERAL.finditer(code)}
        if len(literals & BACKENDS) >= 2:
            out.append(f"{rel}: lists backend names {sorted(literals & BACKENDS)}: read _core.backend_registry()")
        if len(literals & FORMATS) >= 2:
            out.append(f"{rel}: lists map formats {sorted(literals & FORMATS)}: read _core.map_formats()")
    return out


def main():
    problems = include_violations() + package_violations()
    for p in problems:
        print(p)
    print(f"structure: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
