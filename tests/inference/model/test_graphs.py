"""inference.model.graphs: one exported model's ONNX graphs as the runtime runs them (the committed untrained
fixtures) —
runs split into batches with the same answers, the B-spline head's points checked against scipy, empty batches, the
rows counted, and graphs that do not match their manifest refused with what is wrong."""

from pathlib import Path

import numpy as np
import onnxruntime as ort
import pytest
from scipy.interpolate import BSpline

from curve_vae.inference.model.graphs import ModelGraphs
from curve_vae.inference.model.manifest import Manifest, ModelLoadError
from curve_vae.inference.model.sessions import CPU, SessionConfig
from tests.helpers import bspline_curves

ONE_THREAD = SessionConfig(intra_op_threads=1)


def _open(model_dir: Path, manifest: Manifest | None = None, **options) -> ModelGraphs:
    return ModelGraphs.open(
        model_dir, manifest or Manifest.read(model_dir), providers="cpu", sessions=ONE_THREAD, **options
    )


@pytest.fixture(scope="module")
def graphs(model_dir) -> ModelGraphs:
    return _open(model_dir, batch_size=3)  # small runs: 7 curves take three


def test_the_dimensions_are_the_manifests(graphs, model_dir):
    manifest = Manifest.read(model_dir)
    assert (graphs.n_points, graphs.latent_dim, graphs.n_ctrl) == (161, 32, 31)
    assert graphs.model_size == manifest.frame.model_size
    np.testing.assert_allclose(graphs.knots, manifest.spline.knots, atol=1e-15)  # the head's knots, rebuilt
    assert graphs.has_splines and not graphs.has_params
    assert graphs.providers == [CPU] and graphs.onnxruntime_version == ort.__version__


def test_runs_split_into_batches_answer_as_one_run(graphs, runtime):
    curves = bspline_curves(7, seed=1)
    mean, log_var = graphs.encode(curves)
    whole_mean, whole_log_var = runtime.graphs.encode(curves)  # batch_size 64: one run
    assert mean.shape == log_var.shape == (7, 32) and mean.dtype == np.float32
    np.testing.assert_allclose(mean, whole_mean, rtol=1e-5, atol=1e-5)
    np.testing.assert_allclose(log_var, whole_log_var, rtol=1e-5, atol=1e-5)
    out, ctrl, params = graphs.decode(mean)
    np.testing.assert_allclose(out, runtime.graphs.decode(mean)[0], rtol=1e-5, atol=1e-4)
    assert out.shape == (7, 161, 2) and ctrl.shape == (7, 31, 2) and params is None
    np.testing.assert_array_equal(graphs.decode_model(mean), out)


def test_a_batch_is_counted_in_rows_and_run_in_batch_size_pieces(graphs, monkeypatch):
    runs: list[tuple[str, int]] = []
    run = graphs._run_graph
    monkeypatch.setattr(
        graphs, "_run_graph", lambda s, graph, x, o: runs.append((graph, len(x))) or run(s, graph, x, o)
    )
    before = dict(graphs.rows)
    graphs.decode(graphs.encode(bspline_curves(7, seed=2))[0])
    assert runs == [("encoder", 3), ("encoder", 3), ("encoder", 1), ("decoder", 3), ("decoder", 3), ("decoder", 1)]
    assert graphs.rows == {"encoder": before["encoder"] + 7, "decoder": before["decoder"] + 7}


def test_the_heads_points_are_its_spline_at_even_parameters(graphs):
    # the manifest: "curve point i is the clamped uniform cubic B-spline at u = i/160"
    z = np.random.default_rng(0).standard_normal((4, 32))
    out, ctrl, _ = graphs.decode(z)
    for o, c in zip(out, ctrl):
        want = BSpline(graphs.knots, c.astype(np.float64), 3)(np.linspace(0, 1, 161))
        np.testing.assert_allclose(o, want, atol=1e-4 * np.abs(want).max())


def test_learned_parameters_place_each_point_on_its_spline(params_model_dir):
    g = _open(params_model_dir)
    assert g.has_params
    out, ctrl, params = g.decode(np.random.default_rng(1).standard_normal((3, 32)))
    assert params.shape == (3, 161) and ((params >= 0) & (params <= 1)).all()
    for o, c, u in zip(out, ctrl, params):
        want = BSpline(g.knots, c.astype(np.float64), 3)(u.astype(np.float64))
        np.testing.assert_allclose(o, want, atol=1e-4 * np.abs(want).max())


def test_a_model_without_a_head_decodes_points_alone(raw_model_dir):
    g = _open(raw_model_dir, warm_up=False)
    out, ctrl, params = g.decode(np.zeros((2, 32)))
    assert out.shape == (2, 161, 2) and ctrl is None and params is None
    assert not g.has_splines and g.knots is None and g.spline_degree == 0


def test_empty_batches_come_back_empty_without_a_run(graphs, monkeypatch):
    monkeypatch.setattr(graphs, "_run_graph", lambda *a: pytest.fail("an empty batch ran a graph"))
    mean, log_var = graphs.encode(np.zeros((0, 161, 2)))
    assert mean.shape == log_var.shape == (0, 32)
    out, ctrl, params = graphs.decode(np.zeros((0, 32)))
    assert out.shape == (0, 161, 2) and out.dtype == np.float32 and ctrl.shape == (0, 31, 2) and params is None


MISMATCHES = {
    "point count": ({"n_points": 100}, r"encoder input \w+ has shape \['batch', 161, 2\], expected \[batch, 100, 2\]"),
    "latent size": ({"latent_dim": 16}, r"decoder input \w+ has shape \['batch', 32\], expected \[batch, 16\]"),
}


@pytest.mark.parametrize("change, message", MISMATCHES.values(), ids=MISMATCHES.keys())
def test_graphs_that_do_not_match_the_manifest_are_refused(model_dir, change, message):
    manifest = Manifest.read(model_dir).model_copy(update=change)
    with pytest.raises(ModelLoadError, match="graphs do not match the manifest: " + message):
        _open(model_dir, manifest, warm_up=False)


def test_a_decoder_without_the_manifests_head_is_refused(model_dir, raw_model_dir):
    # the B-spline manifest over the raw model's graphs: the decoder has no control_points output
    with pytest.raises(ModelLoadError, match=r"decoder outputs \['curves'\], expected curves, control_points"):
        _open(raw_model_dir, Manifest.read(model_dir, check_files=False), warm_up=False)
