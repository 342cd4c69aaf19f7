"""curve_vae/commands/ranker.py: `curve-vae ranker label | train | export` against a real (untrained, committed)
model: each stage writes what the next reads, says where, and the export keeps a model's ranker unless forced."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from curve_vae.cli import main
from curve_vae.inference.model.manifest import Manifest


@pytest.fixture(scope="module")
def staged(closest_model_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """Labels of 8 curves in two chunks, and a ranker trained on them for a second: (labels, best checkpoint)."""
    tmp = tmp_path_factory.mktemp("ranker")
    labels, run = tmp / "labels", tmp / "run"
    assert main(["ranker", "label", "--model-dir", str(closest_model_dir), "--out", str(labels),
                 "--curves", "8", "--chunk", "4", "--seed", "2"]) == 0  # fmt: skip
    assert main(["ranker", "train", "--labels", str(labels), "--run-dir", str(run), "--time-budget", "1"]) == 0
    return labels, run / "ranker-best.pt"


def test_label_writes_its_chunks_named_by_seed(staged: tuple[Path, Path]):
    labels, _ = staged
    files = sorted(labels.glob("*.npz"))
    assert [f.name for f in files] == ["labels-2-0000.npz", "labels-2-0001.npz"]
    for f in files:
        with np.load(f) as d:
            assert int(d["seed"]) == 2 and sorted(np.unique(d["curve"])) == [0, 1, 2, 3]  # 4 curves a chunk


def test_label_again_is_done_at_once_and_counts_the_files(staged: tuple[Path, Path], closest_model_dir, capsys):
    labels, _ = staged
    before = {f: f.stat().st_mtime_ns for f in labels.glob("*.npz")}
    argv = ["ranker", "label", "--model-dir", str(closest_model_dir), "--out", str(labels), "--curves", "8"]
    assert main([*argv, "--chunk", "4", "--seed", "2"]) == 0
    assert capsys.readouterr().out == f"2 label files in {labels} (train on them with curve-vae ranker train)\n"
    assert {f: f.stat().st_mtime_ns for f in labels.glob("*.npz")} == before


def test_train_leaves_its_best_and_last_checkpoints(staged: tuple[Path, Path]):
    _, best = staged
    assert best.is_file() and (best.parent / "ranker-last.pt").is_file()


def test_the_command_line_keeps_a_models_ranker_unless_forced(
    staged: tuple[Path, Path], tmp_path: Path, closest_model_dir: Path
):
    _, best = staged
    model = tmp_path / "model"
    shutil.copytree(closest_model_dir, model)
    assert main(["ranker", "export", str(best), "--model-dir", str(model)]) == 0
    kept = (model / "ranker.onnx").read_bytes(), (model / "manifest.json").read_text()
    assert main(["ranker", "export", str(best), "--model-dir", str(model), "--version", "2.0.0"]) == 2
    assert ((model / "ranker.onnx").read_bytes(), (model / "manifest.json").read_text()) == kept
    assert main(["ranker", "export", str(best), "--model-dir", str(model), "--version", "2.0.0", "--force"]) == 0
    assert Manifest.read(model).version == "2.0.0"


@pytest.mark.parametrize(
    "flags,pose",
    [pytest.param([], "learned", id="default-reading"), pytest.param(["--not-default"], None, id="not-default")],
)
def test_export_makes_learned_the_models_reading_unless_told_not_to(
    staged: tuple[Path, Path], tmp_path: Path, closest_model_dir: Path, capsys, flags, pose
):
    _, best = staged
    model = tmp_path / "model"
    shutil.copytree(closest_model_dir, model)
    was = Manifest.read(model).reading.pose
    assert main(["ranker", "export", str(best), "--model-dir", str(model), "--note", "two chunks", *flags]) == 0
    manifest = Manifest.read(model)
    assert manifest.reading.pose == (pose or was) and manifest.ranker is not None
    assert "two chunks" in (model / "manifest.json").read_text()
    assert capsys.readouterr().out.startswith(f"wrote {model / 'ranker.onnx'}; ")


def test_label_refuses_a_family_it_does_not_know(closest_model_dir: Path, tmp_path: Path, capsys):
    argv = ["ranker", "label", "--model-dir", str(closest_model_dir), "--out", str(tmp_path)]
    with pytest.raises(SystemExit) as e:
        main([*argv, "--families", "closed,blob"])
    assert e.value.code == 2 and not any(tmp_path.iterdir())
    said = capsys.readouterr().err
    assert "unknown families ['blob']: choose from paper, polygon, arc, spiral, wave, naca, closed" in said
