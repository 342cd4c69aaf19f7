"""Weight averaging and BatchNorm re-estimation (curve-vae average)."""

import numpy as np
import pytest
import torch
from torch import nn

from curve_vae.training.average import average_state_dicts, recompute_batchnorm
from curve_vae.training.config import ModelConfig
from curve_vae.training.model import VAE


def _vae(seed):
    torch.manual_seed(seed)
    return VAE(ModelConfig(variant="cnn1", latent_dim=8))


def test_average_is_the_elementwise_mean_and_keeps_counters():
    a, b = _vae(0).state_dict(), _vae(1).state_dict()
    key = next(k for k, v in a.items() if v.is_floating_point() and not torch.equal(v, b[k]))
    b_counter = next(k for k in b if k.endswith("num_batches_tracked"))
    b[b_counter] = torch.tensor(7)
    avg = average_state_dicts([a, b])
    assert list(avg) == list(a)
    torch.testing.assert_close(avg[key], (a[key] + b[key]) / 2)
    assert int(avg[b_counter]) == 7 and avg[b_counter].dtype == torch.int64
    loaded = _vae(2)
    loaded.load_state_dict(avg)  # a loadable model of the same architecture


def test_average_refuses_other_architectures():
    other = VAE(ModelConfig(variant="cnn2", latent_dim=16)).state_dict()
    with pytest.raises(ValueError, match="not the same architecture"):
        average_state_dicts([_vae(0).state_dict(), other])
    with pytest.raises(ValueError, match="nothing to average"):
        average_state_dicts([])


class _PointNorm(nn.Module):
    """(B, n, 2) curves → BatchNorm over the two coordinates."""

    def __init__(self):
        super().__init__()
        self.bn = nn.BatchNorm1d(2)

    def forward(self, x):
        return self.bn(x.transpose(1, 2))


def test_batchnorm_statistics_are_those_of_the_curves():
    rng = np.random.default_rng(0)
    curves = (rng.normal(size=(256, 161, 2)) * [3.0, 0.5] + [40.0, -7.0]).astype(np.float32)
    model = _PointNorm()
    model.bn.running_mean.fill_(123.0)  # stale statistics, as after averaging weights
    model.bn.running_var.fill_(99.0)
    recompute_batchnorm(model, curves, batch=64)
    assert not model.training
    np.testing.assert_allclose(model.bn.running_mean.numpy(), curves.reshape(-1, 2).mean(0), rtol=1e-5)
    np.testing.assert_allclose(model.bn.running_var.numpy(), curves.reshape(-1, 2).var(0), rtol=1e-3)
