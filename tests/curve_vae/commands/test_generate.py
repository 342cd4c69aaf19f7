"""curve_vae/commands/generate.py: `curve-vae sample` and `augment` offline give what the REST endpoints answer for the
same request (issue 5), refuse what they cannot do in one line, and need no torch."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from curve_vae.cli import main
from tests.helpers import ROOT


@pytest.fixture
def seeds(curves, tmp_path) -> tuple[list, Path]:
    c = [(x * (1 + i) - 30 * i).tolist() for i, x in enumerate(curves(5, 90))]
    path = tmp_path / "seeds.json"
    path.write_text(json.dumps({"curves": c}))
    return c, path


def _run(model_dir: Path, *args: str) -> None:
    assert main([*args, "--model-dir", str(model_dir)]) == 0


def test_sample_offline_equals_the_endpoint(client, model_dir, tmp_path):
    _run(model_dir, "sample", "--count", "5", "--seed", "42", "--temperature", "0.7", "--n-points", "60",
         "--metrics", "-o", str(tmp_path / "s.json"))  # fmt: skip
    rest = client.post(
        "/sample", json={"count": 5, "seed": 42, "temperature": 0.7, "n_points": 60, "metrics": True}
    ).json()
    assert json.loads((tmp_path / "s.json").read_text()) == rest
    _run(model_dir, "sample", "--count", "5", "--seed", "42", "--temperature", "0.7", "--n-points", "60",
         "-o", str(tmp_path / "s.npy"))  # fmt: skip
    batch = np.load(tmp_path / "s.npy")
    assert batch.dtype == np.float32 and batch.shape == (5, 60, 2)
    np.testing.assert_array_equal(batch, np.array(rest["curves"], np.float32))


@pytest.mark.parametrize(
    "args,body",
    [
        pytest.param([], {}, id="pairs"),
        pytest.param(
            ["--mode", "triplet", "--neighbours", "3", "--offset", "7", "--n-points", "33"],
            {"mode": "triplet", "neighbours": 3, "offset": 7, "n_points": 33},
            id="triplets-of-neighbours-page-2",
        ),
        pytest.param(
            ["--frame", "model", "--spacing", "arc_length"], {"frame": "model", "spacing": "arc_length"}, id="m"
        ),
    ],
)
def test_augment_offline_equals_the_endpoint(client, model_dir, seeds, tmp_path, args, body):
    c, path = seeds
    _run(model_dir, "augment", str(path), "--count", "9", "--seed", "5", *args, "-o", str(tmp_path / "a.json"))
    rest = client.post("/augment", json={"curves": c, "count": 9, "seed": 5, **body}).json()
    assert json.loads((tmp_path / "a.json").read_text()) == rest


def test_augment_npy_offline_is_the_endpoints_file_byte_for_byte(make_client, model_dir, seeds, tmp_path):
    c, path = seeds
    client = make_client(batch_size=7)  # the service streams 7-curve chunks, the CLI writes 64-curve ones
    _run(model_dir, "augment", str(path), "--count", "150", "--seed", "8", "--neighbours", "2", "-o",
         str(tmp_path / "a.npy"))  # fmt: skip
    rest = client.post("/augment", json={"curves": c, "count": 150, "seed": 8, "neighbours": 2, "format": "npy"})
    assert (tmp_path / "a.npy").read_bytes() == rest.content
    assert np.load(tmp_path / "a.npy").shape == (150, 90, 2)


def test_offline_errors_are_one_line(model_dir, seeds, tmp_path, capsys):
    _, path = seeds
    assert main(["augment", str(path), "--count", "2", "--metrics", "-o", str(tmp_path / "a.npy"),
                 "--model-dir", str(model_dir)]) == 2  # fmt: skip
    assert "--metrics needs a JSON output" in capsys.readouterr().err
    assert main(["augment", str(path), "--count", "2", "--mode", "triplet", "--neighbours", "1",
                 "--model-dir", str(model_dir)]) == 2  # fmt: skip
    assert "neighbours: mode triplet mixes each curve with 2 others" in capsys.readouterr().err
    assert main(["sample", "--count", "2", "--model-dir", str(tmp_path)]) == 2
    assert "manifest.json is missing" in capsys.readouterr().err


def test_offline_commands_need_no_torch(model_dir, seeds, tmp_path):
    _, path = seeds
    model, out_dir = str(model_dir), str(tmp_path)
    code = f"""
import sys
sys.modules["torch"] = None  # any `import torch` now raises ImportError
from curve_vae.cli import main
from tests.helpers import ROOT
assert main(["sample", "--count", "2", "--seed", "1", "--model-dir", {model!r}, "-o", {out_dir!r} + "/s.json"]) == 0
assert main(["augment", {str(path)!r}, "--count", "3", "--model-dir", {model!r}, "-o", {out_dir!r} + "/a.npy"]) == 0
assert main(["fit", {str(path)!r}, "--param", "uniform", "-o", {out_dir!r} + "/f.json"]) == 0
print("ok")
"""
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


def test_a_page_of_the_seeded_sequence_is_that_stretch_of_the_whole(model_dir, seeds, tmp_path):
    _, path = seeds
    _run(model_dir, "augment", str(path), "--count", "7", "--seed", "3", "-o", str(tmp_path / "whole.npy"))
    _run(model_dir, "augment", str(path), "--count", "3", "--seed", "3", "--offset", "4", "-o", str(tmp_path / "p.npy"))
    np.testing.assert_array_equal(np.load(tmp_path / "p.npy"), np.load(tmp_path / "whole.npy")[4:])


@pytest.mark.parametrize("command", ["sample", "augment"])
def test_an_existing_output_is_kept_unless_forced(command, model_dir, seeds, tmp_path, capsys):
    _, path = seeds
    out = tmp_path / "mine.json"
    out.write_text("the user's own file")
    argv = [command, *([str(path)] if command == "augment" else []), "--count", "2", "--seed", "1", "-o", str(out)]
    assert main([*argv, "--model-dir", str(model_dir)]) == 2
    assert f"{out} exists and is left as it is: pass --force" in capsys.readouterr().err
    assert out.read_text() == "the user's own file"
    assert main([*argv, "--model-dir", str(model_dir), "--force"]) == 0
    assert len(json.loads(out.read_text())["curves"]) == 2
