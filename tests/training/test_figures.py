"""training/figures.py: the evaluation's figures. A latent sweep runs eq. 9 from one curve to the other; the figures
are PNG files written whole (no partial file left), from a run's log or from curves."""

from __future__ import annotations

import json

import numpy as np
import pytest

from curve_vae.training import figures as F
from tests.helpers import bspline_curves

PNG = b"\x89PNG\r\n\x1a\n"


def _flat_codec():
    """An encoder that flattens a curve into its latent and a decoder that folds it back: eq. 9 is point-wise."""
    return (lambda c: np.asarray(c).reshape(len(c), -1)), (lambda z: np.asarray(z).reshape(len(z), -1, 2))


def test_a_latent_sweep_runs_from_the_first_curve_to_the_second():
    a, b = bspline_curves(2, 20, seed=1)
    sweep = F.latent_sweep(*_flat_codec(), a, b, steps=5)
    assert sweep.shape == (5, 20, 2)
    for w, c in zip([1.0, 0.75, 0.5, 0.25, 0.0], sweep):
        np.testing.assert_allclose(c, w * a + (1 - w) * b)


def test_the_training_figure_is_drawn_from_the_log_blank_lines_and_all(tmp_path):
    rows = [
        {"epoch": e, "train_mse": 1 / e, "val_mse": 1.2 / e, "train_kl": 3.0, "train_lap": 0.01, "lr": 1e-3 / e}
        for e in (1, 2, 3)
    ]
    log = tmp_path / "log.jsonl"
    log.write_text("\n".join(json.dumps(r) for r in rows) + "\n\n")
    F.plot_training(log, tmp_path / "training.png")
    assert (tmp_path / "training.png").read_bytes().startswith(PNG)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["log.jsonl", "training.png"]  # nothing half-written left


@pytest.mark.parametrize(
    "draw",
    [
        pytest.param(lambda c, p: F.plot_reconstructions(c, c + 1.0, p, n=3), id="reconstructions"),
        pytest.param(lambda c, p: F.plot_samples(c, c[::-1], p, n=4), id="samples"),
        pytest.param(lambda c, p: F.plot_beside(list(c), list(c[::-1]), p, n=3, title="t"), id="beside"),
        pytest.param(lambda c, p: F.plot_tangents([c[0], c[1]], ["a", "b"], p), id="tangents"),
        pytest.param(lambda c, p: F.plot_triplet(*_flat_codec(), c, p, steps=3), id="triplet"),
    ],
)
def test_each_figure_of_curves_is_a_png_written_whole(tmp_path, draw):
    curves = bspline_curves(4, 161, seed=2)
    path = tmp_path / "figure.png"
    draw(curves, path)
    assert path.read_bytes().startswith(PNG) and [p.name for p in tmp_path.iterdir()] == ["figure.png"]


def test_a_figure_that_fails_to_draw_keeps_the_file_it_would_replace(tmp_path):
    path = tmp_path / "runs" / "figure.png"
    path.parent.mkdir()
    path.write_bytes(b"the previous figure")
    plt = F.pyplot()
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    ax.set_title("$\\unknowncommand$")  # mathtext that cannot be parsed: savefig raises
    with pytest.raises(ValueError):
        F.save_figure(fig, path)
    plt.close(fig)
    assert path.read_bytes() == b"the previous figure" and [p.name for p in path.parent.iterdir()] == ["figure.png"]
