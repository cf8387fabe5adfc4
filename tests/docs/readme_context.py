"""What the docs test's checks share: the run's context (the source tree, the build's tools,
scratch directories, each tool's --help), the failure they raise, and running a block's
shell commands in a fixture's scratch directory (standard library only).
"""

from __future__ import annotations

import os
import re
import subprocess
import tempfile
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

import readme_checks
from readme_blocks import Block
from readme_checks import Check

COMMAND_TIMEOUT = 120


class Failed(Exception):
    pass


class Context:
    def __init__(self, args):
        self.readme = Path(args.readme).resolve()
        self.source = Path(args.source).resolve()
        self.doc = self.readme.name  # the document being checked (readme_blocks.doc_name)
        self.path = self.readme  # its file
        self.text = ""  # its text
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
            if not (self.bin / tool).is_file():
                raise Failed(f"no {tool} in {self.bin} (--bin): build it first")
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



def make_dry_run(ctx: Context, target: str, variables: Sequence[str] = ()) -> str:
    r = subprocess.run(["make", "-n", "-C", str(ctx.source), *variables, target], capture_output=True, text=True,
                       env=ctx.env(), timeout=60)
    if r.returncode != 0:
        raise Failed(f"`make -n {' '.join([*variables, target])}` exits {r.returncode}: {short(r.stderr)}")
    return r.stdout


OPTION = re.compile(r"(?<![\w-])(--[a-zA-Z][\w-]*|-[a-zA-Z])(?![\w-])")


def option_in_help(ctx: Context, tool: str, opt: str) -> bool:
    text = ctx.help_of(tool)
    if re.fullmatch(r"--vasco_[A-Z]+", opt):  # --vasco_KEY: a placeholder
        return "--vasco_" in text
    return re.search(r"(?<![\w-])" + re.escape(opt) + r"(?![\w-])", text) is not None

