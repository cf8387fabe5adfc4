"""The package's layers, read from its source: the message adapters (vasco_gpu.msgs) import
nothing above them, the bag reader nothing but them and the error root (no compiled extension),
no module imports another that imports it back, and every exception class the package defines
derives from vasco_gpu.Error; no file is renamed outside the output transaction."""

from __future__ import annotations

import ast
import builtins
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "vasco_gpu"
# The bags modules that write through the compiled extension or hand the scans to it.
ENGINE_MODULES = {"load.py", "cli.py", "carmen2bag.py", "bag_writer.py"}


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path, top_level_only: bool = False) -> list[str]:
    """The modules path imports, absolute (relative imports resolved, ``from . import x`` as
    the package.x); with top_level_only, not those inside functions."""
    package = module_name(path) if path.name == "__init__.py" else module_name(path).rpartition(".")[0]
    tree = ast.parse(path.read_text())
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    found = []
    for node in nodes:
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package.split(".")
            base = base[:len(base) - node.level + 1] if node.level else []
            target = ".".join(base + ([node.module] if node.module else []))
            found += [f"{target}.{a.name}" if not node.module else target for a in node.names]
    return found


def sources(sub: str) -> list[Path]:
    return sorted((PACKAGE / sub).glob("*.py"))


def test_the_adapters_import_nothing_above_them():
    for path in sources("msgs"):
        outside = [m for m in imports(path) if m.startswith("vasco_gpu") and not m.startswith("vasco_gpu.msgs")
                   and m != "vasco_gpu._errors"]
        assert not outside, (path.name, outside)


def test_the_bag_reader_does_not_import_the_extension():
    """The reader's modules import nothing of vasco_gpu but bags/, msgs/ and the error root
    (vasco_gpu's __init__ loads the compiled extension); only those that hand the scans to it
    or write through it do."""
    modules = [p for p in sources("bags") if p.name not in ENGINE_MODULES]
    assert {p.name for p in modules} >= {"__init__.py", "reader.py", "scans.py", "carmen_writer.py"}
    for path in modules:
        outside = [m for m in imports(path) if m.startswith("vasco_gpu")
                   and not m.startswith(("vasco_gpu.bags", "vasco_gpu.msgs")) and m != "vasco_gpu._errors"]
        assert not outside, (path.name, outside)


def test_no_import_circle():
    paths = sorted(PACKAGE.rglob("*.py"))
    names = {module_name(p): p for p in paths}
    graph = {}
    for name, path in names.items():
        targets = set()
        for m in imports(path, top_level_only=True):
            while m and m not in names:
                m = m.rpartition(".")[0]
            if m and m != name and m != "vasco_gpu" and not name.startswith(m + "."):
                targets.add(m)
        graph[name] = targets
    state: dict[str, int] = {}

    def visit(n, trail):
        state[n] = 1
        for t in sorted(graph[n]):
            assert state.get(t) != 1, f"import circle: {' -> '.join(trail + [n, t])}"
            if t not in state:
                visit(t, trail + [n])
        state[n] = 2

    for n in sorted(graph):
        if n not in state:
            visit(n, [])


def test_every_exception_derives_from_the_error_root():
    """A class whose bases name an exception (…Error, Exception, Refused, …) lists Error or a
    class of the package that does; warnings are not errors."""
    ours: dict[str, list[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef):
                ours[node.name] = [ast.unparse(b).rpartition(".")[2] for b in node.bases]
    def is_exception(name: str) -> bool:
        if name in ours:
            return any(is_exception(b) for b in ours[name])
        cls = getattr(builtins, name, None)
        return isinstance(cls, type) and issubclass(cls, BaseException) and not issubclass(cls, Warning)

    def rooted(name: str) -> bool:
        return name == "Error" or (name in ours and any(rooted(b) for b in ours[name]))

    loose = sorted(n for n, bases in ours.items() if n != "Error" and is_exception(n) and not rooted(n))
    assert not loose, loose


def test_no_file_is_renamed_outside_the_output_transaction():
    """Files are replaced by the engine's transaction only (_core._OutputFile: its checks,
    locks and signal clean-up), never by a rename of the package's own."""
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Attribute) and node.attr in ("replace", "rename") and \
                    isinstance(node.value, ast.Name) and node.value.id == "os":
                raise AssertionError(f"{path.name}:{node.lineno}: os.{node.attr}")
