"""training/families.py: the families, their spacings and poses: validity, spacing, pose."""

import numpy as np
import pytest

from curve_vae.geometry import fit_frame, self_intersects, signed_turning
from curve_vae.geometry.frame import MODEL_CENTER, chord_heading
from curve_vae.training import families as F


@pytest.mark.parametrize("name", [*F.RANKER_FAMILIES, *F.HELD_OUT])
def test_every_family_draws_simple_finite_curves_in_the_models_pose_and_frame(name):
    fam = {**F.RANKER_FAMILIES, **F.HELD_OUT}[name]
    curves = F.draw_family(fam, 64, np.random.default_rng(0), model_size=92.6)
    assert curves.shape == (64, 161, 2) and curves.dtype == np.float32 and np.isfinite(curves).all()
    assert not self_intersects(curves).any()
    for c in curves.astype(np.float64):
        f = fit_frame(c)
        np.testing.assert_allclose(f.center, MODEL_CENTER, atol=1e-3)
        assert f.size == pytest.approx(92.6, rel=1e-5)
        assert signed_turning(c) >= -1e-4  # counter-clockwise, as the paper's curves turn (a straight line: 0)
        assert -0.75 * np.pi - 1e-6 <= chord_heading(c) <= -0.25 * np.pi + 1e-6


def test_closed_outlines_close_either_way_round_and_stay_out_of_the_vaes_mix():
    curves = F.closed(np.random.default_rng(3), 200)
    np.testing.assert_allclose(curves[:, 0], curves[:, -1], atol=1e-12)  # once round: the loop closes
    ways = {bool(signed_turning(c) > 0) for c in curves}
    assert ways == {True, False}  # listed counter-clockwise and clockwise
    assert "closed" not in F.TRAIN_FAMILIES and F.RANKER_FAMILIES["closed"] is F.closed


def test_spacings_put_points_where_they_say():
    t = np.linspace(0, 1, F.DENSE)
    dense = np.stack([t**3, np.zeros_like(t)], 1)[None].repeat(3, axis=0)  # x = u³: parameter ≠ arc length
    rng = np.random.default_rng(1)
    param, arc, warped = F.respace(dense, 41, ["parameter", "arc_length", "warped"], rng)
    np.testing.assert_allclose(param[:, 0], np.linspace(0, 1, 41) ** 3, atol=1e-5)
    np.testing.assert_allclose(np.diff(arc[:, 0]), 1 / 40, atol=1e-4)  # evenly by arc length
    gaps = np.diff(warped[:, 0])
    assert (gaps > 0).all() and warped[0, 0] == 0 and warped[-1, 0] == pytest.approx(1)
    assert not np.allclose(warped[:, 0], param[:, 0], atol=1e-3)


def test_warps_are_monotone_and_end_to_end():
    w = F.warp(np.random.default_rng(2), 200, 161)
    assert (np.diff(w, axis=1) > 0).all()
    np.testing.assert_allclose(w[:, [0, -1]], [[0, 1]] * 200, atol=1e-12)
