"""Model shapes for every variant and latent size; mean decoding at inference."""

import pytest
import torch

from curve_vae.training.config import VARIANTS, ModelConfig
from curve_vae.training.model import VAE, count_parameters


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


def test_unknown_variant_is_rejected():
    with pytest.raises(ValueError, match="unknown variant"):
        ModelConfig(variant="resnet")


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
