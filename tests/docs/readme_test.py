#!/usr/bin/env python3
"""The documentation's commands and snippets, run or checked (ctest ReadmeCommandsWork).

The documents are README.md and every Markdown file under the source tree's docs/. Every
fenced block of each must have an entry in readme_checks.CHECKS under that document, which
says how it is checked (see that module); a block without one fails, and so does an entry
without a block. Besides the blocks, in each document: the `make TARGET` spans of the prose
must name targets of the Makefile; the options that inline code spans give log2map,
mapconvert and mapdiff must be in the tool's --help; the CMake variables that
`-DVASCO_...` and `cmake.define.VASCO_...` name must be the project's options; the source paths that inline code names must exist; every
relative link must lead to a file that exists, and its #anchor to a heading of it; and the
contents list at the top of each document (before its first `##` heading) must link every
`##` heading.

Prints one line per block (document:line, check, ok / skipped / FAILED and why), one per
document's prose and links, and a summary; exits 0 only when no check failed. Standard
library only (Python 3.9+).

  python3 tests/docs/readme_test.py --readme README.md --source . --bin build/bin
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import readme_blocks  # noqa: E402
import readme_checks  # noqa: E402
from readme_blocks import Block  # noqa: E402
from readme_checks import Check  # noqa: E402

COMMAND_TIMEOUT = 120


class Failed(Exception):
    pass


class Context:
    def __init__(self, args):
        self.readme = Path(args.readme).resolve()
        self.source = Path(args.source).resolve()
        self.doc = self.readme.name  # the document being checked (readme_blocks.doc_name)
        self.bin = Path(args.bin).resolve()
        self.cc = args.cc
        self.cxx = args.cxx
        self.keep = args.keep
        self.scratch_root = Path(tempfile.mkdtemp(prefix="readme_test."))
        self._help: Dict[str, str] = {}

    def env(self) -> Dict[str, str]:
        env = dict(os.environ)
        env["PATH"] = f"{self.bin}{os.pathsep}{env.get('PATH', '')}"
        for k in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL"):  # ctest under make: no jobserver here
            env.pop(k, None)
        env["LC_ALL"] = "C"
        env["VASCO_SOURCE"] = str(self.source)
        env["VASCO_BUILD"] = str(self.bin.parent)
        return env

    def scratch(self, name: str) -> Path:
        """A new scratch directory for a block of the current document."""
        d = self.scratch_root / (re.sub(r"[^\w.-]", "_", self.doc) + "." + name)
        d.mkdir(parents=True)
        return d

    def help_of(self, tool: str) -> str:
        if tool not in self._help:
            r = subprocess.run([str(self.bin / tool), "--help"], capture_output=True, text=True, timeout=30)
            if r.returncode != 0:
                raise Failed(f"{tool} --help exits {r.returncode}")
            self._help[tool] = r.stdout + r.stderr
        return self._help[tool]


def short(text: str, n: int = 600) -> str:
    text = text.strip()
    return text if len(text) <= n else "..." + text[-n:]


def bash(ctx: Context, cmd: str, cwd: Path) -> subprocess.CompletedProcess:
    try:
        return subprocess.run(["bash", "-c", cmd], cwd=cwd, env=ctx.env(), capture_output=True, text=True,
                              timeout=COMMAND_TIMEOUT)
    except subprocess.TimeoutExpired:
        raise Failed(f"`{cmd}` ran past {COMMAND_TIMEOUT} s")


def prepare(ctx: Context, check: Check, name: str) -> Path:
    d = ctx.scratch(name)
    if check.fixture:
        fixture = readme_checks.FIXTURES.get(check.fixture)
        if fixture is None:
            raise Failed(f"no fixture {check.fixture!r} in readme_checks.FIXTURES")
        try:
            fixture(d, ctx.source, ctx.bin)
        except subprocess.CalledProcessError as e:
            raise Failed(f"fixture {check.fixture}: {' '.join(map(str, e.cmd))} exits {e.returncode}: "
                         f"{short(e.stderr.decode() if isinstance(e.stderr, bytes) else str(e.stderr))}")
    return d


def expected_status(check: Check, cmd: str) -> int:
    for prefix, status in check.status.items():
        if cmd.startswith(prefix):
            return status
    return 0


def skip_reason(check: Check, cmd: str) -> Optional[str]:
    for prefix, reason in check.skip.items():
        if cmd.startswith(prefix):
            return reason
    return None


def run_commands(ctx: Context, check: Check, commands: List[Tuple[int, str]], block: Block, d: Path) -> str:
    ran, skipped = 0, []
    for offset, cmd in commands:
        reason = skip_reason(check, cmd)
        if reason is not None:
            skipped.append(f"{ctx.doc}:{block.content_line(offset)} ({reason})")
            continue
        want = expected_status(check, cmd)
        r = bash(ctx, cmd, d)
        if r.returncode != want:
            raise Failed(f"{ctx.doc}:{block.content_line(offset)}: `{cmd}` exits {r.returncode}, "
                         f"not {want}: {short(r.stderr or r.stdout)}")
        ran += 1
    missing = [o for o in check.outputs if not (d / o).exists()]
    if missing:
        raise Failed(f"after the commands, missing: {', '.join(missing)}")
    note = f"{ran} command(s) ran"
    if check.outputs:
        note += f", {len(check.outputs)} output(s) there"
    if skipped:
        note += f"; not run: {'; '.join(skipped)}"
    return note


# --- the checks ---------------------------------------------------------------------------


def do_run(ctx: Context, check: Check, block: Block) -> str:
    if check.python:
        return "skipped: " + (check.reason or readme_checks.PY_SCRIPT_RUNS_IT)
    commands = readme_blocks.shell_commands(block.text)
    if not commands:
        raise Failed("no commands in the block")
    d = prepare(ctx, check, f"L{block.line}")
    return run_commands(ctx, check, commands, block, d)


def make_dry_run(ctx: Context, target: str, variables: Sequence[str] = ()) -> str:
    r = subprocess.run(["make", "-n", "-C", str(ctx.source), *variables, target], capture_output=True, text=True,
                       env=ctx.env(), timeout=60)
    if r.returncode != 0:
        raise Failed(f"`make -n {' '.join([*variables, target])}` exits {r.returncode}: {short(r.stderr)}")
    return r.stdout


def do_make_target(ctx: Context, check: Check, block: Block) -> str:
    targets = []
    for offset, cmd in readme_blocks.shell_commands(block.text):
        words = cmd.split()
        variables = words[1:-1]
        if words[0] != "make" or len(words) < 2 or not all(re.fullmatch(r"[A-Z_]+=\S*", v) for v in variables):
            raise Failed(f"{ctx.doc}:{block.content_line(offset)}: `{cmd}` is not one `make [VAR=VALUE...] TARGET`")
        target = words[-1]
        out = make_dry_run(ctx, target, variables)
        for m in check.mentions.get(target, ()):
            if m not in out:
                raise Failed(f"`make -n {' '.join(words[1:])}` does not mention {m!r}")
        targets.append(" ".join(words[1:]))
    return "targets " + ", ".join(targets) + " exist (make -n)"


def do_compile(ctx: Context, check: Check, block: Block) -> str:
    includes = [ln for ln in block.text.splitlines() if ln.strip().startswith("#include")]
    body = "\n".join(ln for ln in block.text.splitlines() if not ln.strip().startswith("#include"))
    src = check.harness.replace("@INCLUDES@", "\n".join(includes)).replace("@BODY@", body)
    is_c = block.lang == "c"
    d = ctx.scratch(f"L{block.line}")
    path = d / ("snippet.c" if is_c else "snippet.cc")
    path.write_text(src)
    inc = [f"-I{ctx.source / 'vasco_gpu' / 'include'}", f"-I{ctx.source / 'carmen_compat' / 'include'}"]
    if is_c:
        cmd = [ctx.cc, "-std=c99", "-fsyntax-only", "-Wall", "-Werror=implicit-function-declaration",
               "-Werror=incompatible-pointer-types", "-Werror=int-conversion", *inc, str(path)]
    else:
        cmd = [ctx.cxx, "-std=c++17", "-fsyntax-only", "-Wall", *inc, str(path)]
    if shutil.which(cmd[0]) is None:
        raise Failed(f"no compiler {cmd[0]!r} (--cc / --cxx)")
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        raise Failed(f"{'C99' if is_c else 'C++17'} in its harness does not compile: {short(r.stderr, 1500)}")
    return f"compiles as {'C99' if is_c else 'C++17'} in its harness against the headers"


def do_covered_by(ctx: Context, check: Check, block: Block) -> str:
    if not check.files:
        raise Failed("covered-by names no file")
    for rel, strings in check.files:
        p = ctx.source / rel
        if not p.is_file():
            raise Failed(f"{rel} is not there")
        text = p.read_text(errors="replace")
        for s in strings:
            if s not in text:
                raise Failed(f"{rel} does not contain {s!r}")
    return "covered by " + ", ".join(rel for rel, _ in check.files)


OPTION = re.compile(r"(?<![\w-])(--[a-zA-Z][\w-]*|-[a-zA-Z])(?![\w-])")


def option_in_help(ctx: Context, tool: str, opt: str) -> bool:
    text = ctx.help_of(tool)
    if re.fullmatch(r"--vasco_[A-Z]+", opt):  # --vasco_KEY: a placeholder
        return "--vasco_" in text
    return re.search(r"(?<![\w-])" + re.escape(opt) + r"(?![\w-])", text) is not None


def do_synopsis(ctx: Context, check: Check, block: Block) -> str:
    options = sorted({m.group(1) for ln in block.text.splitlines()
                      for m in OPTION.finditer(readme_blocks.strip_comment(ln))})
    missing = [o for o in options if not option_in_help(ctx, check.tool, o)]
    if missing:
        raise Failed(f"not in `{check.tool} --help`: {', '.join(missing)}")
    note = f"{len(options)} option(s) in `{check.tool} --help`"
    if check.examples:
        d = prepare(ctx, check, f"L{block.line}")
        note += "; " + run_commands(ctx, check, [(0, c) for c in check.examples], block, d) + " (filled in)"
    return note


NUMBER = re.compile(r"\d+(?:\.\d+)?(?:e[+-]?\d+)?")


def line_pattern(line: str, alternatives) -> re.Pattern:
    pieces: List[Tuple[bool, str]] = [(False, line)]  # (is a regex, text)
    for literal, rx in alternatives:
        out = []
        for is_rx, text in pieces:
            if is_rx or literal not in text:
                out.append((is_rx, text))
                continue
            parts = text.split(literal)
            for i, part in enumerate(parts):
                if i:
                    out.append((True, rx))
                out.append((False, part))
        pieces = out
    rx = ""
    for is_rx, text in pieces:
        if is_rx:
            rx += text
            continue
        at = 0
        for m in NUMBER.finditer(text):
            rx += re.escape(text[at:m.start()]) + r"[0-9.e+-]+"
            at = m.end()
        rx += re.escape(text[at:])
    return re.compile(rx)


def do_output(ctx: Context, check: Check, block: Block) -> str:
    d = prepare(ctx, check, f"L{block.line}")
    r = bash(ctx, check.command, d)
    if r.returncode != 0:
        raise Failed(f"`{check.command}` exits {r.returncode}: {short(r.stderr)}")
    if check.output_file:
        got = (d / check.output_file).read_text()
        if got != block.text:
            raise Failed(f"`{check.command}` writes {check.output_file} as\n{got}not as the README shows it")
        return f"`{check.command}` writes {check.output_file} as shown"
    want = [ln for ln in block.text.splitlines() if ln.strip()]
    got = (r.stderr + r.stdout).splitlines()
    for ln in want:
        pat = line_pattern(ln, check.alternatives)
        if not any(pat.fullmatch(g) for g in got):
            raise Failed(f"no line of `{check.command}` reads like {ln!r}; it says:\n{short(r.stderr + r.stdout)}")
    return f"`{check.command}` prints it (numbers aside)"


def do_layout(ctx: Context, check: Check, block: Block) -> str:
    """Directory entries (`name/` at the start of a line, nested by two-space indentation),
    and every file name with an extension in their descriptions, found under the entry's
    directory (or, for a name with a '/', under the source tree)."""
    missing = []
    parents: Dict[int, Path] = {}
    current: List[Path] = []
    checked = 0
    file_rx = re.compile(r"(?<![\w./*-])([\w./-]*\w\.(?:h|hpp|cuh|cu|cc|c|py|sh|md|cmake|txt|in))(?![\w])")
    skip_dirs = {".git"}

    def exists_under(dirs: List[Path], name: str) -> bool:
        for d in dirs:
            if (d / name).exists():
                return True
            base = Path(name).name
            for p in d.rglob(base):
                if str(p).endswith(name) and not any(part.startswith("build") or part in skip_dirs
                                                     for part in p.relative_to(ctx.source).parts):
                    return True
        return False

    for raw in block.text.splitlines():
        if not raw.strip():
            continue
        indent = len(raw) - len(raw.lstrip(" "))
        m = re.match(r"((?:[\w.-]+/)+(?:[\w.-]+\.\w+)?(?:, (?:[\w.-]+/)+)*)(\s{2,}|$)(.*)", raw.strip())
        desc = raw.strip()
        if m and indent <= 8:
            names = [n.strip() for n in m.group(1).split(",")]
            base = parents.get(indent - 2, ctx.source) if indent else ctx.source
            current = []
            for n in names:
                p = base / n
                checked += 1
                if not p.exists():
                    missing.append(str(p.relative_to(ctx.source)))
                current.append(p if p.is_dir() or n.endswith("/") else p.parent)
            if names[0].endswith("/"):
                parents[indent] = base / names[0]
            desc = m.group(3)
        for f in file_rx.findall(desc):
            checked += 1
            if not exists_under(current or [ctx.source], f) and not ("/" in f and exists_under([ctx.source], f)):
                missing.append(f"{f} (under {', '.join(str(c.relative_to(ctx.source)) for c in current)})")
        for dname in re.findall(r"(?<![\w/.-])([a-z_]+/)(?=[\s,)]|$)", desc):
            checked += 1
            if not any((c / dname).is_dir() for c in current):
                missing.append(f"{dname} (under {', '.join(str(c.relative_to(ctx.source)) for c in current)})")
    if missing:
        raise Failed("not in the tree: " + "; ".join(missing))
    return f"{checked} paths named, all there"


def do_python(ctx: Context, check: Check, block: Block) -> str:
    return "skipped: " + readme_checks.PY_RUNS_IT


def do_quoted(ctx: Context, check: Check, block: Block) -> str:
    source = ctx.source / check.quote_of
    if not source.is_file():
        raise Failed(f"{check.quote_of} is not there")
    lines = [line.rstrip() for line in source.read_text(errors="replace").splitlines()]
    want = [line.rstrip() for line in block.text.splitlines()]
    if not lines[0].startswith("# vasco_gpu benchmarks:") or not any(l.startswith("# commit:") for l in lines[:6]):
        raise Failed(f"{check.quote_of} lacks bench/run_all.sh's header (date, machine, commit)")
    if not want or not any(lines[i:i + len(want)] == want for i in range(len(lines) - len(want) + 1)):
        raise Failed(f"the block is not a run of lines of {check.quote_of}: quote the run, do not edit it")
    return f"{len(want)} lines quoted from {check.quote_of}"


def hand_table_checks(ctx: Context, text: str) -> List[str]:
    """docs/performance.md: figures of the current run are quoted blocks; a Markdown table is
    allowed only under its dated sections (Earlier runs, History)."""
    if ctx.doc != "docs/performance.md":
        return []
    problems, dated, fenced = [], False, False
    for n, line in enumerate(text.splitlines(), 1):
        fenced = fenced != line.startswith("```")
        if line.startswith("## "):
            dated = line[3:].strip() in ("Earlier runs", "History")
        if line.startswith("|") and not dated and not fenced:
            problems.append(f"line {n}: a table typed by hand above 'Earlier runs': quote the bench run instead")
    return problems


def do_skip(ctx: Context, check: Check, block: Block) -> str:
    return "skipped: " + check.reason


KINDS = {
    "run": do_run, "make-target": do_make_target, "compile": do_compile, "covered-by": do_covered_by,
    "synopsis": do_synopsis, "output": do_output, "layout": do_layout, "python": do_python, "skip": do_skip,
    "quoted": do_quoted,
}


def table_problems(check: Check) -> List[str]:
    problems = []
    if check.kind not in KINDS:
        problems.append(f"unknown kind {check.kind!r}")
    if check.kind == "skip" and not check.reason.strip():
        problems.append("a skip needs a reason")
    if any(not r.strip() for r in check.skip.values()):
        problems.append("a skipped command needs a reason")
    return problems


# --- prose: make targets and tool options in inline code -----------------------------------

TOOLS = ("log2map", "mapconvert", "mapdiff")


def prose_spans(text: str) -> List[Tuple[int, str, str, bool]]:
    """(line, heading, span, first cell of a table row) for every inline code span outside
    fenced blocks."""
    out = []
    heading = ""
    in_fence = None
    for n, ln in enumerate(text.splitlines(), 1):
        fence = re.match(r"^ {0,3}(`{3,}|~{3,})", ln)
        if fence:
            in_fence = None if in_fence else fence.group(1)[0]
            continue
        if in_fence:
            continue
        h = re.match(r"^#{1,6}\s+(.*)", ln)
        if h:
            heading = h.group(1)
        first_cell = re.match(r"^\|\s*`", ln)
        for i, m in enumerate(re.finditer(r"(`+)(.+?)\1", ln)):
            out.append((n, heading, m.group(2).strip(), bool(first_cell) and i == 0))
    return out


def prose_checks(ctx: Context, text: str, counts: Dict[str, int]) -> List[str]:
    """Problems with the prose's make targets and tool options (empty: none): `make X` spans
    must name Makefile targets; a span that starts with a tool's name, a span of options
    under a heading that names the tool, and the first cell of an option table's row in
    section log2map must give options that the tool's --help lists."""
    problems = []
    counts["options"] = 0
    targets: Dict[str, int] = {}
    top = ""
    tops: Dict[int, str] = {}
    for n, ln in enumerate(text.splitlines(), 1):
        m = re.match(r"^##\s+(.*)", ln)
        if m:
            top = m.group(1).strip()
        tops[n] = top
    for n, heading, span, first_cell in prose_spans(text):
        words = span.split()
        if not words:
            continue
        if len(words) >= 2 and words[0] == "make" and re.fullmatch(r"[a-z][\w-]*", words[1]):
            targets.setdefault(words[1], n)
        tool = words[0] if words[0] in TOOLS else None
        if tool is None and words[0].startswith("-"):
            named = [t for t in TOOLS if t in heading]
            if named:
                tool = named[0]
            elif first_cell and tops[n] == "log2map":
                tool = "log2map"
        if tool is None:
            continue
        for m in OPTION.finditer(span):
            opt = m.group(1)
            if opt in ("--help", "-h") or not opt.startswith("--") and tool != "mapconvert":
                continue
            counts["options"] += 1
            if not option_in_help(ctx, tool, opt):
                problems.append(f"{ctx.doc}:{n}: `{span}`: {opt} is not in `{tool} --help`")
    counts["targets"] = len(targets)
    for target, n in sorted(targets.items(), key=lambda kv: kv[1]):
        try:
            make_dry_run(ctx, target)
        except Failed as e:
            problems.append(f"{ctx.doc}:{n}: `make {target}`: {e}")
    return problems


# --- CMake options, links and contents -----------------------------------------------------

CMAKE_VAR = re.compile(r"(?:-D|cmake\.define\.)(VASCO_[A-Z0-9_]+)")


def cmake_text(ctx: Context) -> str:
    if not hasattr(ctx, "_cmake_text"):
        files = [p for p in ctx.source.rglob("CMakeLists.txt")] + list(ctx.source.rglob("*.cmake"))
        files = [p for p in files if not any(part.startswith("build") or part == ".git"
                                             for part in p.relative_to(ctx.source).parts)]
        ctx._cmake_text = "\n".join(p.read_text(errors="replace") for p in files)
    return ctx._cmake_text


def cmake_option_checks(ctx: Context, text: str, counts: Dict[str, int]) -> List[str]:
    """Problems with the CMake variables the document sets (-DVASCO_X, cmake.define.VASCO_X,
    in prose or blocks): each must be an option() or a cache variable of the project."""
    problems = []
    names: Dict[str, int] = {}
    for n, ln in enumerate(text.splitlines(), 1):
        for m in CMAKE_VAR.finditer(ln):
            names.setdefault(m.group(1), n)
    defined = cmake_text(ctx)
    for name, n in names.items():
        if not re.search(r"\b(option|set)\(\s*" + re.escape(name) + r"\b[^)]*(CACHE|\"|OFF|ON)", defined):
            problems.append(f"{ctx.doc}:{n}: {name} is not an option or cache variable of the CMake project")
    counts["cmake"] = len(names)
    return problems


def link_checks(ctx: Context, path: Path, text: str, counts: Dict[str, int]) -> List[str]:
    """Problems with the document's relative links: the file must exist (inside the source
    tree), and an #anchor must be a heading of that file (a Markdown file) or of this one."""
    problems = []
    n_links = 0
    for n, label, target in readme_blocks.links(text):
        if re.match(r"[a-z][a-z0-9+.-]*:", target, re.I):  # https:, mailto:, ...
            continue
        n_links += 1
        rel, anchor = readme_blocks.split_target(target)
        dest = (path.parent / rel).resolve() if rel else path
        if rel and not dest.exists():
            problems.append(f"{ctx.doc}:{n}: [{label}]({target}): {rel} does not exist")
            continue
        try:
            dest.relative_to(ctx.source)
        except ValueError:
            problems.append(f"{ctx.doc}:{n}: [{label}]({target}) leads out of the source tree")
            continue
        if anchor is not None and dest.suffix == ".md":
            if anchor not in readme_blocks.anchors(dest.read_text(encoding="utf-8")):
                problems.append(f"{ctx.doc}:{n}: [{label}]({target}): no heading of "
                                f"{readme_blocks.doc_name(dest, ctx.source)} has the anchor #{anchor}")
    counts["links"] = n_links
    return problems


def tree_files(ctx: Context) -> List[str]:
    """Every file and directory of the source tree (posix paths; build directories, .git and
    caches left out)."""
    if not hasattr(ctx, "_tree"):
        out = []
        for dirpath, dirnames, filenames in os.walk(ctx.source):
            rel = Path(dirpath).relative_to(ctx.source)
            dirnames[:] = [d for d in dirnames if not (d.startswith("build") or d.startswith(".") or d == "__pycache__")
                           or rel.parts == () and d == ".ci"]
            out += [(rel / n).as_posix() for n in dirnames + filenames]
        ctx._tree = out
    return ctx._tree


def path_checks(ctx: Context, text: str, counts: Dict[str, int]) -> List[str]:
    """Problems with the source paths the prose names in inline code: a span that is a path
    (`a/b`, `a/b.h`, `a/`) starting at a top-level entry of the source tree must name a file
    or directory there, or the end of one (`vasco_gpu/mapper.hpp` as an #include names it).
    Placeholders (a part in capitals, as `src/NAME_backend.cc`) are left alone."""
    problems = []
    tops = {p.name for p in ctx.source.iterdir() if not p.name.startswith("build")}  # outputs
    tree = None
    n_paths = 0
    for n, ln in readme_blocks.outside_fences(text):
        for m in re.finditer(r"(`+)(.+?)\1", ln):
            span = m.group(2).strip()
            if not re.fullmatch(r"[\w.-]+(/[\w.-]+)+/?", span) or span.split("/")[0] not in tops:
                continue
            if re.search(r"(^|/|_)[A-Z]{3,}(_|\.|/|$)", span):
                continue
            n_paths += 1
            if (ctx.source / span).exists():
                continue
            tree = tree or tree_files(ctx)
            tail = "/" + span.rstrip("/")
            if not any(f.endswith(tail) for f in tree):
                problems.append(f"{ctx.doc}:{n}: `{span}` is not in the source tree")
    counts["paths"] = n_paths
    return problems


def contents_checks(ctx: Context, text: str) -> List[str]:
    """Problems with the document's contents list: the links to its own anchors between the
    first heading and the first `##` heading must name every `##` heading."""
    hs = readme_blocks.headings(text)
    sections = [(n, h) for n, level, h in hs if level == 2]
    if not sections:
        return []
    first_section = sections[0][0]
    listed = {readme_blocks.split_target(t)[1] for n, _, t in readme_blocks.links(text)
              if n < first_section and t.startswith("#")}
    if not listed:
        return [f"{ctx.doc}: no contents list (links to its `##` sections) before line {first_section}"]
    anchors = readme_blocks.anchors(text)
    by_line = {line: a for a, line in anchors.items()}
    return [f"{ctx.doc}:{n}: the contents list does not link `## {h}` (#{by_line[n]})"
            for n, h in sections if by_line[n] not in listed]


# --- main ---------------------------------------------------------------------------------


def check_document(ctx: Context, path: Path, report) -> int:
    """Checks one document; returns its number of blocks."""
    ctx.doc = readme_blocks.doc_name(path, ctx.source)
    name = ctx.doc
    text = path.read_text(encoding="utf-8")
    blocks = readme_blocks.parse_blocks(text)
    seen: Dict[str, int] = {}
    for b in blocks:
        key = b.key
        if key in seen:
            report(f"{name}:{b.line}", b.describe(), "FAILED",
                   f"its key {key!r} is also the key of the block at line {seen[key]}: "
                   "make the blocks' first lines differ")
            continue
        seen[key] = b.line
        check = readme_checks.check_for(name, key)
        if check is None:
            report(f"{name}:{b.line}", "unknown block", "FAILED",
                   f"{b.describe()} the docs test does not know: add a check for {key!r} "
                   f"under {name!r} to tests/docs/readme_checks.py")
            continue
        problems = table_problems(check)
        if problems:
            report(f"{name}:{b.line}", check.kind, "FAILED", "; ".join(problems))
            continue
        try:
            note = KINDS[check.kind](ctx, check, b)
            report(f"{name}:{b.line}", check.kind, "skipped" if note.startswith("skipped: ") else "ok",
                   note[len("skipped: "):] if note.startswith("skipped: ") else note)
        except Failed as e:
            report(f"{name}:{b.line}", check.kind, "FAILED", str(e))
        except (OSError, subprocess.SubprocessError) as e:
            report(f"{name}:{b.line}", check.kind, "FAILED", f"{type(e).__name__}: {e}")
    for key in readme_checks.CHECKS.get(name, {}):
        if key not in seen:
            report(f"{name}:-", "stale entry", "FAILED",
                   f"readme_checks.CHECKS[{name!r}] has {key!r}, which no block of {name} has any more: "
                   "remove or update it")
    counts: Dict[str, int] = {}
    try:
        problems = prose_checks(ctx, text, counts)
    except Failed as e:
        problems = [str(e)]
    problems += cmake_option_checks(ctx, text, counts)
    problems += path_checks(ctx, text, counts)
    problems += hand_table_checks(ctx, text)
    report(f"{name}:-", "prose (make targets, tool options, CMake options, source paths in inline code)",
           "FAILED" if problems else "ok",
           "\n  " + "\n  ".join(problems) if problems else
           f"{counts.get('targets', 0)} make targets exist, {counts.get('options', 0)} options in the tools' "
           f"--help, {counts.get('cmake', 0)} CMake options defined, {counts.get('paths', 0)} source paths there")
    problems = link_checks(ctx, path, text, counts) + contents_checks(ctx, text)
    report(f"{name}:-", "links and contents", "FAILED" if problems else "ok",
           "\n  " + "\n  ".join(problems) if problems else
           f"{counts.get('links', 0)} relative links lead somewhere; the contents list names every section")
    return len(blocks)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--readme", required=True, help="README.md to check (the docs/ of --source too)")
    ap.add_argument("--source", required=True, help="the source tree (Makefile, logs/, tests/data, docs/)")
    ap.add_argument("--bin", required=True, help="the build's bin directory (log2map, mapconvert, mapdiff)")
    ap.add_argument("--cc", default=os.environ.get("CC", "cc"), help="C compiler of the compile checks")
    ap.add_argument("--cxx", default=os.environ.get("CXX", "c++"), help="C++ compiler of the compile checks")
    ap.add_argument("--only", action="append", default=[],
                    help="check only this document (a path; may be repeated); stale documents are not reported")
    ap.add_argument("--keep", action="store_true", help="keep the scratch directories")
    args = ap.parse_args(argv)
    ctx = Context(args)
    docs = readme_blocks.doc_files(ctx.source, ctx.readme)
    if args.only:
        only = {Path(o).resolve() for o in args.only}
        docs = [d for d in docs if d.resolve() in only]
        if len(docs) != len(only):
            print(f"--only: not a document of the docs test: {sorted(str(o) for o in only - {d.resolve() for d in docs})}")
            return 1
    results = {"ok": 0, "skipped": 0, "FAILED": 0}

    def report(where, what, status, why):
        results[status] += 1
        print(f"{where}: {what}: {status}" + (f": {why}" if why else ""), flush=True)

    n_blocks = 0
    try:
        for path in docs:
            n_blocks += check_document(ctx, path, report)
        if not args.only:
            names = {readme_blocks.doc_name(d, ctx.source) for d in docs}
            for doc in readme_checks.CHECKS:
                if doc not in names:
                    report(f"{doc}:-", "stale document", "FAILED",
                           f"readme_checks.CHECKS has entries for {doc}, which the docs test does not walk "
                           "(gone, or not under docs/): remove or move them")
    finally:
        if ctx.keep:
            print(f"scratch kept in {ctx.scratch_root}")
        else:
            shutil.rmtree(ctx.scratch_root, ignore_errors=True)
    print(f"{len(docs)} documents, {n_blocks} blocks: {results['ok']} ok, {results['skipped']} skipped, "
          f"{results['FAILED']} failed")
    return 1 if results["FAILED"] else 0


if __name__ == "__main__":
    sys.exit(main())
