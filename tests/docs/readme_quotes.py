"""The checks that keep the documents' benchmark figures those of a saved run: a quoted block
must be lines of its results file (bench/results/..., made by one bench/run_all.sh run under
a header naming its date, machine and commit) and the document must link that file; a page
of figures (readme_checks.NO_HAND_TABLES) has no table typed by hand; and a summary section
(readme_checks.SUMMARIES) quotes only figures that its files hold (standard library only).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import List, Set

import readme_blocks
import readme_checks
from readme_blocks import Block
from readme_checks import Check
from readme_context import Context, Failed


def results_lines(ctx: Context, rel: str) -> List[str]:
    """The lines of a results file, trailing blanks dropped; Failed unless it is there with
    bench/run_all.sh's header."""
    source = ctx.source / rel
    if not source.is_file():
        raise Failed(f"{rel} is not there")
    lines = [line.rstrip() for line in source.read_text(errors="replace").splitlines()]
    if not lines or not lines[0].startswith("# vasco_gpu benchmarks:") \
            or not any(line.startswith("# commit:") for line in lines[:6]):
        raise Failed(f"{rel} lacks bench/run_all.sh's header (date, machine, commit)")
    return lines


def is_run_of(want: List[str], lines: List[str]) -> bool:
    """Whether want is a run of consecutive lines of lines."""
    return bool(want) and any(lines[i:i + len(want)] == want for i in range(len(lines) - len(want) + 1))


def is_picked_from(want: List[str], lines: List[str]) -> bool:
    """Whether want is lines of lines in their order (a header and the rows wanted)."""
    rest = iter(lines)
    return bool(want) and all(any(line == w for line in rest) for w in want)


def linked_files(ctx: Context, text: str) -> Set[Path]:
    """Every file that a relative link of the document leads to."""
    out = set()
    for _, _, target in readme_blocks.links(text):
        rel, _ = readme_blocks.split_target(target)
        if rel and not re.match(r"[a-z][a-z0-9+.-]*:", rel, re.I):
            out.add((ctx.path.parent / rel).resolve())
    return out


def do_quoted(ctx: Context, check: Check, block: Block) -> str:
    lines = results_lines(ctx, check.quote_of)
    want = [line.rstrip() for line in block.text.splitlines()]
    if check.picked:
        if not is_picked_from(want, lines):
            raise Failed(f"the block is not lines of {check.quote_of} in its order: quote the run, do not edit it")
    elif not is_run_of(want, lines):
        raise Failed(f"the block is not a run of lines of {check.quote_of}: quote the run, do not edit it")
    if (ctx.source / check.quote_of).resolve() not in linked_files(ctx, ctx.text):
        raise Failed(f"{ctx.doc} does not link {check.quote_of}: link the run the block is quoted from")
    how = "picked from" if check.picked else "quoted from"
    return f"{len(want)} lines {how} {check.quote_of}, which the document links"


def hand_table_checks(ctx: Context, text: str) -> List[str]:
    """A page of figures (readme_checks.NO_HAND_TABLES) quotes its tables from the runs: a
    Markdown table typed by hand there is a problem."""
    if ctx.doc not in readme_checks.NO_HAND_TABLES:
        return []
    return [f"line {n}: a table typed by hand: quote the bench run instead"
            for n, line in readme_blocks.outside_fences(text) if line.startswith("|")]


DECIMAL = re.compile(r"(?<![\w.])\d+\.\d+(?![\w.]*\d)")


def section_lines(text: str, title: str) -> List[tuple]:
    """(line, text) of the `## title` section, fenced blocks left out."""
    out, inside = [], False
    for n, line in readme_blocks.outside_fences(text):
        if line.startswith("## "):
            inside = line[3:].strip() == title
        elif inside:
            out.append((n, line))
    return out


def summary_checks(ctx: Context, text: str) -> List[str]:
    """Every figure with a decimal point in the document's summary section
    (readme_checks.SUMMARIES) must be in a results file that the document quotes or that the
    section links: the short answer cannot drift from the runs either."""
    title = readme_checks.SUMMARIES.get(ctx.doc)
    if title is None:
        return []
    lines = section_lines(text, title)
    if not lines:
        return [f"{ctx.doc}: no section `## {title}` (readme_checks.SUMMARIES)"]
    files = {c.quote_of for c in readme_checks.CHECKS.get(ctx.doc, {}).values() if c.kind == "quoted"}
    section_links = linked_files(ctx, "\n".join(line for _, line in lines))
    results = (ctx.source / "bench" / "results").resolve()
    files |= {p.relative_to(ctx.source).as_posix() for p in section_links
              if p.parent == results and p.suffix == ".txt"}
    texts = [(ctx.source / f).read_text(errors="replace") for f in sorted(files) if (ctx.source / f).is_file()]
    problems = []
    for n, line in lines:
        plain = re.sub(r"\]\([^)]*\)", "]", line)  # link targets hold no figures
        for m in DECIMAL.finditer(plain):
            figure = re.compile(r"(?<![\d.])" + re.escape(m.group(0)) + r"(?!\d)")
            if not any(figure.search(t) for t in texts):
                problems.append(f"{ctx.doc}:{n}: {m.group(0)} is in no results file that the page quotes "
                                "or this section links")
    return problems
