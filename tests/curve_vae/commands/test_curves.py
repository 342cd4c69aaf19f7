"""curve_vae/commands/curves.py: `curve-vae reconstruct` and `encode` offline write the JSON the endpoints answer for
the same curves and reading; encode writes JSON alone; neither replaces a user's file unless forced."""

from __future__ import annotations

import json

import pytest

from curve_vae.cli import main


@pytest.fixture
def seeds(curves, tmp_path):
    c = [(x * (1 + i) - 20 * i).tolist() for i, x in enumerate(curves(3, 70, seed=4))]
    path = tmp_path / "in.json"
    path.write_text(json.dumps({"curves": c}))
    return c, path


@pytest.mark.parametrize(
    "args,body",
    [
        pytest.param([], {}, id="default-reading"),
        pytest.param(
            ["--pose", "as_is", "--spacing", "arc_length"], {"pose": "as_is", "spacing": "arc_length"}, id="as-is"
        ),
    ],
)
def test_encode_offline_equals_the_endpoint(client, model_dir, seeds, tmp_path, args, body):
    c, path = seeds
    assert main(["encode", str(path), *args, "--model-dir", str(model_dir), "-o", str(tmp_path / "e.json")]) == 0
    got = json.loads((tmp_path / "e.json").read_text())
    rest = client.post("/encode", json={"curves": c, **body}).json()
    assert got == rest and len(got["mean"]) == 3 and len(got["mean"][0]) == 32


@pytest.mark.parametrize(
    "args,body",
    [
        pytest.param(["--output-as", "bspline"], {"output": "bspline"}, id="splines-alone"),
        pytest.param(["--output-as", "both", "--metrics"], {"output": "both", "metrics": True}, id="both-with-metrics"),
        pytest.param(["--n-points", "25"], {"n_points": 25}, id="respaced"),
    ],
)
def test_reconstruct_offline_equals_the_endpoint(client, model_dir, seeds, tmp_path, args, body):
    c, path = seeds
    assert main(["reconstruct", str(path), *args, "--model-dir", str(model_dir), "-o", str(tmp_path / "r.json")]) == 0
    got = json.loads((tmp_path / "r.json").read_text())
    rest = client.post("/reconstruct", json={"curves": c, **body}).json()
    assert got == {k: rest[k] for k in got} and "mse" in got
    assert ("curves" in got) == (body.get("output") != "bspline")
    assert ("splines" in got) == (body.get("output") in ("bspline", "both"))
    assert ("metrics" in got) == bool(body.get("metrics"))


def test_encode_writes_json_alone_and_nothing_else(model_dir, seeds, tmp_path, capsys):
    _, path = seeds
    out = tmp_path / "latents.npy"
    assert main(["encode", str(path), "--model-dir", str(model_dir), "-o", str(out)]) == 2
    assert f"{out}: encode writes latents as JSON" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("command", ["reconstruct", "encode"])
def test_an_existing_output_is_kept_unless_forced(command, model_dir, seeds, tmp_path, capsys):
    _, path = seeds
    out = tmp_path / "mine.json"
    out.write_text("the user's own file")
    argv = [command, str(path), "--model-dir", str(model_dir), "-o", str(out)]
    assert main(argv) == 2
    assert f"{out} exists and is left as it is: pass --force" in capsys.readouterr().err
    assert out.read_text() == "the user's own file"
    assert main([*argv, "--force"]) == 0
    assert len(json.loads(out.read_text())["mse" if command == "reconstruct" else "mean"]) == 3
