"""Loss terms on hand-computed cases (paper eqs. 4, 5, 7)."""

import math

import numpy as np
import pytest
import torch

from curve_vae.training.losses import kl_divergence, laplacian, vae_loss


def test_laplacian_of_a_parabola_is_constant_including_ends():
    i = torch.arange(6, dtype=torch.float32)
    c = torch.stack([i, i**2], dim=-1)[None]  # (1, 6, 2)
    lap = laplacian(c)
    assert lap.shape == (1, 6, 2)
    torch.testing.assert_close(lap[0], torch.tensor([[0.0, 2.0]] * 6))


def test_laplacian_interior_values():
    c = torch.tensor([[[0.0, 0], [1, 0], [3, 0], [6, 1]]])
    # interior: (3-2+0, 0)=(1,0); (6-6+1, 1)=(1,1); ends copy their neighbours
    torch.testing.assert_close(laplacian(c)[0], torch.tensor([[1.0, 0], [1, 0], [1, 1], [1, 1]]))


def test_kl_zero_at_prior_and_known_value():
    z = torch.zeros(4, 8)
    assert kl_divergence(z, z).item() == 0.0
    # μ=1, log σ²=0: ½μ² = 0.5 per dimension; log σ²=log 2, μ=0: ½(2 − 1 − log 2)
    assert kl_divergence(torch.ones(2, 3), torch.zeros(2, 3)).item() == pytest.approx(0.5)
    lv = torch.full((1, 1), math.log(2.0))
    assert kl_divergence(torch.zeros(1, 1), lv).item() == pytest.approx(0.5 * (1 - math.log(2)))


def test_vae_loss_terms_and_weights():
    target = torch.zeros(2, 5, 2)
    pred = target.clone()
    pred[0, 2, 1] = 2.0  # one coordinate of 20 off by 2 → MSE 4/20; Lap of pred: 2,−4,2 at points 1..3
    mean, lv = torch.ones(2, 4), torch.zeros(2, 4)
    t = vae_loss(target, pred, mean, lv, beta=0.1, lap_weight=2.0)
    assert t["mse"].item() == pytest.approx(0.2)
    assert t["kl"].item() == pytest.approx(0.5)
    # |Lap| of pred's y over points 0..4 = 2 (copied), 2, 4, 2, 2 (copied) → 12 over 20 entries
    assert t["lap"].item() == pytest.approx(12 / 20)
    assert t["loss"].item() == pytest.approx(0.2 + 0.1 * 0.5 + 2.0 * 0.6)


def test_distance_to_a_polyline_is_the_foot_points_and_ignores_spacing():
    import shapely

    from curve_vae.geometry import random_control_points, sample_bspline
    from curve_vae.training.losses import closest_point_terms, squared_distance_to_polyline

    rng = np.random.default_rng(0)
    line = torch.tensor(sample_bspline(random_control_points(rng, 3), 321))
    points = line[:, ::7] + torch.tensor(rng.normal(0, 2.0, (3, 46, 2)))
    got = squared_distance_to_polyline(points, line).numpy()
    for p, ln, g in zip(points.numpy(), line.numpy(), got):
        want = shapely.distance(shapely.points(p), shapely.linestrings(ln)) ** 2
        np.testing.assert_allclose(g, want, rtol=1e-9, atol=1e-9)
    # the same curve at another spacing is at distance ~0 both ways; point i to point i it is far
    ctrl = random_control_points(rng, 2)
    even = torch.tensor(sample_bspline(ctrl, 161))
    fine = torch.tensor(sample_bspline(ctrl, 321))
    uneven = torch.tensor(
        np.stack(
            [
                np.stack([np.interp(np.linspace(0, 1, 161) ** 2, np.linspace(0, 1, 321), f[:, k]) for k in (0, 1)], 1)
                for f in fine.numpy()
            ]
        )
    )
    terms = closest_point_terms(uneven, fine)
    assert float(terms["mse"]) < 1e-3 and float(terms["back"]) < 1e-3
    assert float((uneven - even).square().mean()) > 10
    # gradients reach the curve
    fine.requires_grad_(True)
    closest_point_terms(uneven + 1.0, fine)["mse"].backward()
    assert fine.grad.abs().sum() > 0
