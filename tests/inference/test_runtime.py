"""CurveRuntime without HTTP: loading checks, frames and lengths, interpolation, inputs the model cannot take."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import onnxruntime as ort
import pytest

from curve_vae.geometry import blend_frames, evaluate_bspline, fit_frame, mse_per_curve, simplex_grid
from curve_vae.inference.errors import InputError
from curve_vae.inference.model.manifest import ModelLoadError
from curve_vae.inference.reader import Reader
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from tests.helpers import ROOT, SHIPPED

# ----------------------------------------------------------------------------- loading


def _copy(model_dir: Path, tmp_path: Path) -> Path:
    out = tmp_path / "model"
    shutil.copytree(model_dir, out)
    return out


def test_load_reports_cpu_provider(runtime):
    assert runtime.graphs.providers[0] == "CPUExecutionProvider"
    assert (runtime.n_points, runtime.latent_dim, runtime.model_size) == (161, 32, 100.0)


_KERNELS_AFTER_LOAD = """
import json, sys
from curve_vae.geometry.matching_kernel import place
from curve_vae.geometry.natural_kernel import fit_start, lm_steps
from curve_vae.inference.runtime import CurveRuntime
rt = CurveRuntime.load(sys.argv[1], providers="cpu", warm_up=sys.argv[2] == "1")
print(json.dumps({
    "compiled": [len(k.signatures) for k in (fit_start, lm_steps, place)],
    "rows": rt.graphs.rows,
    "cache": [len(rt.cache), rt.cache.hits, rt.cache.misses],
}))
"""


@pytest.mark.parametrize("warm", [True, False])
def test_loading_runs_a_default_request_so_the_first_callers_does_not_compile(warm):
    """In a fresh process (nothing compiled yet): the shipped model's default reading runs the natural fit's and the
    placement's compiled kernels, which loading with warm-up has compiled (or loaded from numba's cache) already,
    leaving the encoding cache empty and the graphs' row counts at the graphs' own warm-up; without it, none is."""
    if not (SHIPPED / "manifest.json").is_file():
        pytest.skip("no shipped model: models/manifest.json is absent")
    done = subprocess.run(
        [sys.executable, "-c", _KERNELS_AFTER_LOAD, str(SHIPPED), "1" if warm else "0"],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout.strip().splitlines()[-1])
    if warm:
        assert all(n >= 1 for n in got["compiled"]), got
        # the learned parts' rows are counted beside the graphs' (ModelGraphs.run_part); their warm-up runs are not
        assert got["rows"] == {"encoder": 1, "decoder": 1, "ranker": 0, "spacer": 0} and got["cache"] == [0, 0, 0]
    else:
        assert got["compiled"] == [0, 0, 0] and got["rows"] == {"encoder": 0, "decoder": 0, "ranker": 0, "spacer": 0}


def test_a_warm_up_request_that_fails_is_a_startup_error(model_dir, monkeypatch):
    def broken(self, *args, **kwargs):
        raise ValueError("the reading broke")

    monkeypatch.setattr(Reader, "read", broken)
    with pytest.raises(ModelLoadError, match="warm-up request failed: the reading broke"):
        CurveRuntime.load(model_dir, providers="cpu", cache_bytes=0)


def test_tampered_graph_is_a_startup_error(model_dir, tmp_path):
    copy = _copy(model_dir, tmp_path)
    with open(copy / "decoder.onnx", "ab") as f:
        f.write(b"\0")
    with pytest.raises(ModelLoadError, match=r"decoder\.onnx: sha256 .* does not match the manifest"):
        CurveRuntime.load(copy, providers="cpu")


def test_a_model_plane_centred_elsewhere_is_a_startup_error_not_a_silent_shift(model_dir, tmp_path):
    copy = _copy(model_dir, tmp_path)
    manifest = json.loads((copy / "manifest.json").read_text())
    manifest["frame"]["center"] = [0.0, 0.0]
    (copy / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ModelLoadError, match=r"centred at \[0\.0, 0\.0\]"):
        CurveRuntime.load(copy, providers="cpu")


def test_a_manifest_promising_learned_parameters_of_a_decoder_without_them_is_a_startup_error(model_dir, tmp_path):
    copy = _copy(model_dir, tmp_path)
    manifest = json.loads((copy / "manifest.json").read_text())
    manifest["spline"]["learned_params"] = True  # the even-parameter decoder has no `params` output
    (copy / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ModelLoadError, match=r"expected curves, control_points, params"):
        CurveRuntime.load(copy, providers="cpu")


def test_missing_manifest_is_a_startup_error(tmp_path):
    with pytest.raises(ModelLoadError, match=r"manifest\.json is missing"):
        CurveRuntime.load(tmp_path, providers="cpu")


def test_manifest_without_checksum_is_a_startup_error(model_dir, tmp_path):
    copy = _copy(model_dir, tmp_path)
    manifest = json.loads((copy / "manifest.json").read_text())
    del manifest["files"]["encoder.onnx"]
    (copy / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ModelLoadError, match=r"no sha256 for encoder\.onnx"):
        CurveRuntime.load(copy, providers="cpu")


# ----------------------------------------------------------------------------- frames and lengths (item 3)


@pytest.mark.parametrize(
    "scale,shift",
    [
        pytest.param(1.0, (0.0, 0.0), id="identity"),
        pytest.param(3.5, (100.0, -7.0), id="small"),
        pytest.param(1e-3, (0.5, 0.25), id="tiny"),
        pytest.param(250.0, (-4e4, 9e3), id="large"),
        pytest.param(1e-9, (1.0, 2.0), id="nano"),
        pytest.param(1e12, (3e12, -1e12), id="huge"),
    ],
)
@pytest.mark.parametrize("n_points", [161, 50, 500])
@pytest.mark.parametrize("spacing", ["parameter", "arc_length"])
def test_reconstruction_follows_scale_and_shift(runtime, curves, scale, shift, n_points, spacing):
    """reconstruct(c·s + t) == reconstruct(c)·s + t to float precision, at any length."""
    c = curves(3, n_points, seed=1)
    t = np.asarray(shift)
    res = runtime.reconstruct(list(c), Reading(spacing=spacing))
    base, base_mse = res.curves, res.mse
    res = runtime.reconstruct(list(c * scale + t), Reading(spacing=spacing))
    moved, moved_mse = res.curves, res.mse
    for b, m in zip(base, moved, strict=True):
        assert m.shape == (n_points, 2)
        # float32 inside the graphs: a relative 1e-6 of the curve's size, plus rounding of the shift itself
        tol = 1e-6 * 128 * scale + 1e-15 * np.abs(t).max()
        np.testing.assert_allclose(m, b * scale + t, rtol=0, atol=tol)
    np.testing.assert_allclose(moved_mse, base_mse * scale**2, rtol=1e-5)


def test_model_frame_passes_coordinates_untouched(raw_runtime, curves):
    c = curves(2)
    res = raw_runtime.reconstruct(list(c), Reading(frame="model", spacing="parameter", looks=0))  # as given
    out, mse = res.curves, res.mse
    mean, _ = raw_runtime.graphs.encode(c)
    direct = raw_runtime.graphs.decode_model(mean)
    np.testing.assert_array_equal(np.stack(out), direct.astype(np.float64))
    np.testing.assert_allclose(mse, mse_per_curve(c, direct))


def test_spline_head_points_are_the_spline_at_its_params(runtime, curves):
    """With a B-spline head, returned points are the returned spline at the returned parameters (float64), and in
    the model's frame at its 161 points they are the graph's own curves (to float32 rounding)."""
    c = curves(2)
    runtime.reader.keep_ends = False  # the decoder's own curves (the untrained model's ends are far from the input's)
    try:
        rec = runtime.reconstruct(list(c), Reading(frame="model", spacing="parameter", looks=0))
    finally:
        runtime.reader.keep_ends = True
    out, splines = rec.curves, rec.splines
    direct = runtime.graphs.decode_model(runtime.graphs.encode(c)[0])
    np.testing.assert_allclose(np.stack(out), direct, rtol=0, atol=1e-4)
    for curve, spline in zip(out, splines, strict=True):
        np.testing.assert_array_equal(spline.params, np.linspace(0, 1, 161))
        np.testing.assert_allclose(evaluate_bspline(spline.control_points, spline.params), curve, rtol=0, atol=1e-12)


def test_auto_frame_maps_into_and_out_of_the_model_frame(runtime, curves):
    c = curves(1)[0] * 0.01 + 5.0
    frame = fit_frame(c)
    res = runtime.encode([c], Reading(pose="as_is", spacing="parameter"))
    mean, frames = res.mean, res.frames
    assert frames == [frame]
    mean_model, _ = runtime.graphs.encode(frame.to_model(c, runtime.model_size)[None])
    np.testing.assert_allclose(mean, mean_model, atol=1e-5)
    out = runtime.decode(mean, frames=frames).curves
    np.testing.assert_allclose(out[0], frame.from_model(runtime.graphs.decode_model(mean)[0], runtime.model_size))


@pytest.mark.parametrize("n_out", [None, 10, 161, 1000])
@pytest.mark.parametrize("spacing", ["parameter", "arc_length"])
def test_lengths_in_and_out(runtime, curves, n_out, spacing):
    inputs = [curves(1, 50)[0], curves(1, 161, seed=2)[0], curves(1, 733, seed=3)[0]]
    res = runtime.reconstruct(inputs, Reading(spacing=spacing), n_points=n_out)
    out, mse = res.curves, res.mse
    assert [len(o) for o in out] == [n_out or len(c) for c in inputs]
    assert mse.shape == (3,)


def test_mse_is_measured_at_the_inputs_own_points(runtime, curves):
    c = [curves(1, 50)[0] * 7.0, curves(1, 300, seed=4)[0] - 40.0]
    res = runtime.reconstruct(c)
    own, mse = res.curves, res.mse
    res = runtime.reconstruct(c, n_points=20)
    resized, mse_again = res.curves, res.mse
    np.testing.assert_allclose(mse, [mse_per_curve(a[None], b[None])[0] for a, b in zip(c, own, strict=True)])
    np.testing.assert_array_equal(mse, mse_again)
    assert all(len(r) == 20 for r in resized)


def _relative_errors(
    rt: CurveRuntime, ctrl: np.ndarray, n_points: int, spacing: str = "parameter", looks: int = 0
) -> np.ndarray:
    from curve_vae.geometry import sample_bspline

    c = sample_bspline(ctrl, n_points)
    mse = rt.reconstruct(list(c), Reading(spacing=spacing, looks=looks)).mse
    sizes = np.array([fit_frame(x).size for x in c])
    return np.sqrt(mse) / sizes


def _check_length_independence(
    rt: CurveRuntime, factor: float, spacing: str = "parameter", looks: int = 0
) -> dict[int, float]:
    """The reading itself (no look again: what the encoder reads) is as close at 50 and 500 points as at 161."""
    from curve_vae.geometry import random_control_points

    ctrl = random_control_points(np.random.default_rng(11), 24)
    err = {n: float(np.median(_relative_errors(rt, ctrl, n, spacing, looks))) for n in (50, 161, 500)}
    assert err[50] <= factor * err[161], err
    assert err[500] <= factor * err[161], err
    return err


@pytest.mark.parametrize("spacing", ["parameter", "arc_length"])
def test_other_lengths_reconstruct_about_as_well(runtime, spacing):
    """50- and 500-point versions of curves: error relative to size within a small factor of 161 points."""
    _check_length_independence(runtime, factor=1.5, spacing=spacing)


def test_neighbouring_lengths_give_the_same_curve(runtime, curves):
    """160, 161 and 162 samples of a curve are the same curve to the model: no jump at its own length."""
    from curve_vae.geometry import sample_bspline

    ctrl = __import__("curve_vae.geometry", fromlist=["random_control_points"]).random_control_points(
        np.random.default_rng(3), 1
    )[0]
    out = {n: runtime.reconstruct([sample_bspline(ctrl, n)], n_points=161).curves[0] for n in (160, 161, 162)}
    size = fit_frame(out[161]).size
    assert np.abs(out[160] - out[161]).max() < 0.02 * size
    assert np.abs(out[162] - out[161]).max() < 0.02 * size


def test_other_lengths_reconstruct_about_as_well_with_the_shipped_model(shipped_runtime):
    """The same with the trained model, where reconstructions resemble their inputs; the default look again brings
    every length closer, curves of many points the most (the encoder reads 50 points joined by straight lines, so the
    look draws 50-point curves towards their chords)."""
    read = _check_length_independence(shipped_runtime, factor=1.5)
    from curve_vae.geometry import random_control_points

    ctrl = random_control_points(np.random.default_rng(11), 24)
    for n in (50, 161, 500):
        looked = _relative_errors(shipped_runtime, ctrl, n, looks=1)
        assert float(np.median(looked)) < read[n]
    assert float(np.median(_relative_errors(shipped_runtime, ctrl, 161, looks=1))) < 0.7 * read[161]


# ----------------------------------------------------------------------------- interpolation


def test_pair_ends_are_the_reconstructions(runtime, curves):
    a, b = curves(1, 161)[0] * 2 + 9, curves(1, 161, seed=5)[0] / 3
    res = runtime.interpolate([a, b], simplex_grid(2, 3))
    out, frames = res.curves, res.frames
    rec = runtime.reconstruct([a, b], together=True).curves
    np.testing.assert_allclose(out[0], rec[0], atol=1e-9)
    np.testing.assert_allclose(out[-1], rec[1], atol=1e-9)
    fa, fb = runtime.encode([a, b], together=True).frames  # the set's one pose, each curve's own box
    assert (fa.rotation, fa.mirror, fa.reverse) == (fb.rotation, fb.mirror, fb.reverse)
    assert frames[0] == fa and frames[-1] == fb
    assert frames[1] == blend_frames([fa, fb], np.array([[0.5, 0.5]]))[0]


def test_interpolants_keep_a_common_input_length(runtime, curves):
    a, b = curves(1, 60)[0], curves(1, 60, seed=6)[0] + 50
    out = runtime.interpolate([a, b], simplex_grid(2, 4)).curves
    rec = runtime.reconstruct([a, b], together=True).curves
    assert out.shape == (4, 60, 2)
    np.testing.assert_allclose(out[0], rec[0], atol=1e-9)  # same spacing as the first input's reconstruction
    mixed = runtime.interpolate([a, curves(1, 70)[0]], simplex_grid(2, 2)).curves
    assert mixed.shape == (2, 161, 2)  # lengths differ: the model's
    sized = runtime.interpolate([a, b], simplex_grid(2, 2), n_points=33).curves
    assert sized.shape == (2, 33, 2)


def test_n_way_weights_mix_latent_means(runtime, curves):
    c = list(curves(4, 161, seed=7))
    w = np.array([[0.25, 0.25, 0.25, 0.25], [1.5, -0.5, 0.0, 0.0]])
    runtime.reader.keep_ends = False  # the decoder's own curves, not moved onto the blend of the inputs' ends
    try:
        res = runtime.interpolate(c, w, Reading(frame="model", spacing="parameter", looks=0))
    finally:
        runtime.reader.keep_ends = True
    out, frames = res.curves, res.frames
    mean, _ = runtime.graphs.encode(np.stack(c))
    np.testing.assert_allclose(out, runtime.graphs.decode_model(w @ mean.astype(np.float64)), atol=1e-5)
    assert frames == [None, None]


# ----------------------------------------------------------------------------- inputs the model cannot take


def test_coincident_points_are_an_input_error(runtime):
    with pytest.raises(InputError, match="coincide") as e:
        runtime.reconstruct([np.ones((10, 2)) * 3.0])
    assert e.value.loc == ("curves", 0)


@pytest.mark.parametrize("magnitude", [1e-320, 1e200])
def test_magnitudes_beyond_float64_results_are_input_errors(runtime, curves, magnitude):
    with pytest.raises(InputError):
        runtime.reconstruct([curves(1)[0], curves(1)[0] * magnitude])


@pytest.mark.parametrize("magnitude", [1e-290, 1e140])
def test_extreme_but_representable_magnitudes_work(runtime, curves, magnitude):
    c = curves(1)[0]
    base = runtime.reconstruct([c]).curves
    res = runtime.reconstruct([c * magnitude])
    out, mse = res.curves, res.mse
    np.testing.assert_allclose(out[0], base[0] * magnitude, rtol=1e-5, atol=0)
    assert np.isfinite(mse).all()


def test_cuda_that_falls_back_to_cpu_is_a_startup_error(model_dir, monkeypatch):
    """onnxruntime-gpu lists CUDA even where its libraries cannot load, then silently runs on CPU: refuse that."""
    if "CUDAExecutionProvider" in ort.get_available_providers():
        pytest.skip("CUDA is available here")
    monkeypatch.setattr(ort, "get_available_providers", lambda: ["CUDAExecutionProvider", "CPUExecutionProvider"])
    with pytest.raises(ModelLoadError, match="CUDA provider failed to load"):
        CurveRuntime.load(model_dir, providers="cuda", warm_up=False)
    auto = CurveRuntime.load(model_dir, providers="auto", warm_up=False)  # auto accepts the fallback ...
    assert auto.graphs.providers == ["CPUExecutionProvider"]  # ... and reports it


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        pytest.param(lambda d: (d / "encoder.onnx").unlink(), r"encoder\.onnx is missing", id="missing-encoder"),
        pytest.param(lambda d: (d / "prior.npz").unlink(), r"prior\.npz is missing", id="missing-prior"),
        pytest.param(
            lambda d: (d / "decoder.onnx").write_bytes((d / "decoder.onnx").read_bytes()[:1000]),
            r"decoder\.onnx: sha256 .* does not match .* changed or truncated",
            id="truncated-decoder",
        ),
    ],
)
def test_missing_or_truncated_model_files_stop_the_server_naming_the_file(model_dir, tmp_path, damage, message):
    import re
    import subprocess
    import sys

    copy = _copy(model_dir, tmp_path)
    damage(copy)
    with pytest.raises(ModelLoadError, match=message):
        CurveRuntime.load(copy, providers="cpu")
    serve = subprocess.run(
        [sys.executable, "-m", "curve_vae.service.server", "--model-dir", str(copy), "--port", "0"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert serve.returncode == 2 and re.search(message, serve.stderr), serve.stderr
