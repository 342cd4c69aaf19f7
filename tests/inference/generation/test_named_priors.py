"""Priors fitted to a user's curves: fitted, saved, loaded by the service (and refused for another model), sampled
in the curves' own frame, closed for closed families, the same for the same seed."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from fastapi.testclient import TestClient

from curve_vae.cli import main
from curve_vae.inference.generation.named_priors import NamedPrior
from curve_vae.inference.model.manifest import ModelLoadError
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings
from tests.helpers import bspline_curves

pytest.importorskip("sklearn")


def _strokes(count: int, closed: bool = False) -> list[np.ndarray]:
    """Curves of one family in a frame of their own: small, far from the origin, turned by 30°."""
    a = np.radians(30)
    turn = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
    out = [(c - 64) / 40 @ turn + [500, -300] for c in bspline_curves(count, 60, seed=21)]
    return [np.concatenate([c, c[:1]]) for c in out] if closed else out


@pytest.fixture(scope="module")
def prior_dir(model_dir, tmp_path_factory):
    d = tmp_path_factory.mktemp("priors")
    folder = d / "mine"
    folder.mkdir()
    for i, c in enumerate(_strokes(24)):
        np.save(folder / f"c{i}.npy", c)
    assert (
        main(
            [
                "prior",
                "--curves",
                str(folder),
                "-o",
                str(d / "strokes.npz"),
                "--model-dir",
                str(model_dir),
                "--refine",
                "0",
            ]
        )
        == 0
    )
    loops = d / "loops"
    loops.mkdir()
    (loops / "all.json").write_text(json.dumps([c.tolist() for c in _strokes(16, closed=True)]))
    assert (
        main(
            [
                "prior",
                "--curves",
                str(loops),
                "-o",
                str(d / "loops.npz"),
                "--model-dir",
                str(model_dir),
                "--refine",
                "0",
                "--kind",
                "gmm",
            ]
        )
        == 0
    )
    return d


def test_a_prior_samples_in_its_curves_frame_the_same_for_the_same_seed(model_dir, prior_dir):
    rt = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1, priors_dir=prior_dir, cache_bytes=0)
    assert set(rt.priors) == {"strokes", "loops"} and rt.priors["strokes"].meta["kind"] == "parzen"
    made = rt.sample(20, seed=4, prior="strokes")
    centres = np.array([np.ptp(c, axis=0).max() for c in made.curves])
    assert np.abs(np.mean(made.curves, axis=(0, 1)) - [500, -300]).max() < 2 and centres.max() < 4  # their frame
    again = rt.sample(20, seed=4, prior="strokes")
    np.testing.assert_array_equal(again.curves, made.curves)
    loops = rt.sample(10, seed=1, prior="loops")
    np.testing.assert_allclose(loops.curves[:, 0], loops.curves[:, -1], atol=1e-9)  # closed stay closed
    assert rt.priors["loops"].closed and rt.priors["loops"].meta["chosen_by"].startswith("BIC over")


def test_the_service_lists_named_priors_and_samples_them(model_dir, prior_dir):
    with TestClient(create_app(Settings(model_dir=model_dir, providers="cpu", priors_dir=prior_dir))) as client:
        info = client.get("/model").json()
        assert info["priors"]["strokes"]["curves"] == 24 and info["priors"]["loops"]["closed"] is True
        r = client.post("/sample", json={"count": 3, "seed": 2, "prior": "strokes"})
        assert r.status_code == 200 and r.json()["prior"] == "strokes" and len(r.json()["frames"]) == 3
        bad = client.post("/sample", json={"count": 3, "prior": "airfoils"})
        assert bad.status_code == 422
        assert "no prior named 'airfoils' on this server; it has: learned, standard, loops, strokes" in bad.text
        schema = client.get("/openapi.json").json()["components"]["schemas"]["SampleRequest"]
        assert schema["properties"]["prior"]["anyOf"][0]["enum"] == ["learned", "standard", "loops", "strokes"]


def test_a_prior_of_another_model_stops_the_start_naming_both(model_dir, prior_dir, tmp_path):
    other = tmp_path / "other"
    shutil.copytree(prior_dir, other)
    p = NamedPrior.load(other / "strokes.npz")
    NamedPrior(p.name, p.mixture, p.reference, {k: "0" * 64 for k in p.model}, p.meta).save(other / "strokes.npz")
    with pytest.raises(ModelLoadError, match=r"strokes\.npz: fitted to another model .* than the one served"):
        CurveRuntime.load(model_dir, providers="cpu", priors_dir=other)


def test_evaluate_prior_prints_every_metric_with_its_interval(model_dir, prior_dir, tmp_path, capsys):
    held = tmp_path / "held"
    held.mkdir()
    (held / "c.json").write_text(json.dumps([c.tolist() for c in _strokes(30)[24:]]))
    out = tmp_path / "report.json"
    args = [
        "evaluate-prior",
        "--prior",
        str(prior_dir / "strokes.npz"),
        "--curves",
        str(held),
        "--model-dir",
        str(model_dir),
        "--seeds",
        "2",
        "--count",
        "40",
        "--likelihood-samples",
        "30",
        "--lsc-lines",
        "5",
        "--points",
        "32",
        "--out",
        str(out),
    ]
    assert main(args) == 0
    text = capsys.readouterr().out
    report = json.loads(out.read_text())
    assert set(report["real"]) >= {"mmd_ideallab", "precision", "recall", "rvod"}  # the data's own scores beside
    assert "real: the training curves in the samples' place" in text
    want = {
        "valid",
        "mmd_ideallab",
        "mmd_gaussian",
        "precision",
        "recall",
        "coverage",
        "coverage_radius",
        "rvod",
        "diversity_ratio",
        "vendi",
        "dpp",
        "novelty",
        "copy_rate",
        "nn_to_held_out",
        "mean_log_likelihood",
        "lsc",
    }
    assert want <= set(report["metrics"]) and all(len(m["runs"]) == 2 for m in report["metrics"].values())
    assert all(f"{name} " in text and "±" in text for name in want)
