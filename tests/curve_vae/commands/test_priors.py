"""curve_vae/commands/priors.py: `curve-vae prior` fits a latent prior to a user's curves into NAME.npz, which `sample`
then draws from by name; it and `evaluate-prior` refuse what they cannot do in one line, before any work."""

from __future__ import annotations

import json

import numpy as np
import pytest

from curve_vae.cli import main
from curve_vae.inference.generation.named_priors import NamedPrior


@pytest.fixture
def folder(curves, tmp_path):
    """Six curves of the paper's kind, one file each."""
    out = tmp_path / "mine"
    out.mkdir()
    for i, c in enumerate(curves(6, 80, seed=9)):
        (out / f"c{i}.json").write_text(json.dumps(c.tolist()))
    return out


@pytest.mark.parametrize(
    "kind,components",
    [
        pytest.param(["--kind", "parzen"], 6, id="parzen-one-per-curve"),
        pytest.param(["--kind", "gmm", "--components", "2"], 2, id="gmm-given"),
    ],
)
def test_prior_writes_a_named_prior_that_sample_draws_from(folder, model_dir, tmp_path, capsys, kind, components):
    out = tmp_path / "priors" / "mine.npz"
    out.parent.mkdir()
    assert (
        main(["prior", "--curves", str(folder), "-o", str(out), *kind, "--refine", "0", "--model-dir", str(model_dir)])
        == 0
    )
    said = capsys.readouterr().err
    assert f"{out}: a prior of 6 curves ({components} components" in said and "prior 'mine'" in said
    prior = NamedPrior.load(out)
    assert prior.name == "mine" and len(prior.mixture.weights) == components
    assert prior.meta["kind"] == kind[1] and prior.meta["reading"]["refine"] == 0
    assert len(prior.reference.latents) == 6
    made = tmp_path / "s.json"
    argv = ["sample", "--count", "3", "--seed", "1", "--prior", "mine", "--priors-dir", str(out.parent)]
    assert main([*argv, "--model-dir", str(model_dir), "-o", str(made)]) == 0
    body = json.loads(made.read_text())
    assert body["prior"] == "mine" and np.shape(body["curves"])[0] == 3


@pytest.mark.parametrize(
    "output,keep,says",
    [
        pytest.param("mine.json", 6, "a prior is a .npz file named after it", id="not-npz"),
        pytest.param("mine.npz", 1, "1 curves; a prior needs at least 2", id="one-curve"),
    ],
)
def test_prior_refuses_what_it_cannot_fit(folder, model_dir, tmp_path, capsys, output, keep, says):
    for extra in sorted(folder.iterdir())[keep:]:
        extra.unlink()
    out = tmp_path / output
    assert main(["prior", "--curves", str(folder), "-o", str(out), "--model-dir", str(model_dir)]) == 2
    assert says in capsys.readouterr().err
    assert not out.exists()


def test_prior_keeps_an_existing_file_unless_forced(folder, model_dir, tmp_path, capsys):
    out = tmp_path / "mine.npz"
    out.write_bytes(b"the user's own prior")
    assert main(["prior", "--curves", str(folder), "-o", str(out), "--model-dir", str(model_dir)]) == 2
    assert "pass --force to replace it" in capsys.readouterr().err
    assert out.read_bytes() == b"the user's own prior"


def test_evaluate_prior_keeps_an_existing_report_before_evaluating(folder, model_dir, tmp_path, capsys):
    report = tmp_path / "report.json"
    report.write_text("the user's own report")
    argv = ["evaluate-prior", "--prior", "learned", "--curves", str(folder), "--out", str(report)]
    assert main([*argv, "--model-dir", str(model_dir)]) == 2
    assert "pass --force to replace it" in capsys.readouterr().err
    assert report.read_text() == "the user's own report"


def test_evaluate_prior_of_a_built_in_prior_needs_the_curves_it_was_fitted_to(folder, model_dir, capsys):
    argv = ["evaluate-prior", "--prior", "standard", "--curves", str(folder), "--model-dir", str(model_dir)]
    assert main(argv) == 2
    assert "--prior standard: a built-in prior needs --train" in capsys.readouterr().err
