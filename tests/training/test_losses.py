"""Loss terms on hand-computed cases (paper eqs. 4, 5, 7)."""

import math

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
