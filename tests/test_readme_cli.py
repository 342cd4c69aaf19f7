"""Every CLI command the README shows runs as written, at a tiny scale: the same subcommands and options, with a
few flags appended that shrink the data set and the number of epochs (argparse keeps the last value of a flag)."""

from __future__ import annotations

import hashlib
import json
import re
import shlex
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
TINY_DATA = ["--n-train", "256", "--n-val", "64", "--n-test", "64"]
#: What each subcommand gets appended to run in seconds; the README's own flags all stay. Training and evaluation
#: draw no figures here (9 CPU-s a chain): tests/training/test_end_to_end.py checks every figure they draw.
TINY = {
    "dataset": TINY_DATA,
    "train": [*TINY_DATA, "--epochs", "1", "--no-progress", "--no-figures"],
    "export": ["--prior-components", "2", "--suite-count", "2", "--fresh-count", "16"],
    "evaluate": ["--fresh-seed", "-1", "--suite-count", "2", "--morph-count", "2", "--no-figures"],
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


#: The README's commands in four independent chains, each run by a test class of its own (pytest-xdist's loadscope
#: hands each class to a worker: the chains run side by side): training, training on one's own curves, the learned
#: parts, the rest on the shipped model; with what each chain must leave behind.
CHAINS = {
    "training": ({"dataset", "train", "average", "export", "evaluate"}, [
        "data/preview.png",
        "runs/ref/best.pt",
        "runs/ref/averaged.pt",
        "runs/ref/model/manifest.json",
        "runs/evaluation/report.json",
    ]),
    "training on one's own curves": (set(), [
        "data/my_curves.png",
        "runs/mine/best.pt",
        "runs/mine/model/manifest.json",
        "runs/mine/evaluation/report.json",
    ]),
    "parts": ({"ranker", "spacer"}, [
        "runs/ranker/ranker-best.pt",
        "model-copy/ranker.onnx",
        "runs/spacer/spacer-best.pt",
        "model-copy/spacer.onnx",
    ]),
    "shipped model": (set(), [
        "samples.json", "batch.npy", "fits.json", "vase.obj", "priors/mine.npz", "mine_samples.json",
        "reconstructed.svg", "reconstructed.dxf",
    ]),
}  # fmt: skip


def _chain(argv: list[str]) -> str:
    if argv[0] in CHAINS["training"][0] and any("my_curves" in a or "runs/mine" in a for a in argv):
        return "training on one's own curves"
    return next((name for name, (heads, _) in CHAINS.items() if argv[0] in heads), "shipped model")


def test_every_readme_command_is_in_a_chain():
    assert {_chain(argv) for argv in readme_commands()} == set(CHAINS)


def run_chain(chain: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture) -> None:
    """The chain's README commands in order, at a tiny scale: each exits 0 without a traceback or a warning, leaves
    what it should, and leaves the shipped model as it was.

    Each runs as `curve-vae` runs it (`curve_vae.cli.main` on the command's arguments, in the README's working
    directory), in the test's own process: a new interpreter for each would import torch, scipy and the project again
    (the training chain: 28 CPU-s against 47). Python's warnings are recorded, and what the command wrote to the
    process's stderr (onnxruntime's and torch's native logs too) is read from the file descriptor."""
    import torch  # the test install has it: its threads are process-wide (`spacer train --threads 1` sets them)

    from curve_vae.cli import main

    _inputs(tmp_path)
    monkeypatch.chdir(tmp_path)
    shipped = {f.name: hashlib.sha256(f.read_bytes()).hexdigest() for f in (ROOT / "models").glob("*") if f.is_file()}
    commands = sorted(readme_commands(), key=lambda argv: ORDER.index(argv[0]) if argv[0] in ORDER else len(ORDER))
    threads = torch.get_num_threads()
    for argv in [argv for argv in commands if _chain(argv) == chain]:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")  # a warning earlier tests saw is not hidden as seen before
            try:
                code = main([*argv, *_tiny(argv)])
            except SystemExit as e:  # argparse's refusals
                code = e.code
            finally:
                torch.set_num_threads(threads)  # as the process had them, for the next command and test
        err = capfd.readouterr().err
        assert code == 0, f"{shlex.join(argv)} failed:\n{err[-3000:]}"
        assert not caught, f"{shlex.join(argv)}: {[f'{w.category.__name__}: {w.message}' for w in caught]}"
        assert "Traceback" not in err and "Warning" not in err, err[-3000:]
    for made in CHAINS[chain][1]:
        assert (tmp_path / made).is_file(), made
    now = {f.name: hashlib.sha256(f.read_bytes()).hexdigest() for f in (ROOT / "models").glob("*") if f.is_file()}
    assert now == shipped, "a documented command changed the shipped model"


@pytest.mark.slow
class TestTrainingChain:
    def test_dataset_train_average_export_evaluate_run_as_written(self, tmp_path, monkeypatch, capfd):
        run_chain("training", tmp_path, monkeypatch, capfd)


@pytest.mark.slow
class TestOwnCurvesTrainingChain:
    def test_dataset_train_export_evaluate_on_ones_own_curves_run_as_written(self, tmp_path, monkeypatch, capfd):
        run_chain("training on one's own curves", tmp_path, monkeypatch, capfd)


@pytest.mark.slow
class TestLearnedPartsChain:
    def test_ranker_and_spacer_stages_run_as_written(self, tmp_path, monkeypatch, capfd):
        run_chain("parts", tmp_path, monkeypatch, capfd)


@pytest.mark.slow
class TestShippedModelChain:
    def test_prior_sample_augment_fit_revolve_reconstruct_run_as_written(self, tmp_path, monkeypatch, capfd):
        run_chain("shipped model", tmp_path, monkeypatch, capfd)
        assert np.load(tmp_path / "batch.npy").shape[0] == 300
