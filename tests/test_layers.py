"""The import graph: geometry at the bottom, the inference package on it, the HTTP layer and training beside each other
on top of inference, the command line on top of all. A module imports only from its own layer or below, so no cycle
runs between layers; the service and inference never import torch, and the service reaches onnxruntime only through
inference."""

from __future__ import annotations

import ast
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Each part of the package, and the parts it may import (besides itself).
ALLOWED: dict[str, set[str]] = {
    "curve_vae.errors": set(),  # the exceptions' one root: beneath every layer
    "curve_vae.geometry": set(),
    "curve_vae.base": {"curve_vae.geometry"},  # files, npy, progress, the package's __init__
    "curve_vae.inference": {"curve_vae.geometry", "curve_vae.base"},
    "curve_vae.client": {"curve_vae.geometry", "curve_vae.base", "curve_vae.inference"},
    "curve_vae.service": {"curve_vae.geometry", "curve_vae.base", "curve_vae.inference"},
    "curve_vae.training": {"curve_vae.geometry", "curve_vae.base", "curve_vae.inference"},
    "curve_vae.triton": {"curve_vae.geometry", "curve_vae.base", "curve_vae.inference"},
    "curve_vae.distributed": {"curve_vae.geometry", "curve_vae.base", "curve_vae.inference"},
    # generation metrics and prior reports: evaluation, beside the serving core, not in it
    "curve_vae.evaluation": {"curve_vae.geometry", "curve_vae.base", "curve_vae.inference"},
    "curve_vae.commands": {
        "curve_vae.geometry",
        "curve_vae.base",
        "curve_vae.inference",
        "curve_vae.client",
        "curve_vae.training",
        "curve_vae.triton",
        "curve_vae.distributed",
        "curve_vae.evaluation",
    },
}
for _part_name, _allowed in ALLOWED.items():  # the exceptions' root is beneath every layer
    if _part_name != "curve_vae.errors":
        _allowed.add("curve_vae.errors")
#: `curve-vae serve` is the one command that starts the HTTP layer.
SERVE_ENTRY = ("curve_vae.cli", "curve_vae.service.server")
NO_TORCH = (
    "curve_vae.geometry",
    "curve_vae.base",
    "curve_vae.inference",
    "curve_vae.service",
    "curve_vae.client",
    "curve_vae.evaluation",
)
#: Modules of those parts that exist for torch users: imported only by them, never by the rest.
FOR_TORCH = ("curve_vae.client.dataset",)


def _modules() -> dict[str, Path]:
    tool = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    roots = {"curve_vae": ROOT / "curve_vae", **{n: ROOT / p for n, p in tool["package-dir"].items()}}
    out = {}
    for name, root in roots.items():
        for path in root.rglob("*.py"):
            rel = path.relative_to(root).with_suffix("")
            parts = [p for p in rel.parts if p != "__init__"]
            out.setdefault(".".join([name, *parts]), path)
    return out


def _part(module: str) -> str:
    for part in sorted(ALLOWED, key=len, reverse=True):
        if module == part or module.startswith(part + "."):
            return part
    if module in ("curve_vae", "curve_vae.cli"):
        return "curve_vae.commands"
    return "curve_vae.base"  # curve_vae.files, .npy, .progress


def _imports(path: Path) -> list[tuple[int, str]]:
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out += [(node.lineno, node.module)]
            out += [(node.lineno, f"{node.module}.{a.name}") for a in node.names if node.module == "curve_vae"]
    return out


MODULES = _modules()


@pytest.mark.parametrize("module", sorted(MODULES))
def test_a_module_imports_only_its_own_layer_or_below(module):
    mine = _part(module)
    for line, name in _imports(MODULES[module]):
        if name.split(".")[0] == "torch":
            assert not module.startswith(NO_TORCH) or module in FOR_TORCH, f"{module}:{line} imports torch"
        if name.split(".")[0] == "onnxruntime":  # the HTTP layer asks inference for what onnxruntime knows
            assert not module.startswith("curve_vae.service"), f"{module}:{line} imports onnxruntime"
        if name.startswith(FOR_TORCH):
            assert module in FOR_TORCH or _part(module) == "curve_vae.commands", f"{module}:{line} imports {name}"
        if not name.startswith("curve_vae.") or name == "curve_vae.__version__":
            continue
        if (module, name) == SERVE_ENTRY:
            continue
        theirs = _part(name)
        assert theirs == mine or theirs in ALLOWED[mine], f"{module}:{line} imports {name} ({theirs} above {mine})"


def test_the_layers_are_where_the_modules_are():
    parts = {_part(m) for m in MODULES}
    assert {"curve_vae.geometry", "curve_vae.inference", "curve_vae.service", "curve_vae.training"} <= parts
