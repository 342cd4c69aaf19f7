"""`--server URL`: each command against a live server writes what it writes with the local model."""

from __future__ import annotations

import json

import numpy as np
import pytest

from curve_vae.cli import main

C = [
    [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]],
    [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]],
    [[0, 4], [2, 5], [4, 4], [6, 2], [8, 1], [10, 2], [12, 4]],
]


def _close(a, b) -> None:
    """JSON bodies equal, numbers to float rounding (the server's onnxruntime threads may differ)."""
    if isinstance(a, dict):
        assert set(a) == set(b), (set(a), set(b))
        for k in a:
            _close(a[k], b[k])
    elif isinstance(a, list) and a and isinstance(a[0], (list, dict)):
        assert len(a) == len(b)
        for x, y in zip(a, b):
            _close(x, y)
    elif isinstance(a, (int, float)) and not isinstance(a, bool) or (isinstance(a, list) and a):
        np.testing.assert_allclose(np.asarray(a, float), np.asarray(b, float), rtol=1e-6, atol=1e-9)
    else:
        assert a == b


@pytest.mark.parametrize(
    "command",
    [
        pytest.param(["sample", "--count", "5", "--seed", "3", "--n-points", "20"], id="sample"),
        pytest.param(["sample", "--count", "3", "--seed", "4", "--output-as", "both", "--metrics"], id="sample-both"),
        pytest.param(["augment", "IN", "--count", "300", "--seed", "2", "--mode", "triplet"], id="augment-json"),
        pytest.param(["augment", "IN", "--count", "300", "--seed", "2", "-o", "OUT.npy"], id="augment-npy"),
        pytest.param(["reconstruct", "IN", "--output-as", "both", "--metrics"], id="reconstruct"),
        pytest.param(["encode", "IN", "--pose", "as_is"], id="encode"),
        pytest.param(["fit", "IN", "--n-ctrl", "5", "--n-points", "9"], id="fit"),
    ],
)
def test_server_output_equals_the_local_commands(live_server, model_dir, tmp_path, command):
    (tmp_path / "in.json").write_text(json.dumps(C))
    outs = []
    for where in (["--model-dir", str(model_dir)], ["--server", live_server.url]):
        out = tmp_path / f"out{len(outs)}{'.npy' if 'OUT.npy' in command else '.json'}"
        argv = [str(tmp_path / "in.json") if x == "IN" else x for x in command if x not in ("-o", "OUT.npy")]
        if command[0] in ("fit",):
            where = where if where[0] == "--server" else []
        assert main([*argv, "-o", str(out), *where, *(["--no-progress"] if command[0] == "augment" else [])]) == 0
        outs.append(out)
    if outs[0].suffix == ".npy":
        np.testing.assert_allclose(np.load(outs[0]), np.load(outs[1]), rtol=1e-5, atol=1e-5)
    else:
        _close(json.loads(outs[0].read_text()), json.loads(outs[1].read_text()))


def test_revolve_on_a_server_writes_the_same_mesh(live_server, tmp_path):
    (tmp_path / "p.json").write_text(json.dumps([[0, 0], [3, 0], [4, 1], [3, 3], [0, 5]]))
    for fmt in ("obj", "stl"):
        local, remote = tmp_path / f"a.{fmt}", tmp_path / f"b.{fmt}"
        assert main(["revolve", str(tmp_path / "p.json"), "-o", str(local), "--segments", "16"]) == 0
        assert (
            main(
                [
                    "revolve",
                    str(tmp_path / "p.json"),
                    "-o",
                    str(remote),
                    "--segments",
                    "16",
                    "--server",
                    live_server.url,
                ]
            )
            == 0
        )
        assert local.read_bytes() == remote.read_bytes()


def test_a_refusal_of_the_server_is_the_commands_error(live_server, tmp_path, capsys):
    (tmp_path / "in.json").write_text(json.dumps(C[:2]))
    assert (
        main(["augment", str(tmp_path / "in.json"), "--count", "5", "--mode", "triplet", "--server", live_server.url])
        == 2
    )
    assert "422: curves: mode triplet needs at least 3 curves, got 2" in capsys.readouterr().err
