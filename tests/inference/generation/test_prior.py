"""The learned latent prior: its file, its sampling, rejection of invalid curves, and the generation metrics."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from curve_vae.inference.generation.prior import PRIOR_FILE, LatentPrior
from curve_vae.inference.model.manifest import ModelLoadError
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.training.evaluate import nearest_distances, sample_quality


def test_prior_round_trips_and_checks_its_shapes(tmp_path):
    prior = LatentPrior(np.array([0.25, 0.75]), np.zeros((2, 3)), np.stack([np.eye(3)] * 2))
    prior.save(tmp_path / "p.npz")
    again = LatentPrior.load(tmp_path / "p.npz")
    np.testing.assert_array_equal(again.cholesky, prior.cholesky)
    with pytest.raises(ValueError, match="shapes disagree"):
        LatentPrior(np.array([1.0]), np.zeros((2, 3)), np.stack([np.eye(3)] * 2))
    with pytest.raises(ValueError, match="sum to"):
        LatentPrior(np.array([0.5, 0.2]), np.zeros((2, 3)), np.stack([np.eye(3)] * 2))


def test_draws_follow_the_mixture():
    """Component means ±10 apart, spread 0.5 × temperature: draws sit around the means in the given proportions."""
    means = np.array([[10.0, 0.0], [-10.0, 0.0]])
    prior = LatentPrior(np.array([0.2, 0.8]), means, np.stack([np.eye(2) * 0.5] * 2))
    rng = np.random.default_rng(0)
    z = np.array([prior.draw(rng, temperature=2.0) for _ in range(4000)])
    right = z[:, 0] > 0
    assert abs(right.mean() - 0.2) < 0.02
    assert abs(z[right, 1].std() - 1.0) < 0.05 and abs(z[~right, 0].mean() + 10) < 0.05
    np.testing.assert_array_equal(prior.draw(np.random.default_rng(1), 0.0), prior.draw(np.random.default_rng(1), 0.0))


def test_a_tampered_prior_refuses_to_load(model_dir, tmp_path):
    copy = tmp_path / "model"
    shutil.copytree(model_dir, copy)
    with open(copy / PRIOR_FILE, "r+b") as f:
        f.seek(200)
        f.write(b"\x00\x01")
    with pytest.raises(ModelLoadError, match=r"prior\.npz: sha256 .* does not match"):
        CurveRuntime.load(copy, providers="cpu")


def test_the_learned_prior_is_the_default_and_the_standard_one_is_there_by_name(client, runtime):
    learned = client.post("/sample", json={"count": 3, "seed": 2}).json()
    assert learned["prior"] == "learned"
    z = np.array(learned["latents"])  # the fixture's mixture: four tight components
    assert min(np.linalg.norm(runtime.prior.means - zi, axis=1).min() for zi in z) < 0.05 * 32**0.5 * 6
    standard = client.post("/sample", json={"count": 3, "seed": 2, "prior": "standard"}).json()
    assert standard["prior"] == "standard" and standard["latents"] != learned["latents"]
    info = client.get("/model").json()["prior"]
    assert info == {"kind": "gaussian_mixture", "components": 4, "fitted_on": "4 test curves"}


def test_a_model_without_a_prior_says_so(raw_model_dir, tmp_path):
    copy = tmp_path / "model"
    shutil.copytree(raw_model_dir, copy)
    manifest = json.loads((copy / "manifest.json").read_text())
    del manifest["prior"], manifest["files"][PRIOR_FILE]
    (copy / "manifest.json").write_text(json.dumps(manifest))
    rt = CurveRuntime.load(copy, providers="cpu")
    assert rt.sample(2, seed=1).prior == "standard"
    with pytest.raises(ValueError, match="ships no learned prior"):
        rt.sample(2, seed=1, prior="learned")


@pytest.mark.parametrize("prior", ["learned", "standard"])
def test_rejection_keeps_the_seed_in_charge(runtime, monkeypatch, prior):
    """Every draw is decoded once (and only once: the curves returned are the draws' own); rejected ones are drawn
    again from the item's own generator, so the same seed gives the same curves and a larger count extends a
    smaller one, rejections and all."""
    decoded: list[int] = []
    decode = runtime.graphs.decode
    monkeypatch.setattr(runtime.graphs, "decode", lambda z: decoded.append(len(z)) or decode(z))
    made = runtime.sample(12, seed=7, prior=prior, max_draws=5)
    assert sum(decoded) == 12 + made.rejected and made.rejected > 0  # an untrained decoder scribbles
    ok = runtime.sampler.plausible(runtime.graphs.decode_model(made.latents).astype(np.float64))
    assert int((~ok).sum()) == made.invalid
    again = runtime.sample(12, seed=7, prior=prior, max_draws=5)
    np.testing.assert_array_equal(again.latents, made.latents)
    assert again.rejected == made.rejected
    fewer = runtime.sample(5, seed=7, prior=prior, max_draws=5)
    np.testing.assert_array_equal(fewer.latents, made.latents[:5])
    kept_all = runtime.sample(12, seed=7, prior=prior, valid=False)
    assert kept_all.rejected == 0 and kept_all.invalid == 0


def test_plausible_rejects_crossings_and_curves_outside_the_disc(runtime):
    t = np.linspace(0, 1, 161)
    line = np.stack([20 + 80 * t, 64 + 0 * t], axis=1)
    loop = np.stack([64 + 30 * np.cos(8 * t), 64 + 30 * np.sin(8 * t)], axis=1)  # more than a full turn: crosses
    far = line + [0, 60]  # y = 124: beyond radius 64 from (64, 64)
    assert runtime.sampler.plausible(np.stack([line, loop, far])).tolist() == [True, False, False]


def test_sample_quality_on_known_inputs(curves):
    data = curves(50, seed=3)
    reference = data + [0.01, 0.0]  # every real curve 0.01 from its twin, and much farther from the rest
    samples = data + [0.03, 0.0]
    np.testing.assert_allclose(nearest_distances(data, reference), 0.01, rtol=1e-6)
    q = sample_quality(samples, data, reference)
    assert q["coverage_vs_real"] == pytest.approx(3.0, rel=1e-5)
    assert q["precision_vs_real"] == pytest.approx(3.0, rel=1e-5)
    assert q["size_vs_data"] == pytest.approx(1.0) and q["self_intersecting"] == 0.0
    half = sample_quality((data - 64) * 0.5 + 64, data, reference)
    assert half["size_vs_data"] == pytest.approx(0.5)


def test_evaluate_reports_generation(model_dir, runtime, curves, tmp_path: Path):
    from curve_vae.training.evaluate import generation_report

    report = generation_report(runtime, curves(40, seed=1), curves(40, seed=2), seed=3)
    assert report["n_samples"] == 40 and set(report) >= {"learned", "standard"}
    for prior in ("learned", "standard"):
        valid = report[prior]["valid"]
        assert 0 <= valid["rejected_share"] < 1 and valid["invalid"] >= 0
        assert report[prior]["every_draw"]["implausible"] >= valid["self_intersecting"]
