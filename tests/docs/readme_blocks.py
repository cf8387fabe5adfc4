"""The fenced code blocks of a Markdown file, and the command lines of a shell block.

Standard library only (Python 3.9+): the docs test (readme_test.py) and the Python tests
(python/tests/test_readme.py) both read README.md through this module.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import List, Tuple

_OPEN = re.compile(r"^( {0,3})(`{3,}|~{3,})[ \t]*([^`\s]*)[^`]*$")
SHELL_LANGS = ("sh", "bash", "shell", "console")
# Keys keep this many characters of the block's line: enough to tell blocks apart, few
# enough that a number changed at the end of a long line leaves the key as it was.
KEY_LENGTH = 60


@dataclass(frozen=True)
class Block:
    """One fenced code block: its info string's language ("" for none), the line of its
    opening fence (1-based), and its text (the lines between the fences)."""

    lang: str
    line: int
    text: str

    def content_line(self, offset: int) -> int:
        """The README line of the block's content line at offset (0-based)."""
        return self.line + 1 + offset

    @property
    def key(self) -> str:
        """The key of the block in the check table: its language and its first distinctive
        line, whitespace collapsed, cut at KEY_LENGTH characters. For a shell block that is the first command without its
        comment; for others the first non-empty line that is not an import or an #include
        (several blocks open with `import vasco_gpu as vg`)."""
        lang = self.lang or "text"
        if lang in SHELL_LANGS:
            cmds = shell_commands(self.text)
            first = cmds[0][1] if cmds else ""
        else:
            lines = [ln.strip() for ln in self.text.splitlines() if ln.strip()]
            plain = [ln for ln in lines if not re.match(r"(import |from \S+ import |#include )", ln)]
            first = (plain or lines or [""])[0]
            first = re.sub(r"\s+(#|//|/\*).*$", "", first)  # a trailing comment
        first = " ".join(first.split())
        return f"{lang}: {first[:KEY_LENGTH].rstrip()}"

    def describe(self) -> str:
        return f"a ```{self.lang} block" if self.lang else "a ``` block"


def parse_blocks(text: str) -> List[Block]:
    """Every fenced block of a Markdown text, in order. A fence closes with the same
    character, at least as long, and nothing after it but blanks (CommonMark); an unclosed
    block runs to the end of the text."""
    blocks: List[Block] = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        m = _OPEN.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, lang = len(m.group(1)), m.group(2), m.group(3).lower()
        close = re.compile(r"^ {0,3}" + re.escape(fence[0]) + "{%d,}[ \t]*$" % len(fence))
        fence_line = i + 1
        body = []
        i += 1
        while i < len(lines) and not close.match(lines[i]):
            ln = lines[i]
            body.append(ln[min(indent, len(ln) - len(ln.lstrip(" "))):])  # the fence's indentation
            i += 1
        blocks.append(Block(lang=lang, line=fence_line, text="".join(b + "\n" for b in body)))
        i += 1
    return blocks


def read_blocks(path) -> List[Block]:
    return parse_blocks(Path(path).read_text(encoding="utf-8"))


def strip_comment(line: str) -> str:
    """A shell line without its trailing comment: a '#' that begins a word (at the start of
    the line or after a blank) outside quotes, and what follows it. A '#' inside a word
    (`a#b`, `${#x}`) or inside quotes is kept."""
    quote = ""
    escaped = False
    for i, c in enumerate(line):
        if escaped:
            escaped = False
        elif c == "\\" and quote != "'":
            escaped = True
        elif quote:
            if c == quote:
                quote = ""
        elif c in "'\"":
            quote = c
        elif c == "#" and (i == 0 or line[i - 1] in " \t"):
            return line[:i].rstrip()
    return line.rstrip()


def shell_commands(text: str) -> List[Tuple[int, str]]:
    """The command lines of a shell block as (offset of the command's first line in the
    block, command): comments stripped, backslash continuations joined with one blank,
    blank lines left out."""
    out: List[Tuple[int, str]] = []
    pending, pending_at = "", 0
    for n, raw in enumerate(text.splitlines()):
        line = strip_comment(raw)
        if not pending:
            pending_at = n
        if line.endswith("\\"):
            pending += line[:-1].strip() + " "
            continue
        cmd = (pending + line.strip()).strip()
        pending = ""
        if cmd:
            out.append((pending_at, cmd))
    if pending.strip():
        out.append((pending_at, pending.strip()))
    return out
