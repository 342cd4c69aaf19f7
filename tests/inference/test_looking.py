"""Looking again after reading (inference.looking): z ← z + E(x) − E(D(z)) on the ONNX graphs, a step kept only where
it brings the answer closer, every curve of a request in one batch a pass; the field's bounds, its cost counted, the
latent /encode returns, and `refine` starting from it."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.geometry import resample
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.training.suite import relative_rmse
from tests.helpers import bspline_curves
from tests.inference.test_untangling import naca


def _plain(rt: CurveRuntime, curves: list[np.ndarray], reading: Reading):
    """The answer before its ends are kept and before untangling: what the look compares."""
    rt.reader.untangle = rt.reader.keep_ends = False
    try:
        return rt.reconstruct(curves, reading)
    finally:
        rt.reader.untangle = rt.reader.keep_ends = True


def test_one_look_is_the_fixed_point_step_on_the_graphs(shipped_runtime: CurveRuntime):
    """In the model's frame at its own 161 points, the latent after one look is E(x) + E(x) − E(D(E(x))) where that
    decodes closer to x, else E(x) itself: the same arithmetic on the graphs' own outputs."""
    x = bspline_curves(6, seed=21).astype(np.float32)
    g = shipped_runtime.graphs
    z0 = g.encode(x)[0].astype(np.float64)
    z1 = z0 + z0 - g.encode(g.decode_model(z0))[0]
    got = _plain(shipped_runtime, list(x), Reading(frame="model", spacing="parameter", looks=1)).latents
    plain = _plain(shipped_runtime, list(x), Reading(frame="model", spacing="parameter", looks=0))
    looked = _plain(shipped_runtime, list(x), Reading(frame="model", spacing="parameter", looks=1))
    moved = looked.mse < plain.mse
    assert moved.sum() >= 4  # most paper curves come closer
    np.testing.assert_allclose(got[moved], z1[moved], atol=1e-5)
    np.testing.assert_array_equal(got[~moved], z0[~moved].astype(np.float32))


@pytest.mark.parametrize("pose", ["canonical", "learned"])
def test_each_look_keeps_an_answer_only_where_it_comes_closer(shipped_runtime: CurveRuntime, pose: str):
    """Per curve, the answer after k looks is never farther than after k − 1 (before untangling), and on the paper's
    curves drawn by arc length one look is much closer on average."""
    curves = [resample(c, 120) * 0.02 + 3 for c in bspline_curves(12, seed=22)]
    mse = [_plain(shipped_runtime, curves, Reading(pose=pose, looks=k)).mse for k in range(4)]
    for before, after in zip(mse, mse[1:]):
        assert (after <= before * (1 + 1e-9)).all()
    rms = [np.sqrt(m).mean() for m in mse]
    assert rms[1] < 0.8 * rms[0], rms


def test_a_request_looks_in_one_batch_a_pass(shipped_runtime: CurveRuntime):
    """Twelve curves, two looks: the looks' encoder runs are one batch each, of the curves still coming closer."""
    runs: list[int] = []
    graphs = shipped_runtime.graphs
    run = graphs._run_graph
    graphs._run_graph = lambda s, graph, x, o: (graph == "encoder" and runs.append(len(x))) or run(s, graph, x, o)
    try:
        shipped_runtime.reconstruct(
            list(bspline_curves(12, seed=23)), Reading(pose="canonical", spacing="parameter", looks=2)
        )
    finally:
        graphs._run_graph = run
    assert runs[:2] == [12, 12] and len(runs) <= 3 and all(r <= 12 for r in runs)


def test_encode_returns_the_latent_after_the_looks_and_refine_starts_there(shipped_runtime: CurveRuntime):
    curves = [c * 3.0 - 50 for c in bspline_curves(4, seed=24)]
    encoded = shipped_runtime.encode(curves)
    answer = shipped_runtime.reconstruct(curves)
    np.testing.assert_array_equal(encoded.mean, answer.latents)
    read = shipped_runtime.encode(curves, Reading(looks=0)).mean
    assert np.abs(encoded.mean - read).max() > 1e-3  # the looks moved them
    refined = shipped_runtime.reconstruct(curves, Reading(refine=2))
    assert (refined.mse <= answer.mse * (1 + 1e-9)).all()  # Levenberg–Marquardt from the looked-at latents


def test_the_cache_keeps_readings_with_other_looks_apart(model_dir):
    rt = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1)
    curves = list(bspline_curves(2, seed=25))
    none = rt.reconstruct(curves, Reading(looks=0)).latents
    one = rt.reconstruct(curves, Reading(looks=1)).latents
    assert rt.reconstruct(curves, Reading(looks=0)).latents.tolist() == none.tolist()
    assert one.tolist() == rt.reconstruct(curves, Reading(looks=1)).latents.tolist()
    assert rt.cache is not None and rt.cache.stats()["entries"] == 4


def test_the_default_is_one_look_and_says_so(client):
    assert Reading().looks == 1
    assert client.get("/model").json()["reading"]["looks"] == 1


@pytest.mark.parametrize("looks", [-1, 6, 1.5, "one", True])
def test_a_look_count_out_of_bounds_is_a_422_naming_it(client, looks):
    c = bspline_curves(1, seed=26)[0].tolist()
    r = client.post("/reconstruct", json={"curves": [c], "looks": looks})
    assert r.status_code == 422, r.text
    assert "looks" in r.text


def test_the_paper_curves_come_back_closer_with_a_look(shipped_runtime: CurveRuntime):
    curves = [c * 0.1 for c in bspline_curves(16, seed=27)]
    read = relative_rmse(curves, shipped_runtime.reconstruct(curves, Reading(looks=0)).curves).mean()
    looked = relative_rmse(curves, shipped_runtime.reconstruct(curves).curves).mean()
    assert looked < read / 1.5, (read, looked)


@pytest.mark.parametrize(
    ("asked", "instead"),
    [(Reading(), Reading(looks=0)), (Reading(refine=2), Reading())],
    ids=["a look gives way to the reading", "refine gives way to the look"],
)
def test_an_answer_that_cannot_be_untangled_gives_way_to_the_one_before_its_last_step(
    shipped_runtime, monkeypatch, asked, instead
):
    """A thin closed section whose decoded trailing edge crosses: where the untangler cannot free the answer, the
    answer is the row before its last step (before refine, before the looks), finished in turn."""
    from curve_vae.geometry.validity import new_crossings
    from curve_vae.inference import placing

    section = naca(0.0, 0.10, 81)  # crosses after the default look (tests/inference/test_untangling.py)
    plain = _plain(shipped_runtime, [section], asked)
    assert new_crossings([section], plain.curves).tolist() == [True]
    real, calls = placing.untangled, []

    def first_fails(ctrl, params, target, **kw):  # the first call is the answer's: it comes back as it was
        calls.append(1)
        return (np.asarray(ctrl, np.float64), False) if len(calls) == 1 else real(ctrl, params, target, **kw)

    monkeypatch.setattr(placing, "untangled", first_fails)
    answer = shipped_runtime.reconstruct([section], asked)
    monkeypatch.setattr(placing, "untangled", real)
    before = shipped_runtime.reconstruct([section], instead)
    assert not new_crossings([section], answer.curves).any()
    np.testing.assert_array_equal(answer.curves[0], before.curves[0])
