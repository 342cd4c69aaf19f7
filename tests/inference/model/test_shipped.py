"""inference.model.shipped: the shipped models by name and how a model directory is named on the command line — a
name, a
path, or nothing (the default), a directory of a shipped model's name in the working directory winning over it."""

from pathlib import Path

import pytest

from curve_vae.inference.model.shipped import NAMED, SHIPPED, model_directory
from tests.helpers import ROOT


def test_the_shipped_models_live_beside_the_inference_package():
    # in this checkout: models/ at the repository root (package-dir maps curve_vae.models there)
    assert SHIPPED == ROOT / "models"
    assert NAMED == {"default": SHIPPED, "paper": SHIPPED / "paper"}


@pytest.mark.parametrize("value", [None, ""], ids=["None", "empty"])
def test_nothing_named_is_the_default_model(value):
    assert model_directory(value) == SHIPPED


@pytest.mark.parametrize("name", ["default", "paper"])
def test_a_shipped_models_name_is_its_directory(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # no directory of that name here
    assert model_directory(name) == NAMED[name]


def test_a_directory_of_a_shipped_models_name_is_taken_as_a_path(tmp_path, monkeypatch):
    # a user's own ./paper must not be shadowed by the shipped model of that name
    (tmp_path / "paper").mkdir()
    monkeypatch.chdir(tmp_path)
    assert model_directory("paper") == Path("paper")


@pytest.mark.parametrize("value", ["runs/latest/export", Path("/opt/model"), "missing-dir"])
def test_anything_else_is_a_path_as_given(value):
    assert model_directory(value) == Path(value)
