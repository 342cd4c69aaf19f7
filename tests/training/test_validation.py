"""training/validation.py: model selection's numbers on stand-in models whose reconstructions are known: eq. 4 point
by point, or each point to its closest point on the decoded curve; which of the two a run's match is measured by."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from torch import nn

from curve_vae.training.validation import reconstruct, validation_closest, validation_measure, validation_mse


class Stand(nn.Module):
    """Reconstructs each curve moved by (3, 4); densely, decodes the segment from (0, 0) to (10, 0)."""

    def __init__(self) -> None:
        super().__init__()
        self.w = nn.Parameter(torch.zeros(()))
        self.calls: list[int] = []

    def forward(self, x: torch.Tensor, dense: bool = False):
        self.calls.append(len(x))
        if dense:
            line = torch.stack([torch.linspace(0, 10, 101), torch.zeros(101)], -1)
            return line.expand(len(x), -1, -1), None, None
        return x + torch.tensor([3.0, 4.0]), None, None


def test_reconstruct_decodes_in_batches_in_eval_mode_as_float32():
    model = Stand().train()
    curves = np.arange(5 * 4 * 2, dtype=np.float64).reshape(5, 4, 2)
    out = reconstruct(model, curves, batch=2)
    assert model.calls == [2, 2, 1] and not model.training
    assert out.dtype == np.float32
    np.testing.assert_array_equal(out, curves + [3.0, 4.0])


@pytest.mark.parametrize("as_tensor", [False, True], ids=["numpy", "tensor"])
def test_the_mse_is_eq4_over_points_and_both_coordinates(as_tensor):
    curves = np.random.default_rng(0).uniform(0, 128, (6, 9, 2)).astype(np.float32)
    given = torch.from_numpy(curves) if as_tensor else curves
    assert validation_mse(Stand(), given) == pytest.approx((3**2 + 4**2) / 2)  # every point off by (3, 4)


def test_the_closest_measure_takes_each_point_to_the_decoded_curve_whatever_its_spacing():
    # on the segment from (0, 0) to (10, 0): the ends on its ends, the inner points 1 and 2 away from it
    target = torch.tensor([[0.0, 0.0], [2.0, 1.0], [5.0, -2.0], [10.0, 0.0]]).expand(3, -1, -1)
    want = (0 + 1**2 + 2**2 + 0) / (2 * 4)  # eq. 4's mean over points and both coordinates
    model = Stand()
    assert validation_closest(model, target, batch=2) == pytest.approx(want)
    assert model.calls == [2, 1]
    respaced = torch.tensor([[0.0, 0.0], [1.0, 1.0], [7.0, -2.0], [10.0, 0.0]]).expand(3, -1, -1)
    assert validation_closest(Stand(), respaced) == pytest.approx(want)  # other spacing along it: the same


@pytest.mark.parametrize(
    "match,measure",
    [
        pytest.param("index", validation_mse, id="index-eq4"),
        pytest.param("closest", validation_closest, id="closest"),
        pytest.param("twin", validation_closest, id="twin"),
        pytest.param("mixed", validation_closest, id="mixed"),
    ],
)
def test_each_match_is_selected_by_its_measure(match, measure):
    assert validation_measure(match) is measure
