#!/usr/bin/env python3
"""Prints, after `make test`, each test that skipped and why: the reason its GTEST_SKIP gave
(the line after "file:line: Skipped" in ctest's log of the run, LastTest.log), grouped so that
one reason shared by many tests (no GPU) is one line. Reads only; exits 0.

    python3 tests/skipped_report.py BUILD_DIR
"""
import collections
import pathlib
import re
import sys

TEST = re.compile(r"^\d+/\d+ Test: (.+)$")
SKIPPED_AT = re.compile(r": Skipped$")


def skipped(log: str):
    """(test, reason) for each test of the log whose output says it skipped."""
    out = []
    for chunk in log.split("\n----------------------------------------------------------\n\n"):
        lines = chunk.splitlines()
        name = next((m.group(1) for m in map(TEST.match, lines) if m), None)
        # ctest's own verdict (its skip expression matched), whatever gtest named the test
        if name is None or not any(line.startswith("Skip regular expression found in output") for line in lines):
            continue
        reason = "no reason given"
        for i, line in enumerate(lines[:-1]):
            if SKIPPED_AT.search(line):
                reason = lines[i + 1].strip() or reason
                break
        out.append((name, reason))
    return out


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[-1].strip(), file=sys.stderr)
        return 2
    log = pathlib.Path(argv[1]) / "Testing" / "Temporary" / "LastTest.log"
    if not log.is_file():
        print(f"skipped_report: {log}: no ctest log", file=sys.stderr)
        return 0
    by_reason = collections.defaultdict(list)
    for name, reason in skipped(log.read_text(errors="replace")):
        by_reason[reason].append(name)
    total = sum(len(v) for v in by_reason.values())
    if not total:
        print("skipped: none")
        return 0
    print(f"skipped: {total} test(s), and why:")
    for reason, names in sorted(by_reason.items(), key=lambda kv: -len(kv[1])):
        shown = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
        print(f"  {len(names):4d}  {reason}\n        ({shown})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
