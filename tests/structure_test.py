#!/usr/bin/env python3
"""The tree's structure, checked. Each check prints its violations, each naming the file
(and the line where there is one); the script exits 1 if any check found one.

1. No include runs upward: each source may include headers of its own layer or a lower one
   (carmen_compat < the engine, kernels included < pipeline < the command line library <
   the tools' mains and the Python bindings).
2. carmen_compat includes nothing of vasco_gpu.
3. The engine (vasco_gpu/src, vasco_gpu/include/vasco_gpu) reads no file: it includes
   neither carmen_compat's log reader, input files nor gzip stream, nor <fstream>, and calls
   no fopen, gzopen or file stream; the pipeline (inputs) layer reads files for it.
4. No source file over 700 lines (C, C++, CUDA and Python, data files aside).
5. No Python file of the package lists backend names or map formats (they come from the C++
   registries through _core), and none is over 600 lines.
6. The Python package renames no file itself (no os.replace, os.rename): outputs are written
   through the output transaction.
7. Every exception class the package defines derives from vasco_gpu.Error (warnings aside).
8. No import circle among the package's modules (imports run when a module is imported;
   an import inside a function does not count).
"""
import ast
import builtins
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "python/src/vasco_gpu"

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
ANY_INCLUDE = re.compile(r'^\s*#\s*include\s+[<"]([^>"]+)[>"]')
C_SOURCES = (".h", ".cc", ".cu", ".cuh", ".hpp")
CODE_FOLDERS = ("carmen_compat", "vasco_gpu", "python", "tests", "bench", "fuzz", "examples", "ros")
SOURCE_SUFFIXES = C_SOURCES + (".c", ".py")
MAX_LINES = 700


def skipped_folder(part: str) -> bool:
    """Build trees, caches, hidden folders and data folders hold no sources of ours."""
    return part.startswith(("build", ".")) or part in ("__pycache__", "data") or part.endswith(".egg-info")


def sources(folders, suffixes):
    """The source files under `folders` (relative to ROOT) with one of `suffixes`, sorted."""
    out = []
    for folder in folders:
        for path in (ROOT / folder).rglob("*"):
            rel = path.relative_to(ROOT)
            if path.suffix in suffixes and path.is_file() and not any(skipped_folder(p) for p in rel.parts[:-1]):
                out.append(path)
    return sorted(out)


def rel(path: pathlib.Path) -> str:
    return path.relative_to(ROOT).as_posix()


def layer_of(rel_path: str):
    for prefix, layer, name in LAYERS:
        if rel_path.startswith(prefix):
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
    found = [f for f in layered_files() if f == name or f.endswith("/" + name)]
    return found[0] if len(found) == 1 else None


_LAYERED_FILES = []


def layered_files():
    """Every file of the layered folders, relative to ROOT (read once)."""
    if not _LAYERED_FILES:
        folders = ["carmen_compat", "vasco_gpu", "python/src"]
        _LAYERED_FILES.extend(rel(p) for p in sources(folders, C_SOURCES + (".c",)))
    return _LAYERED_FILES


def include_violations():
    out = []
    for path in sources(["carmen_compat", "vasco_gpu", "python"], C_SOURCES):
        mine = layer_of(rel(path))
        if mine is None:
            continue
        for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            target = resolve(path, m.group(1))
            theirs = layer_of(target) if target else None
            if theirs and theirs[0] > mine[0]:
                out.append(f"{rel(path)}:{n}: the {mine[1]} includes {target} of the {theirs[1]} (a layer above)")
    return out


def includes(path: pathlib.Path):
    """(line number, included name) for each #include of a C/C++ source."""
    for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
        m = ANY_INCLUDE.match(line)
        if m:
            yield n, m.group(1)


def carmen_compat_engine_includes():
    out = []
    for path in sources(["carmen_compat"], C_SOURCES + (".c",)):
        for n, name in includes(path):
            target = resolve(path, name) or name
            if target.startswith("vasco_gpu/") or name.startswith("vasco_gpu/"):
                out.append(f"{rel(path)}:{n}: carmen_compat includes {target} of vasco_gpu: "
                           "carmen_compat is below the engine and includes nothing of it")
    return out


# What the engine must not include or call: reading files is the pipeline's (inputs) job.
ENGINE_FOLDERS = ["vasco_gpu/src", "vasco_gpu/include/vasco_gpu"]
FILE_READING_HEADERS = re.compile(
    r"(^|/)(log_reader\.h|input_file\.h|gzip_stream\.h)$|^fstream$")
FILE_READING_CALLS = re.compile(r"\b(fopen|gzopen|ifstream|fstream)\b")
COMMENT_OR_STRING = re.compile(r'//[^\n]*|/\*.*?\*/|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', re.S)


def without_comments_and_strings(text: str) -> str:
    """`text` with comments and literals blanked, line breaks kept (so line numbers hold)."""
    return COMMENT_OR_STRING.sub(lambda m: "\n" * m.group(0).count("\n"), text)


def engine_reads_files():
    out = []
    for path in sources(ENGINE_FOLDERS, C_SOURCES):
        for n, name in includes(path):
            if FILE_READING_HEADERS.search(name):
                out.append(f"{rel(path)}:{n}: the engine includes {name}: the engine reads no file "
                           "(the pipeline's inputs read files and hand it data)")
        code = without_comments_and_strings(path.read_text(errors="replace"))
        for n, line in enumerate(code.splitlines(), 1):
            if line.lstrip().startswith("#"):
                continue
            m = FILE_READING_CALLS.search(line)
            if m:
                out.append(f"{rel(path)}:{n}: the engine opens a file ({m.group(1)}): the engine reads no file "
                           "(the pipeline's inputs read files and hand it data)")
    return out


def long_files():
    out = []
    for path in sources(CODE_FOLDERS, SOURCE_SUFFIXES):
        lines = path.read_text(errors="replace").count("\n")
        if lines > MAX_LINES:
            out.append(f"{rel(path)}: {lines} lines (over {MAX_LINES}): split it by job")
    return out


BACKENDS = {"cpu_double", "cpu_threads", "cpu_float", "cuda_exact", "cuda_float"}
FORMATS = {"map.gz", "pgm", "png", "png+yaml", "yaml"}
DOCSTRING = re.compile(r'"""(?:.|\n)*?"""|\'\'\'(?:.|\n)*?\'\'\'')
LITERAL = re.compile(r"""(?<![\w.])(['"])([\w.+]+)\1""")


def package_violations():
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text()
        lines = text.count("\n")
        if lines > 600:
            out.append(f"{rel(path)}: {lines} lines (over 600): split it by job")
        code = DOCSTRING.sub("", text)  # examples in docstrings are not lists
        literals = {m.group(2) for m in LITERAL.finditer(code)}
        if len(literals & BACKENDS) >= 2:
            out.append(f"{rel(path)}: lists backend names {sorted(literals & BACKENDS)}: read _core.backend_registry()")
        if len(literals & FORMATS) >= 2:
            out.append(f"{rel(path)}: lists map formats {sorted(literals & FORMATS)}: read _core.map_formats()")
    return out


# ---------------------------------------------------------------------------
# The Python package, read with ast.
# ---------------------------------------------------------------------------
class Module:
    """One module of the package: its dotted name, file and syntax tree."""

    def __init__(self, name: str, path: pathlib.Path):
        self.name = name
        self.path = path
        self.tree = ast.parse(path.read_text(), filename=str(path))
        self.is_package = path.name == "__init__.py"

    def resolve_from(self, node: ast.ImportFrom) -> str:
        """The absolute module name of `from <node.module> import ...` in this module."""
        if not node.level:
            return node.module or ""
        parts = self.name.split(".")
        base = parts if self.is_package else parts[:-1]
        base = base[: len(base) - (node.level - 1)]
        return ".".join(base + ([node.module] if node.module else []))


def package_modules():
    """{dotted name: Module} of every .py file of python/src/vasco_gpu."""
    modules = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        modules[".".join(parts)] = Module(".".join(parts), path)
    return modules


def extension_modules():
    """The package's compiled modules (nanobind_add_module in python/CMakeLists.txt)."""
    cmake = (ROOT / "python/CMakeLists.txt").read_text()
    return {"vasco_gpu." + m for m in re.findall(r"nanobind_add_module\(\s*(\w+)", cmake)}


def python_renames():
    out = []
    for mod in package_modules().values():
        os_names = {"os"}
        for node in ast.walk(mod.tree):
            if isinstance(node, ast.Import):
                os_names |= {a.asname or a.name for a in node.names if a.name == "os"}
        for node in ast.walk(mod.tree):
            named = None
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in os_names:
                named = node.attr if node.attr in ("replace", "rename", "renames") else None
            elif isinstance(node, ast.ImportFrom) and node.module == "os" and not node.level:
                named = next((a.name for a in node.names if a.name in ("replace", "rename", "renames")), None)
            if named:
                out.append(f"{rel(mod.path)}:{node.lineno}: os.{named}: the package renames no file itself; "
                           "write outputs through the output transaction")
    return out


BUILTIN_EXCEPTIONS = {n for n, v in vars(builtins).items() if isinstance(v, type) and issubclass(v, BaseException)}
BUILTIN_WARNINGS = {n for n in BUILTIN_EXCEPTIONS if issubclass(getattr(builtins, n), Warning)}


def bound_names(mod: Module):
    """{name: "module.Name" or "module"} for what this module's imports bind."""
    bound = {}
    for node in ast.walk(mod.tree):
        if isinstance(node, ast.ImportFrom):
            source = mod.resolve_from(node)
            for a in node.names:
                bound[a.asname or a.name] = f"{source}.{a.name}"
        elif isinstance(node, ast.Import):
            for a in node.names:
                # `import a.b` binds a; `import a.b as c` binds c to a.b.
                top = a.name.split(".")[0]
                bound[a.asname or top] = a.name if a.asname else top
    return bound


def package_classes(modules):
    """{"module.Class": (Module, ClassDef, [qualified base names])} of the package's classes."""
    classes = {}
    for mod in modules.values():
        bound = bound_names(mod)
        local = {n.name for n in ast.walk(mod.tree) if isinstance(n, ast.ClassDef)}
        for node in ast.walk(mod.tree):
            if not isinstance(node, ast.ClassDef):
                continue
            bases = []
            for b in node.bases:
                text = ast.unparse(b)
                head, _, rest = text.partition(".")
                if head in local and not rest:
                    bases.append(f"{mod.name}.{head}")
                elif head in bound:
                    bases.append(bound[head] + ("." + rest if rest else ""))
                else:
                    bases.append(text)
            classes[f"{mod.name}.{node.name}"] = (mod, node, bases)
    return classes


def canonical(name: str, modules, classes, seen=()):
    """A class name followed through re-exports (vasco_gpu.Error -> vasco_gpu._errors.Error)."""
    if name in classes or name in seen:
        return name
    module, _, attr = name.rpartition(".")
    if module in modules:
        target = bound_names(modules[module]).get(attr)
        if target:
            return canonical(target, modules, classes, seen + (name,))
    return name


def ancestors(name, modules, classes, seen=None):
    """Every base of class `name`, transitively, canonical names (builtins by their name)."""
    seen = set() if seen is None else seen
    for base in classes.get(name, (None, None, []))[2]:
        base = canonical(base, modules, classes)
        if base not in seen:
            seen.add(base)
            ancestors(base, modules, classes, seen)
    return seen


def is_exception_name(name: str) -> bool:
    short = name.rpartition(".")[2]
    return short in BUILTIN_EXCEPTIONS or short.endswith(("Error", "Exception"))


def exception_roots():
    modules = package_modules()
    classes = package_classes(modules)
    root = canonical("vasco_gpu.Error", modules, classes)
    if root not in classes:
        return [f"{rel(PACKAGE / '__init__.py')}: no class Error exported: the package's exceptions need one root"]
    out = []
    for name, (mod, node, _) in sorted(classes.items()):
        above = ancestors(name, modules, classes)
        if name == root or not any(is_exception_name(a) for a in above):
            continue
        if any(a.rpartition(".")[2] in BUILTIN_WARNINGS or a.endswith("Warning") for a in above):
            continue
        if root not in above:
            out.append(f"{rel(mod.path)}:{node.lineno}: exception {node.name} does not derive from "
                       "vasco_gpu.Error: every exception the package defines does")
    return out


def top_level_imports(tree):
    """The import statements that run when the module is imported: not inside a function,
    nor under `if TYPE_CHECKING:`."""
    todo = list(tree.body)
    while todo:
        node = todo.pop(0)
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            continue
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            todo.extend(node.orelse)
            continue
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        else:
            todo.extend(ast.iter_child_nodes(node))


def import_edges(modules):
    """{module: {(imported module, line)}} within the package, from top-level imports."""
    known = set(modules) | extension_modules()
    edges = {name: set() for name in modules}
    for mod in modules.values():
        for node in top_level_imports(mod.tree):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                source = mod.resolve_from(node)
                # `from pkg import sub` imports the submodule; `from pkg import name`, pkg itself.
                targets = [f"{source}.{a.name}" if f"{source}.{a.name}" in known else source for a in node.names]
            for t in targets:
                if t in modules and t != mod.name:
                    edges[mod.name].add((t, node.lineno))
    return edges


def strongly_connected(edges):
    """The circles of the graph: its strongly connected components of more than one module."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w, _ in sorted(edges[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def import_circles():
    modules = package_modules()
    edges = import_edges(modules)
    out = []
    for circle in strongly_connected(edges):
        members = set(circle)
        links = [f"{rel(modules[a].path)}:{line} imports {b}"
                 for a in circle for b, line in sorted(edges[a]) if b in members]
        out.append("import circle among " + ", ".join(circle) + ": " + "; ".join(links))
    return out


CHECKS = [
    ("includes run downward", include_violations),
    ("carmen_compat includes no vasco_gpu", carmen_compat_engine_includes),
    ("the engine reads no file", engine_reads_files),
    (f"no source file over {MAX_LINES} lines", long_files),
    ("the package lists no backends or formats", package_violations),
    ("the package renames no file", python_renames),
    ("every package exception under vasco_gpu.Error", exception_roots),
    ("no Python import circle", import_circles),
]


def main():
    failed = 0
    total = 0
    for title, check in CHECKS:
        problems = check()
        total += len(problems)
        failed += bool(problems)
        print(f"{'FAIL' if problems else 'ok  '} {title}: {len(problems)} problem(s)")
        for p in problems:
            print(f"  {p}")
    print(f"structure: {total} problem(s) in {failed} of {len(CHECKS)} checks")
    return 1 if total else 0


if __name__ == "__main__":
    sys.exit(main())
