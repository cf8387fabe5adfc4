"""The fenced code blocks of a Markdown file, the command lines of a shell block, and the
headings, anchors and links of a Markdown file.

Standard library only (Python 3.9+): the docs test (readme_test.py) and the Python tests
(python/tests/test_readme.py) both read README.md and docs/*.md through this module.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Optional, Tuple

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


# --- the documents -------------------------------------------------------------------------


def doc_files(source, readme=None) -> List[Path]:
    """The Markdown files the docs test walks: the README (README.md of the source tree
    unless given), then every .md file under the source tree's docs/, sorted, then the notes
    beside the benchmark runs (bench/results/*.md)."""
    source = Path(source)
    readme = Path(readme) if readme else source / "README.md"
    docs = sorted(p for p in (source / "docs").rglob("*.md") if p.is_file())
    docs += sorted(p for p in (source / "bench" / "results").glob("*.md") if p.is_file())
    return [readme] + [p for p in docs if p.resolve() != readme.resolve()]


def doc_name(path, source) -> str:
    """A document's name in the check table: its path relative to the source tree, with '/'
    (README.md, docs/cli.md); a file outside the tree keeps its own name."""
    path, source = Path(path).resolve(), Path(source).resolve()
    try:
        return path.relative_to(source).as_posix()
    except ValueError:
        return path.name


def outside_fences(text: str) -> List[Tuple[int, str]]:
    """(line number, line) of every line outside fenced blocks (fences themselves left out)."""
    out = []
    fence = None
    for n, ln in enumerate(text.splitlines(), 1):
        m = re.match(r"^ {0,3}(`{3,}|~{3,})", ln)
        if m:
            if fence is None:
                fence = m.group(1)
            elif m.group(1)[0] == fence[0] and len(m.group(1)) >= len(fence) and not ln.strip()[len(m.group(1)):].strip():
                fence = None
            continue
        if fence is None:
            out.append((n, ln))
    return out


_HEADING = re.compile(r"^ {0,3}(#{1,6})\s+(.*?)(?:\s+#+)?\s*$")


def headings(text: str) -> List[Tuple[int, int, str]]:
    """(line, level, text) of every ATX heading outside fenced blocks."""
    out = []
    for n, ln in outside_fences(text):
        m = _HEADING.match(ln)
        if m:
            out.append((n, len(m.group(1)), m.group(2)))
    return out


def slug(heading: str) -> str:
    """The anchor GitHub gives a heading: links reduced to their text, lower case, every
    character but letters, digits, '_', '-' and blanks dropped, blanks made '-'."""
    s = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip()).lower()
    s = re.sub(r"[^\w\- ]", "", s)
    return s.replace(" ", "-")


def anchors(text: str) -> Dict[str, int]:
    """Every heading's anchor -> its line; a repeated anchor gets -1, -2, ... as on GitHub."""
    out: Dict[str, int] = {}
    seen: Dict[str, int] = {}
    for n, _, h in headings(text):
        base = slug(h)
        a = base
        if base in seen:
            seen[base] += 1
            a = f"{base}-{seen[base]}"
        else:
            seen[base] = 0
        out[a] = n
    return out


_LINK = re.compile(r"(?<!!)\[((?:[^\[\]]|\[[^\]]*\])*)\]\(\s*<?([^)\s>]*)>?(?:\s+\"[^\"]*\")?\s*\)")


def links(text: str) -> List[Tuple[int, str, str]]:
    """(line, link text, target) of every inline link outside fenced blocks and code spans."""
    out = []
    for n, ln in outside_fences(text):
        plain = re.sub(r"(`+)(.+?)\1", lambda m: " " * len(m.group(0)), ln)
        for m in _LINK.finditer(plain):
            out.append((n, m.group(1), m.group(2)))
    return out


def split_target(target: str) -> Tuple[str, Optional[str]]:
    """A link target as (path, anchor): ("docs/cli.md", "log2map"), ("", "top"), or
    (path, None) without an anchor."""
    path, sep, anchor = target.partition("#")
    return path, (anchor if sep else None)
