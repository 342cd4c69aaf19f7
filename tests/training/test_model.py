"""training/model.py: shapes for every variant and latent size; mean decoding at inference; the B-spline head with
learned parameters (each decoded point at a spline parameter of the decoder's own)."""

from dataclasses import replace

import numpy as np
import pytest
import torch
from scipy.interpolate import BSpline

from curve_vae.geometry import clamped_uniform_knots
from curve_vae.training.checkpoint import widen
from curve_vae.training.config import VARIANTS, ModelConfig
from curve_vae.training.model import VAE, bspline_basis, count_parameters, increments_to_params, last_span_mask


@pytest.mark.parametrize("variant", [*VARIANTS, "cnn6"])
@pytest.mark.parametrize("latent_dim", [8, 32])
def test_shapes_forward_backward(variant, latent_dim):
    torch.manual_seed(0)
    model = VAE(ModelConfig(variant=variant, latent_dim=latent_dim))
    x = torch.rand(3, 161, 2) * 128
    y, mean, log_var = model(x)
    assert y.shape == (3, 161, 2)
    assert mean.shape == log_var.shape == (3, latent_dim)
    (y.square().mean() + mean.square().mean()).backward()
    assert all(p.grad is not None for p in model.parameters())


def test_reference_architecture_size():
    m = VAE(ModelConfig())
    assert (m.encoder.feat_channels, m.encoder.feat_len) == (256, 16)  # Flatten 16×256, docs/ARCHITECTURE.md
    assert 1.8e6 < count_parameters(m) < 2.0e6


def test_eval_decodes_the_mean_and_train_samples():
    torch.manual_seed(0)
    m = VAE(ModelConfig(variant="cnn1"))
    x = torch.rand(4, 161, 2) * 128
    m.eval()
    with torch.no_grad():
        a, mean, _ = m(x)
        b, _, _ = m(x)
        assert torch.equal(a, b)
        assert torch.allclose(a, m.decoder(mean))
    m.train()
    with torch.no_grad():
        c, _, _ = m(x)
        d, _, _ = m(x)
    assert not torch.allclose(c, d), "training forward samples z = μ + σ·ε"


def test_output_can_be_negative():
    # The reference code's output ReLU would clamp coordinates at 0; ours has none.
    m = VAE(ModelConfig(variant="cnn1")).eval()
    with torch.no_grad():
        m.decoder.features[-1].weight.zero_()
        m.decoder.features[-1].bias.fill_(-2.0)  # normalised −2 → 64 − 2·64 = −64 px
        y = m.decoder(torch.zeros(1, 32))
    torch.testing.assert_close(y, torch.full((1, 161, 2), -64.0))


@pytest.mark.parametrize("variant", VARIANTS)
def test_decoder_prefix_equals_the_full_stack_in_eval(variant):
    torch.manual_seed(0)
    model = VAE(ModelConfig(variant=variant)).eval()
    for m in model.modules():  # non-trivial running statistics, so BatchNorm matters
        if isinstance(m, torch.nn.BatchNorm1d):
            m.running_mean.uniform_(-0.5, 0.5)
            m.running_var.uniform_(0.5, 2.0)
    z = torch.randn(16, 32)
    with torch.no_grad():
        prefix, full = model.decoder(z), model.decoder(z, full=True)
    assert prefix.shape == full.shape == (16, 161, 2)
    # float32 rounding of outputs around 64 px, in units of the network's scale (64 px)
    assert torch.allclose(prefix / 64, full / 64, atol=1e-5, rtol=0)
    crops = model.decoder.crops
    assert crops[-1] == 161 and len(crops) == len(model.decoder.features)


def test_decoder_prefix_is_much_shorter_than_the_full_stack():
    decoder = VAE(ModelConfig()).decoder
    lengths = [m.shape[-1] for m in _layer_inputs(decoder)]
    assert decoder.crops == [7, 7, 7, 21, 19, 19, 19, 56, 54, 54, 54, 161]
    assert lengths == [16, 18, 18, 54, 54, 56, 56, 168, 168, 172, 172, 516]


def _layer_inputs(decoder):
    x = torch.zeros(2, *decoder.feat_shape)
    inputs = []
    with torch.no_grad():
        for layer in decoder.features:
            inputs.append(x)
            x = layer(x)
    return inputs


def test_training_runs_the_full_decoder_stack():
    torch.manual_seed(0)
    decoder = VAE(ModelConfig()).decoder.train()
    z = torch.randn(8, 32)
    with torch.no_grad():
        default, full, prefix = decoder(z), decoder(z, full=True), decoder(z, full=False)
    assert torch.equal(default, full)  # BatchNorm's batch statistics over the whole maps
    assert not torch.allclose(default, prefix, atol=1e-3)  # …which the prefix path would change


def test_building_a_model_leaves_batchnorm_statistics_untouched():
    model = VAE(ModelConfig())  # shape probing at construction must not count as a batch
    assert model.training
    for m in model.modules():
        if isinstance(m, torch.nn.BatchNorm1d):
            assert torch.equal(m.running_mean, torch.zeros_like(m.running_mean))
            assert torch.equal(m.running_var, torch.ones_like(m.running_var))
            assert m.num_batches_tracked.item() == 0


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
