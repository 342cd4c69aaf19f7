"""service.limits: one table of bounds, checked on requests and stated in the published schema."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.inference.errors import InputError
from curve_vae.service import limits
from curve_vae.service.schemas import DecodeRequest, ReconstructRequest
from curve_vae.service.settings import Settings

C = [[0, 0], [1, 1], [2, 0], [3, 1]]


def test_each_bound_is_checked_with_a_message_naming_the_field():
    s = Settings(max_curves=2, max_points=5)
    limits.check(ReconstructRequest(curves=[C, C]), s)
    with pytest.raises(InputError, match=r"curves: at most 2 curves per request, got 3"):
        limits.check(ReconstructRequest(curves=[C] * 3), s)
    with pytest.raises(InputError, match=r"curves\[1\]: at most 5 points per curve, got 6"):
        limits.check(ReconstructRequest(curves=[C, C + [[4, 0], [5, 1]]]), s)
    with pytest.raises(InputError, match=r"n_points: at most 5, got 6"):
        limits.check(ReconstructRequest(curves=[C], n_points=6), s)
    with pytest.raises(InputError, match=r"latents: at most 2 latents per request, got 3"):
        limits.check(DecodeRequest(latents=[[0.0]] * 3), s)
    with pytest.raises(InputError, match=r"curves: at most 5 points per curve, got 9"):
        limits.check_shape("ReconstructRequest", 1, 9, s)


def test_every_bound_is_stated_where_it_is_checked():
    from curve_vae.service.openapi import openapi_spec

    comps = openapi_spec()["components"]["schemas"]
    defaults = Settings.model_construct()
    for bound in limits.BOUNDS:
        p = comps[bound.model]["properties"][bound.field]
        p = next((b for b in p.get("anyOf", []) if b.get("type") != "null"), p)
        stated = {"items": p.get("maxItems"), "per_item": p.get("items", {}).get("maxItems"), "value": p.get("maximum")}
        want = getattr(defaults, bound.setting)
        if (bound.model, bound.field) == ("AugmentRequest", "count"):
            want = max(defaults.max_curves, defaults.max_stream_curves)
        assert stated[bound.kind] == want, bound


Z = [0.0] * 32  # a valid latent


LIMITS = {"max_curves": 4, "max_points": 300, "max_body_bytes": 20_000}


@pytest.fixture
def limited(make_client):
    return make_client(**LIMITS)


C7 = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]  # a valid curve of 7 points

LIMIT_CASES = [
    pytest.param("/encode", {"curves": [C7] * 5}, "curves: at most 4 curves per request, got 5", id="too-many-curves"),
    pytest.param(
        "/fit", {"curves": [C7] * 5, "n_ctrl": 4}, "curves: at most 4 curves per request, got 5", id="fit-curves"
    ),
    pytest.param(
        "/fit",
        {"curves": [C7], "n_ctrl": 4, "n_points": 301},
        "n_points: at most 300, got 301",
        id="fit-n-points-over-limit",
    ),
    pytest.param(
        "/revolve",
        {"curve": np.linspace(0, 1, 602).reshape(301, 2).tolist()},
        "curve: at most 300 points, got 301",
        id="revolve-profile-too-long",
    ),
    pytest.param(
        "/reconstruct",
        {"curves": [C7, np.linspace(0, 1, 602).reshape(301, 2).tolist()]},
        "curves[1]: at most 300 points per curve, got 301",
        id="too-many-points",
    ),
    pytest.param(
        "/reconstruct", {"curves": [C7], "n_points": 301}, "n_points: at most 300, got 301", id="n-points-over-limit"
    ),
    pytest.param(
        "/decode", {"latents": [Z] * 5}, "latents: at most 4 latents per request, got 5", id="too-many-latents"
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C7, C], "steps": 5},
        "steps: 5 steps over 2 curves make 5 curves; at most 4",
        id="steps-over-limit",
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C7, C, C], "steps": 3},
        "steps: 3 steps over 3 curves make 6 curves",
        id="triplet-grid-over-limit",
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C7, C], "weights": [[1, 0]] * 5},
        "weights: at most 4 rows, got 5",
        id="too-many-weight-rows",
    ),
]


@pytest.mark.parametrize("path,body,detail", LIMIT_CASES)
def test_configured_limits(limited, path, body, detail):
    r = limited.post(path, json=body)
    assert r.status_code == 422, r.text
    assert r.json()["detail"].startswith(detail), r.json()["detail"]
