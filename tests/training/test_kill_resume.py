"""A training run killed with SIGKILL mid-epoch resumes from its last checkpoint, losing at most that epoch."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from curve_vae.training.checkpoint import load_checkpoint

pytestmark = pytest.mark.slow


def test_sigkill_mid_epoch_then_resume(tmp_path):
    run, data = tmp_path / "run", str(tmp_path / "curves.npz")
    args = [sys.executable, "-m", "curve_vae.cli", "train", "--run-dir", str(run), "--data", data, "--epochs", "3",
            "--n-train", "768", "--n-val", "64", "--n-test", "32", "--batch-size", "64", "--threads", "1",
            "--no-progress", "--resume"]  # fmt: skip
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=os.environ)
    log = run / "log.jsonl"
    deadline = time.monotonic() + 120
    while not (log.exists() and log.read_text().count("\n") >= 1):  # epoch 1 done and saved ...
        assert proc.poll() is None and time.monotonic() < deadline, proc.stdout.read()  # type: ignore[union-attr]
        time.sleep(0.05)
    time.sleep(0.3)  # ... and epoch 2 under way
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    proc.stdout.close()  # type: ignore[union-attr]
    assert proc.returncode == -signal.SIGKILL
    done = load_checkpoint(run / "last.pt")["state"]["epoch"]  # the checkpoint on disk is whole
    logged = log.read_text().count("\n")
    assert done >= 1 and done == logged  # the checkpoint and the log agree on the epochs completed
    again = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stdout + again.stderr
    assert f"resumed {run / 'last.pt'} at epoch {done}/3" in again.stdout
    rows = [json.loads(line) for line in log.read_text().splitlines()]
    assert [r["epoch"] for r in rows] == [1, 2, 3]  # nothing lost but the killed epoch, nothing repeated
    assert not list(run.glob("*.tmp")) and not list(run.glob(".*.tmp"))  # no half-written checkpoint left
