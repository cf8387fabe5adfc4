"""The type stubs (_core.pyi, written by the build's vasco_gpu_stub step with nanobind's stubgen)
are installed beside the module and cover it, and the docstrings are there."""

from __future__ import annotations

import ast
import inspect
import pydoc
from pathlib import Path

import vasco_gpu as vg
from vasco_gpu import _core

STUB = Path(vg.__file__).with_name("_core.pyi")


def _stub_names():
    tree = ast.parse(STUB.read_text())
    names = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef)} | {
                n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        elif isinstance(node, ast.FunctionDef):
            names[node.name] = None
        elif isinstance(node, ast.AnnAssign):
            names[node.target.id] = None
    return names


def test_stub_covers_the_module():
    stub = _stub_names()
    for name, obj in vars(_core).items():
        if name.startswith("_"):
            continue
        assert name in stub, f"{name} missing from {STUB}: the build's vasco_gpu_stub step did not run"
        if inspect.isclass(obj):
            public = {n for n in vars(obj) if not n.startswith("_")}
            missing = public - stub[name]
            assert not missing, f"{name}: {sorted(missing)} missing from {STUB.name}"


def test_docstrings():
    for cls in (vg.Mapper, vg.Params, vg.Scans, vg.Log, vg.Map, vg.Comparison, vg.Frame):
        assert cls.__doc__ and len(cls.__doc__) > 40, cls
    for fn in (vg.load_log, vg.read_map, vg.write_map, vg.compare, vg.Mapper.insert, vg.Mapper.render,
               vg.Mapper.finish, vg.Mapper.read):
        assert fn.__doc__ and len(fn.__doc__) > 40, fn
    text = pydoc.render_doc(vg.Mapper, renderer=pydoc.plaintext)
    for word in ("insert", "render", "finish", "backend", "cuda_mode", "GIL"):
        assert word in text
