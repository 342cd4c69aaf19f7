"""curve_vae/commands/spacer.py: `curve-vae spacer train | export` against a real (untrained, committed) model: training
says where its checkpoint is, and the export keeps a model's guesser unless forced."""

from __future__ import annotations

import shutil
from pathlib import Path

from curve_vae.cli import main
from curve_vae.inference.model.manifest import Manifest


def test_train_then_export_and_the_export_keeps_a_models_guesser_unless_forced(
    tmp_path: Path, closest_model_dir: Path, capsys
):
    run = tmp_path / "run"
    argv = ["spacer", "train", "--run-dir", str(run), "--time-budget", "2", "--batch", "8", "--threads", "1"]
    assert main(argv) == 0
    best = run / "spacer-best.pt"
    assert capsys.readouterr().out.endswith(f"best held-out step → {best} (export it with curve-vae spacer export)\n")
    assert best.is_file() and (run / "spacer-last.pt").is_file()

    model = tmp_path / "model"
    shutil.copytree(closest_model_dir, model)
    assert main(["spacer", "export", str(best), "--model-dir", str(model), "--note", "two seconds"]) == 0
    assert Manifest.read(model).spacer is not None
    kept = (model / "spacer.onnx").read_bytes(), (model / "manifest.json").read_text()
    assert main(["spacer", "export", str(best), "--model-dir", str(model), "--version", "2.0.0"]) == 2
    assert "--force" in capsys.readouterr().err
    assert ((model / "spacer.onnx").read_bytes(), (model / "manifest.json").read_text()) == kept
    assert main(["spacer", "export", str(best), "--model-dir", str(model), "--version", "2.0.0", "--force"]) == 0
    assert Manifest.read(model).version == "2.0.0"
