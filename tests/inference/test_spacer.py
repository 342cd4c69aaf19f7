"""The spacing guesser: its inputs, its guesses, its file, and the reading it starts (pose "learned" fits
natural spacings from its guess in GUESSED_NATURAL_STEPS)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from curve_vae.errors import InvalidInput
from curve_vae.geometry import arc_length_params, random_control_points, sample_bspline
from curve_vae.geometry.bspline import evaluate_bspline
from curve_vae.inference import reader as reader_module
from curve_vae.inference.model.graphs import Cancelled, CancelToken, ModelGraphs, cancellable
from curve_vae.inference.model.manifest import Manifest
from curve_vae.inference.model.sessions import SessionConfig
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.inference.spacer import GRID, SPACER_KIND, Spacer, on_grid, spacer_inputs
from tests.helpers import natural_fits_asked
from tests.parts import save_npz, spacer_weights, with_spacer

MODELS = Path(__file__).resolve().parents[2] / "models"


@pytest.fixture(scope="module")
def spacer(closest_model_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Spacer:
    """A guesser of random weights, as the graph the runtime opens."""
    model = with_spacer(closest_model_dir, tmp_path_factory.mktemp("spaced"), spacer_weights())
    runtime = CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0)
    assert runtime.reader.spacer is not None
    return runtime.reader.spacer


def _turned(c: np.ndarray, angle: float, scale: float, shift: tuple[float, float]) -> np.ndarray:
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    return c @ rot.T * scale + np.asarray(shift)


def test_the_inputs_are_the_shapes_turning_along_its_length_whatever_its_pose():
    c = sample_bspline(random_control_points(np.random.default_rng(1), 1), 300)[0]
    x = spacer_inputs(on_grid([c]))
    assert x.shape == (1, 3, GRID) and x.dtype == np.float32
    moved = spacer_inputs(on_grid([_turned(c, 2.0, 7.5, (-300.0, 40.0))]))
    np.testing.assert_allclose(moved, x, atol=2e-5)
    mirrored = spacer_inputs(on_grid([c * [-1.0, 1.0]]))
    np.testing.assert_allclose(mirrored[:, 0], -x[:, 0], atol=2e-5)  # the turning changes sign, nothing else
    np.testing.assert_allclose(mirrored[:, 1:], x[:, 1:], atol=2e-5)
    assert x[0, 0, 0] == x[0, 0, -1] == 0.0 and x[0, 2, 0] == -1.0 and x[0, 2, -1] == 1.0
    line = spacer_inputs(on_grid([np.c_[np.linspace(0, 5, 40), np.zeros(40)]]))
    assert not line[:, :2].any()  # a straight line does not turn


def test_guesses_rise_from_0_to_1_at_each_curves_own_points_and_follow_the_shape(spacer: Spacer):
    rng = np.random.default_rng(2)
    curves = [sample_bspline(random_control_points(rng, 1), n)[0] for n in (20, 161, 777)]
    guesses = spacer.guesses(curves)
    for c, u in zip(curves, guesses):
        assert u.shape == (len(c),) and u[0] == 0.0 and u[-1] == pytest.approx(1.0) and (np.diff(u) >= 0).all()
    again = spacer.guesses([_turned(c, -0.7, 0.01, (3.0, 3.0)) for c in curves])
    for u, v in zip(guesses, again):
        np.testing.assert_allclose(v, u, atol=1e-5)
    assert spacer.guesses([]) == []
    # a mirror image is read the way round its curve is: alike to the last bit (in a batch of the same curves)
    for u, v in zip(guesses, spacer.guesses([c * [-1.0, 1.0] for c in curves])):
        np.testing.assert_array_equal(v, u)


def test_a_graph_of_another_shape_or_numpy_weights_are_refused(tmp_path: Path):
    graphs = ModelGraphs.open(MODELS, Manifest.read(MODELS), providers="cpu", warm_up=False)
    with pytest.raises(InvalidInput, match=r"its graph takes \(any, 161, 2\); this part takes \(any, 3, 128\)"):
        Spacer.load(MODELS / "encoder.onnx", graphs, sessions=SessionConfig())
    old = save_npz(tmp_path / "spacer.npz", SPACER_KIND, spacer_weights())
    with pytest.raises(InvalidInput, match=f"curve-vae spacer export {old} --model-dir {tmp_path} --force"):
        Spacer.load(old, graphs, sessions=SessionConfig())
    (tmp_path / "broken.onnx").write_bytes(b"not a graph")
    with pytest.raises(InvalidInput, match="onnxruntime cannot open it"):
        Spacer.load(tmp_path / "broken.onnx", graphs, sessions=SessionConfig())
    assert "spacer" not in graphs.parts  # nothing half-opened is left behind


def test_the_learned_parts_run_as_the_model_graphs_do_counted_and_cancellable(shipped_runtime):
    """The ranker and the guesser run through the model's ModelGraphs: their rows counted beside the encoder's and
    the decoder's, and a cancelled request stops before their run."""
    graphs = shipped_runtime.graphs
    assert set(graphs.parts) == {"ranker", "spacer"}
    before = dict(graphs.rows)
    guesses = shipped_runtime.reader.spacer.guesses([np.stack([np.linspace(0, 1, 30), np.linspace(0, 1, 30) ** 2], 1)])
    assert len(guesses) == 1 and graphs.rows["spacer"] == before["spacer"] + 1
    token = CancelToken()
    token.cancel("the client disconnected")
    with cancellable(token), pytest.raises(Cancelled, match="the client disconnected"):
        shipped_runtime.reader.ranker.scores(np.zeros((3, graphs.n_points, 2)))
    assert graphs.rows["ranker"] == before["ranker"]


def test_the_shipped_guesser_puts_the_papers_curves_drawn_by_arc_length_near_their_own_parameters(shipped_runtime):
    """Its guesses of the paper's test-like curves drawn by arc length: within a few hundredths of the generator's
    parameters (trained on the paper's curves; its held-out error is in the manifest), far closer than the arc-length
    fractions it replaces as the fit's start."""
    spacer = shipped_runtime.reader.spacer
    assert spacer is not None and shipped_runtime.manifest.spacer is not None
    ctrl = random_control_points(np.random.default_rng(11), 40)
    truth = [arc_length_params(c, 161) for c in ctrl]
    drawn = [evaluate_bspline(c, u) for c, u in zip(ctrl, truth)]
    guessed = spacer.guesses(drawn)
    off = np.array([np.sqrt(((g - u) ** 2).mean()) for g, u in zip(guessed, truth)])
    by_arc = np.array([np.sqrt(((np.linspace(0, 1, 161) - u) ** 2).mean()) for u in truth])
    assert np.median(off) < 0.03 and np.median(off) < 0.3 * np.median(by_arc), (np.median(off), np.median(by_arc))


def test_the_learned_reading_starts_its_natural_fit_from_the_guess(shipped_runtime, monkeypatch):
    """Pose "learned" with spacing "search" fits natural spacings from the guesser's guesses in GUESSED_NATURAL_STEPS,
    the arc-length start's fit kept as GUESSED_ARC_READING says; the search and spacing "natural" keep the fit's own
    starts and steps (and every curve's arc-length reading)."""
    scout, steps = reader_module.GUESSED_NATURAL_STEPS
    spacer = shipped_runtime.reader.spacer
    arc = reader_module.GUESSED_ARC_READING
    expected = {
        Reading(pose="learned", spacing="search"): {
            "scout": scout,
            "steps": steps,
            "guess": spacer.guesses,
            "arc_reading": arc,
        },
        Reading(pose="search", spacing="search"): {},
        Reading(pose="learned", spacing="natural"): {},
    }
    asked = natural_fits_asked(shipped_runtime, monkeypatch, list(expected))
    assert asked == [[fit] for fit in expected.values()]
