"""An NVIDIA Triton Inference Server model repository from an exported model: the same ONNX graphs, served there.

    curve-vae triton --model-dir models --out triton-repo

writes, for each graph, `<prefix>_<graph>/1/model.onnx` and `<prefix>_<graph>/config.pbtxt`
(platform onnxruntime_onnx, the batch dimension as Triton's own, input and output names,
dtypes and dims read from the graphs themselves, dynamic batching on). Torch-free: it copies
the files the manifest lists, after checking their sha256.

What Triton serves are raw tensors in the model's 128×128 plane: encoder `curves` (B, 161, 2)
float32 → `mean`, `log_var` (B, 32); decoder `latent` (B, 32) → `curves` (B, 161, 2) and, with
a B-spline head, `control_points` (B, K, 2). The REST service's geometry (frames, resampling
to 161 points, blending frames for interpolants, the learned prior for sampling) happens
around these calls, in `geometry/` and `inference/runtime.py`; a Triton client that wants it
does the same before and after.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import onnxruntime as ort

from curve_vae.errors import InvalidInput
from curve_vae.inference.model.manifest import Manifest

#: onnxruntime's tensor types → Triton's data types
TRITON_TYPES = {"tensor(float)": "TYPE_FP32", "tensor(double)": "TYPE_FP64", "tensor(int64)": "TYPE_INT64"}


def _tensors(items: list, kind: str) -> str:
    rows = []
    for t in items:
        if t.type not in TRITON_TYPES:
            raise InvalidInput(f"{kind} {t.name}: type {t.type} has no Triton data type here")
        dims = [d if isinstance(d, int) else -1 for d in t.shape[1:]]  # the batch dimension is Triton's own
        rows.append(f'  {{\n    name: "{t.name}"\n    data_type: {TRITON_TYPES[t.type]}\n    dims: {dims}\n  }}')
    return f"{kind} [\n" + ",\n".join(rows) + "\n]"


def config_pbtxt(name: str, session: ort.InferenceSession, *, max_batch_size: int, max_queue_delay_us: int) -> str:
    """Triton's model configuration of one ONNX graph, in its text format."""
    return "\n".join(
        [
            f'name: "{name}"',
            'platform: "onnxruntime_onnx"',
            f"max_batch_size: {max_batch_size}",
            _tensors(session.get_inputs(), "input"),
            _tensors(session.get_outputs(), "output"),
            f"dynamic_batching {{\n  max_queue_delay_microseconds: {max_queue_delay_us}\n}}",
            "instance_group [\n  {\n    kind: KIND_AUTO\n    count: 1\n  }\n]",
            "",
        ]
    )


def write_repository(
    model_dir: str | Path,
    out: str | Path,
    *,
    prefix: str = "curve_vae",
    max_batch_size: int = 256,
    max_queue_delay_us: int = 2000,
    force: bool = False,
) -> list[Path]:
    """Write the repository; returns the model folders. Refuses to replace existing ones unless `force`."""
    manifest = Manifest.read(model_dir)  # checks the graphs' sha256
    out = Path(out)
    folders = []
    for graph in ("encoder", "decoder"):
        folder = out / f"{prefix}_{graph}"
        if folder.exists() and not force:
            raise InvalidInput(
                f"{folder} exists and is left as it is: pass --force to replace it, or give another --out"
            )
        src = Path(model_dir) / getattr(manifest.graphs, graph).file
        session = ort.InferenceSession(str(src), providers=["CPUExecutionProvider"])
        (folder / "1").mkdir(parents=True, exist_ok=True)
        tmp = folder / "1" / ".model.onnx.tmp"
        shutil.copyfile(src, tmp)
        tmp.replace(folder / "1" / "model.onnx")
        text = config_pbtxt(folder.name, session, max_batch_size=max_batch_size, max_queue_delay_us=max_queue_delay_us)
        (folder / "config.pbtxt").write_text(text)
        folders.append(folder)
    return folders


def smoke_test(folder: Path, batch: int = 3) -> dict[str, tuple[int, ...]]:
    """Run a repository's model.onnx on zeros of its input shape: output name → shape (a check Triton would do)."""
    session = ort.InferenceSession(str(folder / "1" / "model.onnx"), providers=["CPUExecutionProvider"])
    feeds = {i.name: np.zeros((batch, *i.shape[1:]), np.float32) + 64.0 for i in session.get_inputs()}
    outs = session.run(None, feeds)
    return {o.name: tuple(v.shape) for o, v in zip(session.get_outputs(), outs)}
