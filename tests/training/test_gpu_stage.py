"""scripts/gpu_stage.sh, the way GPU stages run on a machine without the project installed: here on the CPU, tiny."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import torch

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_a_stage_from_a_checkout_leaves_a_slim_best_checkpoint_and_its_log(tmp_path):
    out, run = tmp_path / "out", tmp_path / "run"
    env = {
        **os.environ,
        "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",  # python3: this interpreter's
        "DEVICE": "cpu",
        "NTRAIN": "600",
        "WORKERS": "1",
        "BUDGET": "2",
        "MIX_VERSION": "2",
        "PARAMS": "1",
        "OUT": str(out),
        "RUN": str(run),
        "DATA": str(tmp_path / "d.npz"),
    }
    env.pop("PYTHONPATH", None)
    done = subprocess.run(
        ["bash", str(ROOT / "scripts" / "gpu_stage.sh")], env=env, cwd=tmp_path, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "initialised from" in done.stdout and "stage done" in done.stdout
    config = json.loads((out / "config.json").read_text())
    assert config["data"]["mix_version"] == 2 and config["data"]["n_train"] == 600
    assert config["train"]["device"] == "cpu" and config["train"]["time_budget"] == 2
    assert config["model"]["spline_params"] is True  # from models/vae.pt, its head widened
    assert (out / "log.jsonl").read_text().strip() and (out / "train.log").exists()
    slim = torch.load(out / "best.pt", map_location="cpu", weights_only=False)
    assert "optimizer" not in slim and "model" in slim
    assert (out / "best.pt").stat().st_size < (run / "best.pt").stat().st_size
    assert not (ROOT / "d.npz").exists() and (tmp_path / "d.npz").exists()
