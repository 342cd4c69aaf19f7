"""service.limits: one table of bounds, checked on requests and stated in the published schema."""

from __future__ import annotations

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
