"""Every CLI command the README shows runs as written, at a tiny scale: the same subcommands and options, with a
few flags appended that shrink the data set and the number of epochs (argparse keeps the last value of a flag)."""

from __future__ import annotations

import hashlib
import json
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
TINY_DATA = ["--n-train", "256", "--n-val", "64", "--n-test", "64"]
#: What each subcommand gets appended to run in seconds; the README's own flags all stay.
TINY = {
    "dataset": TINY_DATA,
    "train": [*TINY_DATA, "--epochs", "1", "--no-progress"],
    "export": ["--prior-components", "2", "--suite-count", "8", "--fresh-count", "64"],
    "evaluate": ["--fresh-seed", "-1", "--suite-count", "8", "--morph-count", "2"],
    "average": ["--bn-curves", "128"],
    "augment": ["--count", "300"],
    "ranker label": ["--curves", "24", "--chunk", "12"],
    "ranker train": ["--time-budget", "3"],
    # the shipped model stays as it is: the ranker is exported into a copy (the last --model-dir wins)
    "ranker export": ["--model-dir", "model-copy"],
    "spacer train": ["--time-budget", "3", "--batch", "8"],
    "spacer export": ["--model-dir", "model-copy"],
}
ORDER = ["dataset", "train", "average", "export", "evaluate", "prior", "sample", "augment", "fit", "revolve"]


def readme_commands() -> list[list[str]]:
    """The `.venv/bin/curve-vae …` lines of the README's bash blocks (comments dropped; `serve` runs elsewhere)."""
    pages = ("README.md", "docs/TRAINING.md", "docs/API.md", "docs/CLI.md")
    text = "\n".join((ROOT / page).read_text() for page in pages)
    blocks = re.findall(r"```bash\n(.*?)```", text, flags=re.S)
    commands = []
    for block in blocks:
        for line in block.splitlines():
            line = line.strip()
            if line.startswith(".venv/bin/curve-vae "):
                argv = shlex.split(line, comments=True)[1:]
                if argv[0] != "serve":
                    commands.append(argv)
    return commands


def test_the_readme_shows_every_long_command():
    assert {argv[0] for argv in readme_commands()} >= set(ORDER)


def _inputs(cwd: Path) -> None:
    """The files the README's commands read: seed curves, curves to fit, a profile to revolve."""
    t = np.linspace(0, 1, 40)
    seeds = [np.stack([t * 8, np.sin(np.pi * t) * k], 1).tolist() for k in (2.0, 3.0, 3.5, 1.5, -1.0, -2.0, 2.5, 0.5)]
    (cwd / "seeds.json").write_text(json.dumps(seeds))
    (cwd / "curves.json").write_text(json.dumps({"curves": seeds[:2]}))
    (cwd / "profile.json").write_text(json.dumps([[0, 0], [3, 0], [4, 1], [3, 3], [2.5, 5], [3, 7], [0, 7]]))
    # an airfoil as the UIUC database writes them, notes after the coordinates and all
    (cwd / "my_airfoil.dat").write_text((ROOT / "tests/fixtures/files/selig_notes.dat").read_text())
    mine = cwd / "my_curves"  # a family of one's own, in three formats
    mine.mkdir()
    for i, c in enumerate(seeds):
        if i % 3 == 0:
            np.save(mine / f"c{i}.npy", np.array(c))
        elif i % 3 == 1:
            (mine / f"c{i}.csv").write_text("x,y\n" + "\n".join(f"{x},{y}" for x, y in c))
        else:
            (mine / f"c{i}.json").write_text(json.dumps(c))
    (cwd / "models").symlink_to(ROOT / "models")  # --init-from models/vae.pt, as in the repository
    shutil.copytree(ROOT / "models", cwd / "model-copy", ignore=shutil.ignore_patterns("paper", "vae.pt"))


def _tiny(argv: list[str]) -> list[str]:
    """The flags that shrink a command to seconds (a `ranker` or `spacer` stage by its stage)."""
    return TINY.get(" ".join(argv[:2]) if argv[0] in ("ranker", "spacer") else argv[0], [])


@pytest.mark.slow
def test_readme_cli_commands_run_as_written(tmp_path):
    _inputs(tmp_path)
    shipped = {f.name: hashlib.sha256(f.read_bytes()).hexdigest() for f in (ROOT / "models").glob("*") if f.is_file()}
    commands = sorted(readme_commands(), key=lambda argv: ORDER.index(argv[0]) if argv[0] in ORDER else len(ORDER))
    for argv in commands:
        full = [sys.executable, "-m", "curve_vae.cli", *argv, *_tiny(argv)]
        run = subprocess.run(full, cwd=tmp_path, capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, f"{shlex.join(argv)} failed:\n{run.stderr[-3000:]}"
        assert "Traceback" not in run.stderr and "Warning" not in run.stderr, run.stderr[-3000:]
    for made in [
        "data/preview.png",
        "runs/ref/best.pt",
        "runs/ref/averaged.pt",
        "runs/ref/model/manifest.json",
        "runs/evaluation/report.json",
        "samples.json",
        "batch.npy",
        "fits.json",
        "vase.obj",
        "priors/mine.npz",
        "mine_samples.json",
        "runs/ranker/ranker-best.pt",
        "model-copy/ranker.onnx",
        "runs/spacer/spacer-best.pt",
        "model-copy/spacer.onnx",
    ]:
        assert (tmp_path / made).is_file(), made
    now = {f.name: hashlib.sha256(f.read_bytes()).hexdigest() for f in (ROOT / "models").glob("*") if f.is_file()}
    assert now == shipped, "a documented command changed the shipped model"
    assert np.load(tmp_path / "batch.npy").shape[0] == 300
