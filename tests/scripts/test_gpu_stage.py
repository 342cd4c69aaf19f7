"""scripts/gpu_stage.sh, the way GPU stages run on a machine without the project installed: here on the CPU, tiny."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import torch

ROOT = Path(__file__).resolve().parents[2]


def _stage(tmp_path: Path, **settings: str) -> tuple[subprocess.CompletedProcess, Path, Path]:
    out, run = tmp_path / "out", tmp_path / "run"
    env = {
        **os.environ,
        "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",  # python3: this interpreter's
        "DEVICE": "cpu",
        "NTRAIN": "512",
        "NVAL": "32",
        "NTEST": "32",
        "WORKERS": "1",
        "BUDGET": "2",
        "OUT": str(out),
        "RUN": str(run),
        "DATA": str(tmp_path / "d.npz"),
        **settings,
    }
    env.pop("PYTHONPATH", None)
    done = subprocess.run(
        ["bash", str(ROOT / "scripts" / "gpu_stage.sh")], env=env, cwd=tmp_path, capture_output=True, text=True
    )
    return done, out, run


@pytest.mark.slow
def test_a_stage_from_a_checkout_leaves_a_slim_best_checkpoint_and_its_log(tmp_path):
    done, out, run = _stage(tmp_path, MIX_VERSION="2", PARAMS="1")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "initialised from" in done.stdout and "stage done" in done.stdout
    config = json.loads((out / "config.json").read_text())
    assert config["data"]["mix_version"] == 2 and config["data"]["n_train"] == 512
    assert config["train"]["device"] == "cpu" and config["train"]["time_budget"] == 2
    assert config["model"]["spline_params"] is True  # from models/vae.pt, its head widened
    assert (out / "log.jsonl").read_text().strip() and (out / "train.log").exists()
    slim = torch.load(out / "best.pt", map_location="cpu", weights_only=False)
    assert "optimizer" not in slim and "model" in slim
    assert (out / "best.pt").stat().st_size < (run / "best.pt").stat().st_size
    assert not (ROOT / "d.npz").exists() and (tmp_path / "d.npz").exists()


@pytest.mark.slow
def test_a_twin_stage_of_the_encoder_alone_draws_twins_and_marks_the_model(tmp_path):
    done, out, _ = _stage(tmp_path, MATCH="twin", ONLY_ENCODER="1")
    assert done.returncode == 0, done.stdout + done.stderr
    config = json.loads((out / "config.json").read_text())
    assert config["data"]["twins"] is True and config["train"]["match"] == "twin" and config["train"]["only_encoder"]
    slim = torch.load(out / "best.pt", map_location="cpu", weights_only=False)
    shipped = torch.load(ROOT / "models" / "vae.pt", map_location="cpu", weights_only=False)["model"]
    assert all(torch.equal(slim["model"][k], v) for k, v in shipped.items() if k.startswith("decoder."))
