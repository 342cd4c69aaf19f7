"""curve_vae/commands/train.py: `curve-vae train` and `average`. A run continued from weights with a B-spline head keeps
the head unless told otherwise; a run resumes only on the data it was trained on; options out of range are refused
with one line, before any file is written."""

import json
from pathlib import Path

import pytest
import torch

from curve_vae.cli import main
from curve_vae.training.config import ModelConfig
from curve_vae.training.model import VAE

TINY = ["--n-train", "128", "--n-val", "32", "--n-test", "32", "--epochs", "1", "--no-progress", "--no-figures"]
SMALL = [
    *["--n-train", "96", "--n-val", "16", "--n-test", "16", "--epochs", "1", "--no-progress", "--batch-size", "32"],
    "--no-figures",
]


def _start_weights(tmp_path: Path) -> Path:
    """Seeded weights of a model with the 31-control-point head (even parameters), saved as a checkpoint."""
    torch.manual_seed(0)
    start = tmp_path / "start.pt"
    torch.save(
        {"model_config": ModelConfig(spline_ctrl=31).__dict__, "model": VAE(ModelConfig(spline_ctrl=31)).state_dict()},
        start,
    )
    return start


@pytest.mark.slow
def test_init_from_keeps_the_checkpoints_spline_head(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    start = _start_weights(tmp_path)
    tiny = [*TINY, "--batch-size", "64"]
    assert main(["train", "--run-dir", "kept", "--init-from", str(start), *tiny]) == 0
    assert json.loads((tmp_path / "kept" / "config.json").read_text())["model"]["spline_ctrl"] == 31
    assert (tmp_path / "kept" / "report.json").exists() and not list((tmp_path / "kept").glob("*.png"))  # --no-figures
    assert main(["train", "--run-dir", "dropped", "--init-from", str(start), "--spline-ctrl", "0", *tiny]) == 0
    assert json.loads((tmp_path / "dropped" / "config.json").read_text())["model"]["spline_ctrl"] == 0


@pytest.mark.slow
def test_init_from_weights_without_learned_parameters_widens_them_and_keeps_them(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    start = _start_weights(tmp_path)
    tiny = TINY
    assert main(["train", "--run-dir", "params", "--init-from", str(start), "--spline-params", *tiny]) == 0
    assert json.loads((tmp_path / "params" / "config.json").read_text())["model"]["spline_params"] is True
    again = tmp_path / "params" / "last.pt"
    assert main(["train", "--run-dir", "kept", "--init-from", str(again), *tiny]) == 0
    assert json.loads((tmp_path / "kept" / "config.json").read_text())["model"]["spline_params"] is True
    # the parameter channel is not dropped silently
    assert main(["train", "--run-dir", "dropped", "--init-from", str(again), "--no-spline-params", *tiny]) != 0
    assert "'spline_params': True} model, not" in capsys.readouterr().err


@pytest.mark.slow
def test_resume_refuses_other_data_before_drawing_it(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    run = ["train", "--run-dir", "r", "--mix", "broad", "--workers", "1", *SMALL]
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


def test_every_training_option_is_a_flag_whose_default_is_the_configs():
    from dataclasses import fields

    from curve_vae.cli import build_parser
    from curve_vae.training.config import TrainConfig

    parsed = build_parser().parse_args(["train"])
    assert {f.name: getattr(parsed, f.name) for f in fields(TrainConfig)} == TrainConfig().__dict__
    flipped = build_parser().parse_args(["train", "--only-encoder", "--time-budget", "7.5", "--match", "twin"])
    cfg = TrainConfig(**{f.name: getattr(flipped, f.name) for f in fields(TrainConfig)})
    assert cfg.only_encoder is True and cfg.time_budget == 7.5 and cfg.match == "twin"


@pytest.mark.parametrize(
    "args,says",
    [
        pytest.param(["--schedule", "linear"], "schedule must be one of onecycle, cosine", id="schedule"),
        pytest.param(["--variant", "resnet"], "unknown variant 'resnet'", id="variant"),
        pytest.param(["--spline-ctrl", "3"], "spline_ctrl must be 0 (off) or 4 … 161, got 3", id="head"),
        pytest.param(["--match", "closest"], "match 'closest' measures the decoded spline", id="match-needs-head"),
        pytest.param(["--batch-size", "256"], "128 training curves are fewer than one batch of 256", id="batch"),
    ],
)
def test_a_run_that_cannot_train_is_one_line_and_status_2_and_leaves_no_run(tmp_path, monkeypatch, capsys, args, says):
    monkeypatch.chdir(tmp_path)
    assert main(["train", "--run-dir", "r", *TINY, *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("curve-vae train: error: ") and says in err and err.count("\n") == 1, err
    assert not (tmp_path / "r").exists()


def test_average_refuses_to_replace_a_checkpoint_before_reading_any(tmp_path, capsys):
    sources = [tmp_path / "a.pt", tmp_path / "b.pt"]
    for s in sources:
        s.write_bytes(b"not read: the refusal comes first")
    out = tmp_path / "mine.pt"
    out.write_bytes(b"a checkpoint of the user's")
    assert main(["average", *map(str, sources), "--out", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.read_bytes() == b"a checkpoint of the user's"
    with pytest.raises(SystemExit, match=f"no checkpoint at {tmp_path / 'missing.pt'}"):
        main(["average", str(tmp_path / "missing.pt"), "--out", str(tmp_path / "new.pt")])
    assert not (tmp_path / "new.pt").exists()
