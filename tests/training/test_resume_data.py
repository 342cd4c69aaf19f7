"""A run resumes only on the data it was trained on: another mix version, size or seed is refused by name."""

import pytest

from curve_vae.cli import main

TINY = ["--n-train", "96", "--n-val", "16", "--n-test", "16", "--epochs", "1", "--no-progress", "--batch-size", "32"]


@pytest.mark.slow
def test_resume_refuses_other_data_before_drawing_it(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    run = ["train", "--run-dir", "r", "--mix", "broad", "--workers", "1", *TINY]
    assert main([*run, "--mix-version", "2"]) == 0
    assert (tmp_path / "r" / "last.pt").exists()
    caches = sorted((tmp_path / "data").glob("*.npz"))
    capsys.readouterr()

    # the latest mix version by default: not what the run was trained on
    assert main([*run, "--resume"]) == 2
    said = capsys.readouterr().err
    assert "mix_version 2 (run) vs 3 (asked)" in said and "--mix-version" in said
    assert sorted((tmp_path / "data").glob("*.npz")) == caches, "nothing drawn for the refused run"

    assert main([*run, "--mix-version", "2", "--data-seed", "1", "--resume"]) == 2
    assert "seed 0 (run) vs 1 (asked)" in capsys.readouterr().err

    # the same options resume (the run is complete: nothing more to train)
    assert main([*run, "--mix-version", "2", "--resume"]) == 0
    assert "resumed" in capsys.readouterr().out


def test_mix_version_goes_with_the_broad_mix_only(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["train", "--run-dir", "r", "--mix-version", "2", *TINY]) == 2
    assert "--mix-version goes with --mix broad" in capsys.readouterr().err
    assert not (tmp_path / "r").exists()
