"""The import graph, by import-linter's contracts in pyproject.toml: geometry at the bottom, the inference package on
it, the HTTP layer and training beside each other on top of inference, the command line on top of all; the service
and inference never import torch, and the service reaches onnxruntime only through inference.

import-linter reads the package from one folder, as a wheel installs it; a checkout maps geometry/, inference/,
service/, training/ and models/ into `curve_vae` from beside it (pyproject.toml's package-dir), so the contracts run
on a copy of the sources laid out as the wheel lays them out."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINT = Path(sys.executable).with_name("lint-imports")


def installed_layout(into: Path) -> Path:
    """The package's Python sources under `into`/curve_vae, as the wheel installs them; `into` to put on the path."""
    mapped = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-dir"]
    package = into / "curve_vae"
    shutil.copytree(ROOT / "curve_vae", package, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    for name, folder in mapped.items():
        shutil.copytree(
            ROOT / folder,
            into / name.replace(".", "/"),
            ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "*.onnx", "*.npz", "*.pt", "static"),
        )
    return into


def lint(layout: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(layout)}
    return subprocess.run(
        [str(LINT), "--no-cache", str(ROOT / "pyproject.toml")],
        cwd=layout,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


def _checkout_modules() -> dict[str, Path]:
    """Every module of the package in this checkout, by its dotted name: its file."""
    mapped = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-dir"]
    roots = {"curve_vae": ROOT / "curve_vae", **{n: ROOT / p for n, p in mapped.items()}}
    out = {}
    for name, root in roots.items():
        for path in root.rglob("*.py"):
            parts = [p for p in path.relative_to(root).with_suffix("").parts if p != "__init__"]
            out.setdefault(".".join([name, *parts]), path)
    return out


MODULES = _checkout_modules()


@pytest.fixture(scope="module")
def layout(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return installed_layout(tmp_path_factory.mktemp("layout"))


def test_every_import_contract_is_kept(layout):
    result = lint(layout)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "4 kept, 0 broken" in result.stdout, result.stdout


@pytest.mark.parametrize(
    ("module", "imports", "contract"),
    [
        ("curve_vae/service/_uses_torch.py", "import torch\n", "no torch where serving runs"),
        ("curve_vae/inference/_uses_client.py", "from curve_vae.client import calls\n", "layers"),
        ("curve_vae/service/_uses_ort.py", "import onnxruntime\n", "the service reaches onnxruntime through inference"),
        ("curve_vae/commands/_uses_service.py", "from curve_vae.service import app\n", "the command line starts"),
    ],
)
def test_an_import_across_the_layers_breaks_a_contract(tmp_path, module, imports, contract):
    layout = installed_layout(tmp_path)
    (layout / module).write_text(imports)
    result = lint(layout)
    assert result.returncode == 1, result.stdout
    broken = result.stdout.split("Broken contracts")[-1]
    assert contract in broken and Path(module).stem in broken, result.stdout
