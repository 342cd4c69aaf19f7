"""Refining reconstructions (`refine`, inference.fitting): latents fitted to the caller's points through the real ONNX
decoder; closer reconstructions, never worse ones, and the API's bounds on the work asked for."""

from __future__ import annotations

import io

import numpy as np
import pytest
from fastapi.testclient import TestClient
from scipy.interpolate import BSpline

from curve_vae.geometry import evaluate_bspline, resample, self_intersects
from curve_vae.inference.errors import InputError
from curve_vae.inference.fitting import Fitter
from curve_vae.inference.reading import Reading
from curve_vae.service.app import create_app
from curve_vae.service.schemas import MAX_REFINE_STEPS
from curve_vae.service.settings import Settings
from curve_vae.training.suite import relative_rmse
from tests.helpers import bspline_curves


def _naca_loop(thickness: float = 0.12) -> np.ndarray:
    """A closed-trailing-edge NACA 00xx section listed as closed coordinate files list it: from the trailing edge over
    the upper surface to the leading edge and back under the lower one, the first point repeated at the end."""
    theta = np.linspace(0, 2 * np.pi, 81)
    x = (1 + np.cos(theta)) / 2
    half = 5 * thickness * (0.2969 * np.sqrt(x) - 0.126 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4)
    loop = np.stack([x, np.where(theta <= np.pi, half, -half)], 1)
    loop[-1] = loop[0]
    return loop


def _in_a_user_frame(curves: np.ndarray) -> list[np.ndarray]:
    """Paper curves turned, scaled and shifted, as a user might post them."""
    a = 0.7
    rot = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
    return [0.05 * c @ rot + [300.0, -20.0] for c in curves]


def test_refining_brings_the_shipped_models_reconstructions_much_closer(shipped_runtime):
    paper = _in_a_user_frame(bspline_curves(8, seed=11))
    sets = {"parameter": paper, "arc length, 90 points": [resample(c, 90) for c in paper]}
    for name, curves in sets.items():
        res = shipped_runtime.reconstruct(curves)  # read, then looked at again
        plain, plain_mse = res.curves, res.mse
        res = shipped_runtime.reconstruct(curves, Reading(refine=6))  # fitted from there
        fitted, fitted_mse, splines = res.curves, res.mse, res.splines
        assert (fitted_mse <= plain_mse * (1 + 1e-9)).all(), name
        read = shipped_runtime.reconstruct(curves, Reading(looks=0)).curves  # the reading alone
        before, after = relative_rmse(curves, read).mean(), relative_rmse(curves, fitted).mean()
        assert after < before / 3, (name, before, after)
        assert after < 0.8 * relative_rmse(curves, plain).mean(), name
        for c, s in zip(fitted, splines):  # the returned points lie on the returned spline, at its params
            np.testing.assert_allclose(evaluate_bspline(s.control_points, s.params), c, atol=1e-9 * np.abs(c).max())


def test_a_refined_curve_does_not_depend_on_how_its_points_are_spaced(shipped_runtime):
    # the fit measures each point to its closest point on the curve, so the same curve at another spacing is
    # reconstructed about as closely (plainly, the arc-length samples come back 1.6× further off: RESULTS.md)
    curves = _in_a_user_frame(bspline_curves(6, seed=12))
    arc = [resample(c, 161) for c in curves]
    for name, cs in {"parameter": curves, "arc": arc}.items():
        out = shipped_runtime.reconstruct(cs, Reading(refine=10)).curves
        err = relative_rmse(cs, out).mean()
        assert err < 0.0015, (name, err)


def test_refining_never_raises_the_error_and_each_step_can_only_lower_it(runtime, params_runtime, curves):
    for rt in (runtime, params_runtime):
        c = list(curves(5, seed=2))
        rt.reader.untangle = False  # the fit's own steps: the untrained model's answers cross, and untangling refits
        try:
            plain = rt.reconstruct(c).mse
            one = rt.reconstruct(c, Reading(refine=1)).mse
            four = rt.reconstruct(c, Reading(refine=4)).mse
        finally:
            rt.reader.untangle = True
        assert (one <= plain * (1 + 1e-9)).all() and (four <= one * (1 + 1e-9)).all()
        assert four.sum() < one.sum()  # the steps themselves fit, not only the matching to closest points


def test_refined_points_lie_on_the_returned_spline_with_learned_parameters(params_runtime, curves):
    c = [resample(x, 70) for x in curves(3, seed=4)]
    rec = params_runtime.reconstruct(c, Reading(refine=2))
    out, splines = rec.curves, rec.splines
    for o, s in zip(out, splines):
        assert len(o) == 70 and len(s.params) == 70
        np.testing.assert_allclose(evaluate_bspline(s.control_points, s.params), o, atol=1e-9)


def test_encode_returns_the_refined_latents_that_reconstruct_decodes(runtime, curves):
    c = list(curves(3, seed=5))
    plain = runtime.encode(c).mean
    res = runtime.encode(c, Reading(refine=3))
    mean, frames = res.mean, res.frames
    assert not np.allclose(mean, plain)
    decoded = runtime.decode(mean, frames=frames, n_points=50).curves
    # /decode draws a latent as the model does; /reconstruct's answer is that drawing with its ends moved onto the
    # input's (inference.placing) and, where it crosses itself, untangled (the untrained model's curves cross)
    runtime.reader.keep_ends = False
    try:
        rec = runtime.reconstruct(c, Reading(refine=3), n_points=50)
        kept = ~rec.repaired  # an answer untangled says so; the rest are their latents' decodings exactly
        np.testing.assert_allclose(decoded[kept], np.stack(rec.curves)[kept], atol=1e-9)
        runtime.reader.untangle = False
        plain = runtime.reconstruct(c, Reading(refine=3), n_points=50).curves
    finally:
        runtime.reader.untangle = runtime.reader.keep_ends = True
    np.testing.assert_allclose(decoded, np.stack(plain), atol=1e-9)


def test_a_model_without_a_head_cannot_refine_and_says_why(raw_runtime, raw_model_dir, curves):
    with pytest.raises(InputError, match="refine: refining needs a model with a B-spline head"):
        raw_runtime.reconstruct(list(curves(1)), Reading(refine=2))
    with TestClient(create_app(Settings(model_dir=raw_model_dir), runtime=raw_runtime)) as client:
        r = client.post("/reconstruct", json={"curves": [curves(1)[0].tolist()], "refine": 2})
        assert r.status_code == 422 and "B-spline head" in r.json()["detail"]


@pytest.mark.parametrize("bad", [-1, MAX_REFINE_STEPS + 1, "3", 2.5])
def test_refine_out_of_bounds_is_refused_naming_the_field(client, curves, bad):
    r = client.post("/reconstruct", json={"curves": [curves(1)[0].tolist()], "refine": bad})
    assert r.status_code == 422
    assert "refine" in r.text


def test_refine_over_http_lowers_the_mse_and_works_with_npy_bodies(client, curves):
    c = curves(2, seed=7)
    plain = client.post("/reconstruct", json={"curves": c.tolist()}).json()["mse"]
    fitted = client.post("/reconstruct", json={"curves": c.tolist(), "refine": 3}).json()["mse"]
    assert all(f <= p * (1 + 1e-9) for f, p in zip(fitted, plain)) and fitted != plain
    buf = io.BytesIO()
    np.save(buf, c)
    headers = {"Content-Type": "application/x-npy"}
    r = client.post("/reconstruct?refine=3", content=buf.getvalue(), headers=headers)
    assert r.status_code == 200 and r.json()["mse"] == pytest.approx(fitted, rel=1e-9)
    r = client.post(f"/reconstruct?refine={MAX_REFINE_STEPS + 1}", content=buf.getvalue(), headers=headers)
    assert r.status_code == 422 and "refine" in r.text


def test_evaluate_measures_the_family_suite_refined_too(runtime, curves, tmp_path):
    from curve_vae.training.evaluate import run_evaluation, runtime_codec

    enc, dec, _ = runtime_codec(runtime)
    sets = {"test": curves(8), "fresh": curves(8, seed=1)}
    report = run_evaluation(enc, dec, sets, tmp_path, figures=False, runtime=runtime, suite_count=2, suite_refine=1)
    plain, refined = report["families"], report["families_refined"]
    assert refined["refine"] == 1 and refined["sets"].keys() == plain.keys()
    for name, row in plain.items():
        assert refined["sets"][name]["rel_rmse_mean"] <= row["rel_rmse_mean"] * (1 + 1e-9), name


@pytest.mark.parametrize("magnitude", [1e-290, 1e140])
def test_refining_works_at_extreme_but_representable_magnitudes(runtime, curves, magnitude):
    c = curves(1, seed=8)[0]
    base = runtime.reconstruct([c], Reading(refine=2)).curves
    res = runtime.reconstruct([c * magnitude], Reading(refine=2))
    out, mse = res.curves, res.mse
    np.testing.assert_allclose(out[0], base[0] * magnitude, rtol=1e-5, atol=0)
    assert np.isfinite(mse).all()


@pytest.mark.parametrize("magnitude", [1e-320, 1e200])
def test_refining_beyond_float64_is_an_input_error(runtime, curves, magnitude):
    with pytest.raises(InputError):
        runtime.reconstruct([curves(1)[0], curves(1)[0] * magnitude], Reading(refine=2))


@pytest.mark.parametrize("refine", [0, 3])
def test_a_closed_curve_comes_back_closed(shipped_runtime, refine):
    loop = _naca_loop()
    rec = shipped_runtime.reconstruct([loop, loop[:-5]], Reading(refine=refine))
    out, splines = rec.curves, rec.splines
    np.testing.assert_array_equal(out[0][0], out[0][-1])
    np.testing.assert_array_equal(splines[0].control_points[0], splines[0].control_points[-1])
    assert np.abs(out[1][0] - out[1][-1]).max() > 1e-3  # an open curve stays open
    assert not self_intersects(out[0])


def test_refined_points_never_step_back_along_the_curve_at_a_sharp_corner(shipped_runtime):
    # superellipse arcs (a held-out family) with corners sharper than the spline's: the input points around a corner
    # are all closest to its rounded tip, in no particular order; two of these 40 came back zigzagging before
    from curve_vae.training.families import HELD_OUT, draw_family

    drawn = draw_family(HELD_OUT["superellipse"], 40, np.random.default_rng(0), model_size=None)
    curves = [drawn[8].astype(np.float64), drawn[34].astype(np.float64)]
    rec = shipped_runtime.reconstruct(curves, Reading(refine=10))
    assert rec.splines is not None and len(rec.splines) == len(curves)  # else the loop below checks nothing
    for o, s in zip(rec.curves, rec.splines):
        assert (np.diff(s.params) >= 0).all()
        assert not self_intersects(o)


def test_refined_interpolation_ends_are_the_refined_reconstructions(runtime, curves):
    c = [curves(1, seed=9)[0], resample(curves(1, seed=10)[0], 161)]
    ends = runtime.interpolate(c, np.array([[1.0, 0.0], [0.0, 1.0], [0.5, 0.5]]), Reading(refine=3)).curves
    fitted = runtime.reconstruct(c, Reading(refine=3), together=True).curves  # the pair read as a set
    plain = runtime.reconstruct(c, together=True).curves
    for end, f, p in zip(ends[:2], fitted, plain):
        np.testing.assert_allclose(end, f, rtol=0, atol=1e-9 * np.abs(f).max())
        assert np.abs(f - p).max() > 1e-6  # refined, not the plain reconstruction
    assert np.isfinite(ends[2]).all()


def test_refine_over_http_on_interpolate(client, curves):
    c = curves(2, seed=11).tolist()
    r = client.post("/interpolate", json={"curves": c, "steps": 3, "refine": 2})
    assert r.status_code == 200 and len(r.json()["curves"]) == 3
    same = client.post("/interpolate", json={"curves": [c[0], c[0]], "steps": 2, "refine": 2}).json()["curves"]
    fitted = client.post("/reconstruct", json={"curves": c[:1], "refine": 2}).json()["curves"]
    np.testing.assert_allclose(same[0], fitted[0], atol=1e-9)  # a curve mixed with itself: its refined reconstruction


def test_a_request_asking_for_too_much_fitting_work_is_refused_before_any(make_client, curves):
    client = make_client(max_refine_work=3000)
    c = curves(2, seed=12).tolist()  # 2 × 161 points
    for path, extra in (("/reconstruct", {}), ("/encode", {}), ("/interpolate", {"steps": 3})):
        r = client.post(path, json={"curves": c, "refine": 4, **extra})
        assert r.status_code == 422, (path, r.text)
        assert r.json()["detail"] == (
            "refine: refine 4 and looks 1 on 2 curves of 322 points in all are 3848 units of work (refine × "
            "(points + 300 per curve) + looks × 80 per curve); at most 3000 (CURVE_VAE_MAX_REFINE_WORK): send fewer "
            "curves, steps or looks"
        )
        assert client.post(path, json={"curves": c, "refine": 3, **extra}).status_code == 200  # 2766 + 160
        r = client.post(path, json={"curves": c, "refine": 3, "looks": 5, **extra})  # 2766 + 800
        assert r.status_code == 422 and r.json()["detail"].startswith("refine: refine 3 and looks 5"), r.text
    r = client.post("/reconstruct", json={"curves": c * 10, "looks": 4})  # 20 curves × 4 looks × 80
    assert r.status_code == 422 and r.json()["detail"].startswith("looks: refine 0 and looks 4"), r.text
    assert client.get("/model").json()["limits"]["max_refine_work"] == 3000


def test_closed_curves_interpolate_into_closed_curves_whose_ends_are_their_reconstructions(shipped_runtime):
    loops = [_naca_loop(0.12), _naca_loop(0.2)]
    for refine in (0, 3):
        sweep = shipped_runtime.interpolate(
            loops, np.array([[1.0, 0.0], [0.5, 0.5], [0.0, 1.0]]), Reading(refine=refine)
        ).curves
        ends = shipped_runtime.reconstruct(loops, Reading(refine=refine), together=True).curves  # read as a set
        for curve in sweep:
            np.testing.assert_array_equal(curve[0], curve[-1])
        np.testing.assert_allclose(sweep[0], ends[0], atol=1e-9)
        np.testing.assert_allclose(sweep[2], ends[1], atol=1e-9)


# ------------------------------------------------------------------ Fitter.refine_latents on the graphs themselves


def _distance(graphs, ctrl: np.ndarray, target: np.ndarray, u: np.ndarray) -> float:
    """Sum of squared distances from the target's points to the spline at u, by scipy (not the fitter's own)."""
    return float(((BSpline(graphs.knots, ctrl.astype(np.float64), graphs.spline_degree)(u) - target) ** 2).sum())


def test_refined_latents_come_closer_to_a_curve_the_decoder_can_draw(runtime):
    """The target is the decoding of one latent, the start another nearby: the fit can only come closer, and what it
    returns is consistent — the decoding is the refined latents', the feet ordered from 0 to 1."""
    g = runtime.graphs
    rng = np.random.default_rng(0)
    goal = rng.standard_normal((2, g.latent_dim))
    start = goal + 0.3 * rng.standard_normal(goal.shape)
    targets = [t.astype(np.float64)[::2] for t in g.decode(goal)[0]]  # 81 of each curve's points
    around = [np.linspace(0.0, 1.0, len(t)) for t in targets]
    _, start_ctrl, _ = g.decode(start)
    z, (out, ctrl, params), feet = Fitter(g).refine_latents(start, targets, around, 6)
    assert z.dtype == np.float64 and z.shape == start.shape and params is None
    np.testing.assert_allclose(out, g.decode(z)[0], atol=1e-5)
    np.testing.assert_allclose(ctrl, g.decode(z)[1], atol=1e-5)
    for i, (t, u) in enumerate(zip(targets, feet)):
        assert u[0] == 0.0 and u[-1] == 1.0 and (np.diff(u) >= 0).all()
        before = _distance(g, start_ctrl[i], t, around[i])
        assert _distance(g, ctrl[i], t, u) < 0.5 * before, i  # several steps: much closer, not merely no worse


def test_no_steps_keep_the_latents_and_decode_them(runtime):
    g = runtime.graphs
    start = np.random.default_rng(1).standard_normal((1, g.latent_dim))
    target = [g.decode(start + 0.5)[0][0].astype(np.float64)]
    z, (out, _, _), feet = Fitter(g).refine_latents(start, target, [np.linspace(0, 1, 161)], 0)
    np.testing.assert_array_equal(z, start)
    np.testing.assert_allclose(out, g.decode(start)[0], atol=1e-6)
    assert len(feet) == 1 and len(feet[0]) == 161
