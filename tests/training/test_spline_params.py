"""The B-spline head with learned parameters: each decoded point sits at a spline parameter of the decoder's own."""

from dataclasses import replace

import numpy as np
import pytest
import torch
from scipy.interpolate import BSpline

from curve_vae.geometry import clamped_uniform_knots
from curve_vae.training.checkpoint import widen
from curve_vae.training.config import ModelConfig
from curve_vae.training.model import VAE, bspline_basis, increments_to_params, last_span_mask


@pytest.mark.parametrize("n_ctrl", [4, 10, 31])
def test_the_basis_is_scipys_design_matrix_at_any_parameter_and_at_both_ends(n_ctrl):
    knots = clamped_uniform_knots(n_ctrl, 3)
    u = np.concatenate([[0.0, 1.0], np.random.default_rng(n_ctrl).uniform(size=200), knots])
    t = torch.tensor(knots)
    got = bspline_basis(torch.tensor(u), t, last_span_mask(t), 3).numpy()
    np.testing.assert_allclose(got, BSpline.design_matrix(u, knots, 3).toarray(), rtol=0, atol=1e-14)


def test_equal_logits_give_the_even_parameters_and_any_logits_run_from_0_to_1_increasing():
    np.testing.assert_allclose(increments_to_params(torch.zeros(1, 160))[0], np.linspace(0, 1, 161), atol=1e-7)
    u = increments_to_params(torch.randn(5, 160, dtype=torch.float64) * 4)
    assert torch.all(u[:, 0] == 0) and torch.all(u[:, -1] == 1) and torch.all(u.diff(dim=1) > 0)


def test_a_model_widened_to_learned_parameters_decodes_as_before_and_learns_them():
    torch.manual_seed(0)
    cfg = ModelConfig(variant="cnn1", spline_ctrl=31)
    old = VAE(cfg).eval()
    new = VAE(replace(cfg, spline_params=True))
    new.load_state_dict(widen(old.state_dict(), new))
    new.eval()
    z = torch.randn(4, 32)
    curves, ctrl, params = new.decoder.decode_params(z)
    want, want_ctrl = old.decoder.decode(z)
    torch.testing.assert_close(ctrl, want_ctrl)
    torch.testing.assert_close(curves, want, atol=1e-4, rtol=0)  # the same points, at i/160
    torch.testing.assert_close(params, torch.linspace(0, 1, 161).expand(4, -1), atol=1e-6, rtol=0)
    # a loss that wants the points slid along the curve reaches the parameter channel
    new.train()
    target = torch.matmul(
        torch.tensor(BSpline.design_matrix(np.linspace(0, 1, 161) ** 2, clamped_uniform_knots(31, 3), 3).toarray()),
        ctrl.detach().double(),
    ).float()
    loss = (new.decoder.decode_params(z)[0] - target).square().mean()
    loss.backward()
    last = new.decoder.features[-1]
    assert last.weight.grad[:, 2].abs().sum() > 0 and last.bias.grad[2] != 0


def test_learned_parameters_need_the_spline_head():
    with pytest.raises(ValueError, match="spline_params needs the B-spline head"):
        ModelConfig(spline_params=True)
    assert not ModelConfig(spline_ctrl=31).same_weights(ModelConfig(spline_ctrl=31, spline_params=True))
    assert ModelConfig(spline_ctrl=31, spline_params=True).same_weights(ModelConfig(spline_ctrl=10, spline_params=True))


def test_learning_only_the_parameters_leaves_every_other_weight_and_statistic_as_it_was():
    torch.manual_seed(0)
    model = VAE(ModelConfig(variant="cnn1", spline_ctrl=31, spline_params=True))
    trained = model.learn_only_params()
    model.train()
    before = {k: v.clone() for k, v in model.state_dict().items()}
    opt = torch.optim.Adam(trained, lr=1e-2)
    for _ in range(3):
        loss = (model(torch.rand(8, 161, 2) * 128)[0] - 64).square().mean()
        opt.zero_grad()
        loss.backward()
        opt.step()
    after = model.state_dict()
    last = f"decoder.features.{len(model.decoder.features) - 1}"
    assert [k for k in before if not torch.equal(before[k], after[k])] == [f"{last}.weight", f"{last}.bias"]
    torch.testing.assert_close(after[f"{last}.weight"][:, :2], before[f"{last}.weight"][:, :2], rtol=0, atol=0)
    assert not torch.equal(after[f"{last}.weight"][:, 2], before[f"{last}.weight"][:, 2])
    with pytest.raises(ValueError, match="spline_params"):
        VAE(ModelConfig(variant="cnn1", spline_ctrl=31)).learn_only_params()
