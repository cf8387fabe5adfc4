"""The kinds of check a fenced block can have (readme_checks.Check.kind), one function each:
given the run's context, the block's check and the block, each returns a note for the
report ("skipped: ..." for a block it leaves to another test) or raises Failed. The
quoted-block kind is readme_quotes.py's (standard library only).
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path
from typing import Dict, List, Tuple

import readme_blocks
import readme_checks
from readme_blocks import Block
from readme_checks import Check
from readme_context import OPTION, Context, Failed, bash, make_dry_run, option_in_help, prepare, run_commands, short
from readme_quotes import do_quoted

def do_run(ctx: Context, check: Check, block: Block) -> str:
    if check.python:
        return "skipped: " + (check.reason or readme_checks.PY_SCRIPT_RUNS_IT)
    commands = readme_blocks.shell_commands(block.text)
    if not commands:
        raise Failed("no commands in the block")
    d = prepare(ctx, check, f"L{block.line}")
    return run_commands(ctx, check, commands, block, d)


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


def do_skip(ctx: Context, check: Check, block: Block) -> str:
    return "skipped: " + check.reason


KINDS = {
    "run": do_run, "make-target": do_make_target, "compile": do_compile, "covered-by": do_covered_by,
    "synopsis": do_synopsis, "output": do_output, "layout": do_layout, "python": do_python, "skip": do_skip,
    "quoted": do_quoted,
}


def table_problems(check: Check) -> List[str]:
    """What is wrong with a check's entry itself (empty: nothing)."""
    problems = []
    if check.kind not in KINDS:
        problems.append(f"unknown kind {check.kind!r}")
    if check.kind == "skip" and not check.reason.strip():
        problems.append("a skip needs a reason")
    if any(not r.strip() for r in check.skip.values()):
        problems.append("a skipped command needs a reason")
    if check.kind == "quoted" and not check.quote_of:
        problems.append("a quoted block needs the file it is quoted from")
    return problems

