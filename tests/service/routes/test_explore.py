"""POST /explore (service.routes.generate) on the shipped model: the grid around a curve along the directions the
data varies most, in the curve's own frame, its middle the curve's reconstruction; bad requests name their field."""

from __future__ import annotations

import numpy as np
import pytest
from fastapi.testclient import TestClient

from curve_vae.geometry import resample
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings
from tests.helpers import SHIPPED

T = np.linspace(0, np.pi, 80)
ARCH = np.c_[200 + 100 * np.cos(T), 300 + 80 * np.sin(T)]


@pytest.fixture(scope="module")
def shipped():
    with TestClient(create_app(Settings(model_dir=SHIPPED))) as client:
        yield client


def _apart(a: np.ndarray, b: np.ndarray) -> float:
    """The farthest any point of `a` lies from the polyline `b` (densely resampled by arc length)."""
    dense = resample(b, 4000)
    return float(np.sqrt(((a[:, None, :] - dense[None]) ** 2).sum(-1).min(axis=1)).max())


def test_the_grid_surrounds_the_curves_reconstruction_in_its_own_frame(shipped):
    body = {"curves": [ARCH.tolist()]}
    r = shipped.post("/explore", json=body).json()
    grid = np.array(r["curves"])
    assert grid.shape == (9, 80, 2) and r["prior"] == "learned" and len(r["valid"]) == 9
    assert r["offsets"][4] == [0, 0] and r["directions"][0]["share"] >= r["directions"][1]["share"] > 0
    own = np.array(shipped.post("/reconstruct", json=body).json()["curves"][0])
    diagonal = np.hypot(*np.ptp(ARCH, axis=0))
    # the middle: the curve as the model reads it, the same shape (its points spread evenly in the spline's parameter,
    # the reconstruction's placed closest to the caller's: compared as shapes, each point to the other's polyline)
    assert _apart(grid[4], own) < 0.01 * diagonal and _apart(own, grid[4]) < 0.01 * diagonal
    away = [np.abs(g - grid[4]).max() / diagonal for g in grid]
    assert min(a for i, a in enumerate(away) if i != 4) > 0.02  # the neighbours differ from it, visibly ...
    assert max(away) < 1.0  # ... and stay in its frame, near it
    moved = np.array(shipped.post("/explore", json={"curves": [(ARCH + [1000, -500]).tolist()]}).json()["curves"])
    assert np.allclose(moved, grid + [1000, -500], atol=1e-6 * 1000)  # the caller's plane, wherever the curve is


def test_a_wider_spread_goes_farther_along_one_direction(shipped):
    rows = {}
    for spread in (1.0, 2.0):
        r = shipped.post("/explore", json={"curves": [ARCH.tolist()], "steps": 3, "directions": 1, "spread": spread})
        rows[spread] = np.array(r.json()["curves"])
        assert r.json()["offsets"] == [[-spread], [0.0], [spread]]
    assert all(np.abs(rows[2.0][i] - rows[2.0][1]).max() > np.abs(rows[1.0][i] - rows[1.0][1]).max() for i in (0, 2))


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"curves": [ARCH.tolist()] * 2}, "curves"),
        ({"steps": 9, "directions": 4}, "body"),
        ({"prior": "nope"}, "prior"),
        ({"spread": 0}, "spread"),
        ({"steps": 1}, "steps"),
    ],
)
def test_a_bad_request_names_what_is_wrong(shipped, change, field):
    r = shipped.post("/explore", json={"curves": [ARCH.tolist()], **change})
    assert r.status_code == 422 and r.json()["detail"].startswith(field), r.json()
