"""One exception root: every exception class the project defines descends from `curve_vae.errors.CurveVaeError`,
through the branch of its kind, and keeps the builtin base callers caught before."""

from __future__ import annotations

import ast
import importlib

import pytest

from curve_vae import errors
from curve_vae.client.errors import ApiError, RetriesExhausted
from curve_vae.curvefiles.common import CurveFileError
from curve_vae.geometry.adapt import BeyondFloat32
from curve_vae.inference.errors import InputError
from curve_vae.inference.model.graphs import Cancelled
from curve_vae.inference.model.manifest import ModelLoadError
from curve_vae.service.oip import OipError
from tests.test_layers import MODULES

EXCEPTION_NAMES = ("Error", "Exception", "Exhausted", "Cancelled", "Float32", "Input", "Work")


def _defined_classes() -> list[tuple[str, str]]:
    """(module, class) of every class statement whose base looks like an exception (…Error, …Exception, the
    branches of curve_vae.errors)."""
    out = []
    for module, path in sorted(MODULES.items()):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef):
                bases = [b.id if isinstance(b, ast.Name) else getattr(b, "attr", "") for b in node.bases]
                if any(b.endswith(EXCEPTION_NAMES) for b in bases):
                    out.append((module, node.name))
    return out


DEFINED = _defined_classes()


def test_the_scan_finds_the_projects_exceptions():
    names = {name for _, name in DEFINED}
    assert {"InputError", "ModelLoadError", "ApiError", "OipError", "Cancelled", "CurveFileError"} <= names


@pytest.mark.parametrize(("module", "name"), DEFINED)
def test_every_exception_descends_from_the_one_root(module, name):
    cls = getattr(importlib.import_module(module), name)
    assert issubclass(cls, errors.CurveVaeError), f"{module}.{name} is outside curve_vae.errors.CurveVaeError"


@pytest.mark.parametrize(
    ("cls", "branch", "builtin"),
    [
        (InputError, errors.InvalidInput, ValueError),
        (BeyondFloat32, errors.InvalidInput, ValueError),
        (CurveFileError, errors.InvalidInput, ValueError),
        (ModelLoadError, errors.ModelError, RuntimeError),
        (Cancelled, errors.CancelledWork, Exception),
        (OipError, errors.ProtocolError, Exception),
        (ApiError, errors.ClientError, RuntimeError),
        (RetriesExhausted, errors.ClientError, RuntimeError),
    ],
)
def test_each_kind_sits_on_its_branch_and_keeps_its_builtin_base(cls, branch, builtin):
    assert issubclass(cls, branch) and issubclass(cls, builtin)


def test_one_except_catches_an_input_error_by_its_kind():
    with pytest.raises(errors.InvalidInput, match=r"curves\[2\]\[17\]: not finite"):
        raise InputError(("curves", 2, 17), "not finite")
