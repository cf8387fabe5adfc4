"""The checks of a document's prose, outside its fenced blocks: the make targets and tool
options of inline code, the CMake options it sets, the source paths it names, its relative
links and #anchors, and its contents list (standard library only).
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Dict, List, Tuple

import readme_blocks
from readme_context import OPTION, Context, Failed, make_dry_run, option_in_help

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

