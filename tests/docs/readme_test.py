#!/usr/bin/env python3
"""The documentation's commands and snippets, run or checked (ctest ReadmeCommandsWork).

The documents are README.md, every Markdown file under the source tree's docs/ and the notes
beside the benchmark runs (bench/results/*.md). Every fenced block of each must have an entry
in readme_checks.CHECKS under that document, which says how it is checked (see that module);
a block without one fails, and so does an entry without a block. Besides the blocks, in each
document: the `make TARGET` spans of the prose must name targets of the Makefile; the options
that inline code spans give log2map, mapconvert and mapdiff must be in the tool's --help; the
CMake variables that `-DVASCO_...` and `cmake.define.VASCO_...` name must be the project's
options; the source paths that inline code names must exist; every relative link must lead
to a file that exists, and its #anchor to a heading of it; the contents list at the top of
each document (before its first `##` heading) must link every `##` heading; and a page of
benchmark figures must take them from the runs' files.

This file walks the documents and reports; the checks are beside it: readme_context.py (the
run's context, a block's commands run), readme_kinds.py (the kinds of check of a block),
readme_quotes.py (quoted runs, hand tables, a summary's figures), readme_prose.py (the prose,
its links and contents list). Prints one line per block (document:line, check, ok / skipped /
FAILED and why), one per document's prose and links, and a summary; exits 0 only when no
check failed. Standard library only (Python 3.9+).

  python3 tests/docs/readme_test.py --readme README.md --source . --bin build/bin
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Dict, List

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import readme_blocks  # noqa: E402
import readme_checks  # noqa: E402
import readme_kinds  # noqa: E402
import readme_prose  # noqa: E402
import readme_quotes  # noqa: E402
from readme_blocks import Block  # noqa: E402
from readme_checks import Check  # noqa: E402
from readme_context import Context, Failed  # noqa: E402

# --- one document -------------------------------------------------------------------------


def check_blocks(ctx: Context, blocks: List[Block], report) -> None:
    """Checks every fenced block of the current document by its entry in the table, and
    reports the table's entries that no block has."""
    name = ctx.doc
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
        check_block(ctx, check, b, report)
    for key in readme_checks.CHECKS.get(name, {}):
        if key not in seen:
            report(f"{name}:-", "stale entry", "FAILED",
                   f"readme_checks.CHECKS[{name!r}] has {key!r}, which no block of {name} has any more: "
                   "remove or update it")


def check_block(ctx: Context, check: Check, b: Block, report) -> None:
    where = f"{ctx.doc}:{b.line}"
    problems = readme_kinds.table_problems(check)
    if problems:
        report(where, check.kind, "FAILED", "; ".join(problems))
        return
    try:
        note = readme_kinds.KINDS[check.kind](ctx, check, b)
        skipped = note.startswith("skipped: ")
        report(where, check.kind, "skipped" if skipped else "ok", note[len("skipped: "):] if skipped else note)
    except Failed as e:
        report(where, check.kind, "FAILED", str(e))
    except (OSError, subprocess.SubprocessError) as e:
        report(where, check.kind, "FAILED", f"{type(e).__name__}: {e}")


def check_prose(ctx: Context, path: Path, text: str, report) -> None:
    """Checks the current document's prose, figures, links and contents list."""
    counts: Dict[str, int] = {}
    try:
        problems = readme_prose.prose_checks(ctx, text, counts)
    except Failed as e:
        problems = [str(e)]
    problems += readme_prose.cmake_option_checks(ctx, text, counts)
    problems += readme_prose.path_checks(ctx, text, counts)
    problems += readme_quotes.hand_table_checks(ctx, text) + readme_quotes.summary_checks(ctx, text)
    report(f"{ctx.doc}:-", "prose (make targets, tool options, CMake options, source paths in inline code, figures)",
           "FAILED" if problems else "ok",
           "\n  " + "\n  ".join(problems) if problems else
           f"{counts.get('targets', 0)} make targets exist, {counts.get('options', 0)} options in the tools' "
           f"--help, {counts.get('cmake', 0)} CMake options defined, {counts.get('paths', 0)} source paths there")
    problems = readme_prose.link_checks(ctx, path, text, counts) + readme_prose.contents_checks(ctx, text)
    report(f"{ctx.doc}:-", "links and contents", "FAILED" if problems else "ok",
           "\n  " + "\n  ".join(problems) if problems else
           f"{counts.get('links', 0)} relative links lead somewhere; the contents list names every section")


def check_document(ctx: Context, path: Path, report) -> int:
    """Checks one document; returns its number of blocks."""
    ctx.doc = readme_blocks.doc_name(path, ctx.source)
    ctx.path = path.resolve()
    ctx.text = path.read_text(encoding="utf-8")
    blocks = readme_blocks.parse_blocks(ctx.text)
    check_blocks(ctx, blocks, report)
    check_prose(ctx, path, ctx.text, report)
    return len(blocks)


# --- main ---------------------------------------------------------------------------------


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
