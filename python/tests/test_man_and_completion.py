"""The tools' man pages and bash completion (vasco_gpu/tools/): each tool's page names it in NAME
and SYNOPSIS and covers every option of its --help; the completion completes option names and
the values of options with choices, from the engine's registries.

The tools come from the PATH (the environment's bin/ first); the man pages from VASCO_MAN_DIR
(a build's man/) or the environment's share/man/man1 (a wheel's). Tests without them skip."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from vasco_gpu import _core

TOOLS = ("log2map", "mapdiff", "mapconvert", "bag2map", "bag2carmen", "carmen2bag", "vasco_map_node")
REPO = Path(__file__).resolve().parents[2]
COMPLETION = REPO / "vasco_gpu" / "tools" / "completion" / "vasco_gpu.bash"
PATH = os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])
NODE_HELP = REPO / "vasco_gpu" / "tools" / "man" / "vasco_map_node_help.py"


def _tool(name: str) -> str:
    found = shutil.which(name, path=PATH)
    if not found:
        pytest.skip(f"{name} is not on the PATH")
    return found


def _help(name: str) -> str:
    """The text help2man reads: the tool's --help (the node's from its help script: the node
    itself would start)."""
    command = [sys.executable, str(NODE_HELP)] if name == "vasco_map_node" else [_tool(name), "--help"]
    return subprocess.run(command, capture_output=True, text=True, timeout=60, check=True).stdout


def _help_options(text: str) -> set:
    """The options the help defines: those that start an entry (CLI11's, argparse's and
    mapconvert's own layout) and those of its usage lines, read independently of the
    completion's parser."""
    usage = re.findall(r"^(?:Usage:|usage:|\s+or:|\s+\[).*$", text, re.M)
    return set(re.findall(r"^ {0,2}(?:-\w, ?)?(--[\w-]+)", text, re.M)) | set(re.findall(r"--[\w-]+", "\n".join(usage)))


def _man_page(name: str) -> str:
    dirs = [os.environ.get("VASCO_MAN_DIR", ""), os.path.join(sys.prefix, "share", "man", "man1")]
    page = next((Path(d) / f"{name}.1" for d in dirs if d and (Path(d) / f"{name}.1").is_file()), None)
    if page is None:
        pytest.skip(f"no man page {name}.1 (set VASCO_MAN_DIR to a build's man/; needs help2man)")
    return page.read_text().replace("\\-", "-")


def _section(page: str, title: str) -> str:
    found = re.search(rf'^\.SH "?{title}"?\n(.*?)(?=^\.SH |\Z)', page, re.M | re.S)
    assert found, f"no {title} section"
    return found.group(1)


@pytest.mark.parametrize("name", TOOLS)
def test_man_page_names_the_tool_and_covers_every_option(name):
    page = _man_page(name)
    assert _section(page, "NAME").startswith(f"{name} -")
    assert re.search(rf"^\.B {name}$", _section(page, "SYNOPSIS"), re.M)
    options = _help_options(_help(name))
    assert "--version" in options
    missing = sorted(o for o in options if not re.search(rf"{re.escape(o)}(?![\w-])", page))
    assert not missing, f"{name}.1 lacks {missing}"


def _complete(*words: str) -> list:
    """What the completion offers with the cursor after the last word (as bash calls it)."""
    if not shutil.which("bash"):
        pytest.skip("no bash")
    _tool(words[0])
    quoted = " ".join("'" + w.replace("'", "'\\''") + "'" for w in words)
    script = (f"source '{COMPLETION}'\nCOMP_WORDS=({quoted}); COMP_CWORD=$((${{#COMP_WORDS[@]}} - 1))\n"
              "f=$(complete -p \"${COMP_WORDS[0]}\" | sed -E 's/.*-F ([^ ]+) .*/\\1/'); $f\n"
              "printf '%s\\n' \"${COMPREPLY[@]}\"")
    done = subprocess.run(["bash", "--norc", "-c", script], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PATH": PATH}, check=True)
    return [w for w in done.stdout.splitlines() if w]


def test_backend_values_are_the_registrys():
    # bag2map runs this environment's engine, so its backends are _core.backends()
    assert sorted(_complete("bag2map", "--backend", "")) == sorted(_core.backends())
    offered = _complete("log2map", "--backend", "cpu")
    assert offered and set(offered) <= {b for b in _core.backends() if b.startswith("cpu")} | {"cuda"}


def test_choice_values_come_from_the_schemas():
    modes = next(o["choices"] for o in _core.option_schema("map_output") if o["name"] == "mode")
    for tool in ("log2map", "bag2map", "mapconvert"):
        assert _complete(tool, "--mode", "") == modes
    assert _complete("log2map", "--mode", "=", "s") == ["scale"]  # --mode=s, split at '=' by bash


def test_formats_complete_item_by_item():
    formats = [f["extension"].lstrip(".") for f in _core.map_formats()]
    assert sorted(_complete("log2map", "--formats", "")) == sorted(formats)
    assert sorted(_complete("log2map", "--formats", "map,pn")) == sorted(
        f"map,{f}" for f in formats if f.startswith("pn"))


def test_option_names_are_the_helps():
    offered = set(_complete("bag2map", "--"))
    assert _help_options(_help("bag2map")) <= offered
    assert {"--scan-topic", "--z-band", "--info"} <= offered
    assert set(_complete("carmen2bag", "--")) == {o for o in _help_options(_help("carmen2bag"))
                                                   if o.startswith("--")}


def test_node_parameters_and_their_choices():
    from vasco_gpu.ros.settings import NODE_PARAMETERS

    names = _complete("vasco_map_node", "--ros-args", "-p", "")
    assert names == [f"{p.name}:=" for p in NODE_PARAMETERS]
    backend = next(p for p in NODE_PARAMETERS if p.name == "backend")
    assert _complete("vasco_map_node", "--ros-args", "-p", "backend:=") == [
        f"backend:={b}" for b in backend.check.names]
    assert _complete("vasco_map_node", "--") == ["--version", "--ros-args"]
