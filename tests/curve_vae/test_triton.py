"""curve_vae.triton: the Triton model repository, config.pbtxt files that match the graphs, the graphs themselves,
nothing overwritten, a tampered graph not exported; each written graph runs, and a tensor type Triton has no name
for is refused."""

from __future__ import annotations

import re

import numpy as np
import onnxruntime as ort
import pytest

from curve_vae.cli import main
from curve_vae.errors import InvalidInput
from curve_vae.triton import TRITON_TYPES, config_pbtxt, smoke_test, write_repository

TENSOR = re.compile(r'\{\s*name: "(\w+)"\s*data_type: (\w+)\s*dims: \[([\d, -]*)\]\s*\}')


def parse(config: str) -> dict:
    """The fields of Triton's text format this repository writes: scalars, and input/output tensors."""
    out: dict = {
        "name": re.search(r'^name: "(\w+)"', config, re.M).group(1),  # type: ignore[union-attr]
        "platform": re.search(r'^platform: "(\w+)"', config, re.M).group(1),  # type: ignore[union-attr]
        "max_batch_size": int(re.search(r"^max_batch_size: (\d+)", config, re.M).group(1)),  # type: ignore[union-attr]
        "dynamic_batching": "dynamic_batching {" in config,
    }
    for kind in ("input", "output"):
        block = re.search(rf"^{kind} \[(.*?)^\]", config, re.M | re.S).group(1)  # type: ignore[union-attr]
        out[kind] = [(n, t, [int(d) for d in dims.split(",")]) for n, t, dims in TENSOR.findall(block)]
    return out


def test_repository_matches_the_graphs_and_runs(model_dir, tmp_path, capsys):
    repo = tmp_path / "repo"
    assert main(["triton", "--model-dir", str(model_dir), "--out", str(repo), "--max-batch-size", "64"]) == 0
    assert "a batch of 3 runs" in capsys.readouterr().out
    for graph in ("encoder", "decoder"):
        folder = repo / f"curve_vae_{graph}"
        config = parse((folder / "config.pbtxt").read_text())
        assert config["name"] == folder.name and config["platform"] == "onnxruntime_onnx"
        assert config["max_batch_size"] == 64 and config["dynamic_batching"]
        assert (folder / "1" / "model.onnx").read_bytes() == (model_dir / f"{graph}.onnx").read_bytes()
        session = ort.InferenceSession(str(folder / "1" / "model.onnx"), providers=["CPUExecutionProvider"])
        for kind, tensors in (("input", session.get_inputs()), ("output", session.get_outputs())):
            expected = [(t.name, TRITON_TYPES[t.type], list(t.shape[1:])) for t in tensors]
            assert config[kind] == expected, (graph, kind)
            assert all(t.shape[0] == "batch" for t in tensors)  # the dimension Triton batches along
    decoder = ort.InferenceSession(str(repo / "curve_vae_decoder" / "1" / "model.onnx"))
    curves, ctrl = decoder.run(None, {"latent": np.zeros((5, 32), np.float32)})
    assert curves.shape == (5, 161, 2) and ctrl.shape == (5, 31, 2)
    assert parse((repo / "curve_vae_decoder" / "config.pbtxt").read_text())["output"][1] == (
        "control_points",
        "TYPE_FP32",
        [31, 2],
    )


def test_repository_is_not_overwritten_without_force(model_dir, tmp_path, capsys):
    repo = tmp_path / "repo"
    assert main(["triton", "--model-dir", str(model_dir), "--out", str(repo)]) == 0
    config = repo / "curve_vae_encoder" / "config.pbtxt"
    config.write_text("edited by hand")
    assert main(["triton", "--model-dir", str(model_dir), "--out", str(repo)]) == 2
    assert "exists and is left as it is: pass --force" in capsys.readouterr().err
    assert config.read_text() == "edited by hand"
    assert main(["triton", "--model-dir", str(model_dir), "--out", str(repo), "--force"]) == 0
    assert config.read_text().startswith('name: "curve_vae_encoder"')


def test_a_tampered_graph_is_not_exported(model_dir, tmp_path, capsys):
    import shutil

    copy = tmp_path / "model"
    shutil.copytree(model_dir, copy)
    with open(copy / "encoder.onnx", "ab") as f:
        f.write(b"\0")
    assert main(["triton", "--model-dir", str(copy), "--out", str(tmp_path / "repo")]) == 2
    assert re.search(r"encoder\.onnx: sha256 .* does not match", capsys.readouterr().err)
    assert not (tmp_path / "repo").exists()


def test_the_smoke_test_runs_each_graph_on_a_batch(model_dir, tmp_path):
    encoder, decoder = write_repository(model_dir, tmp_path / "repo", prefix="cv")
    assert [encoder.name, decoder.name] == ["cv_encoder", "cv_decoder"]
    assert smoke_test(encoder, batch=2) == {"mean": (2, 32), "log_var": (2, 32)}
    assert smoke_test(decoder, batch=4) == {"curves": (4, 161, 2), "control_points": (4, 31, 2)}


def test_a_tensor_type_triton_is_not_told_of_is_refused_by_name(tmp_path):
    onnx = pytest.importorskip("onnx")
    from onnx import TensorProto, helper

    graph = helper.make_graph(
        [helper.make_node("Identity", ["steps"], ["out"])],
        "g",
        [helper.make_tensor_value_info("steps", TensorProto.INT32, ["batch", 3])],
        [helper.make_tensor_value_info("out", TensorProto.INT32, ["batch", 3])],
    )
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)], ir_version=8)
    onnx.save(model, tmp_path / "g.onnx")
    session = ort.InferenceSession(str(tmp_path / "g.onnx"), providers=["CPUExecutionProvider"])
    with pytest.raises(InvalidInput, match=r"^input steps: type tensor\(int32\) has no Triton data type here$"):
        config_pbtxt("g", session, max_batch_size=8, max_queue_delay_us=100)
