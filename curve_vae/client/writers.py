"""Batches of curves on disk with what made them: `.npy`, `.npz` or Parquet (pyarrow, the `parquet` extra), each
with a sidecar manifest (`<file>.manifest.json`: the service's and the model's versions and sha256, the request,
the seed) from which `regenerate` makes the same file again.

    with Client(url) as c:
        write_augment("batch.parquet", c, seeds, 100_000, seed=1, chunk=8192)   # streamed: one chunk in memory
    regenerate("batch.parquet.manifest.json", "again.parquet")                # the same curves

Parquet rows: `index` (the item's place in the seeded sequence) and `curve` (its points, a list of [x, y] float32).
"""

from __future__ import annotations

import hashlib
import json
import time
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae import __version__
from curve_vae.client.client import Client, fresh_seed
from curve_vae.client.inputs import CurvesLike, as_batch
from curve_vae.client.results import Augmented, ModelRef
from curve_vae.errors import InvalidInput
from curve_vae.files import atomic_path, atomic_write_text
from curve_vae.npy import npy_chunks

MANIFEST_SUFFIX = ".manifest.json"
FORMATS = (".npy", ".npz", ".parquet")


def manifest_path(path: str | Path) -> Path:
    return Path(str(path) + MANIFEST_SUFFIX)


def write_augment(
    path: str | Path,
    client: Client,
    curves: CurvesLike,
    count: int,
    *,
    seed: int | None = None,
    chunk: int = 4096,
    **fields: Any,
) -> dict[str, Any]:
    """Stream `count` augmented curves (client.augment_chunks) into `path` (.npy, .npz or .parquet, written
    atomically) and its manifest; returns the manifest. `fields`: /augment's other fields (mode, neighbours, …).
    One curve is refused (a mix needs two) before anything is asked or written."""
    seed = fresh_seed() if seed is None else seed
    curves = as_batch(curves, "write_augment", at_least=2)
    chunks = client.augment_chunks(curves, count, seed=seed, chunk=chunk, **fields)
    body = {"curves": [np.asarray(c, np.float64).tolist() for c in curves], "count": count, "seed": seed}
    request = {
        "endpoint": "/augment",
        "body": {**body, **{k: v for k, v in fields.items() if v is not None}},
        "chunk": chunk,
    }
    shape = write_chunks(path, count, chunks)
    return _write_manifest(path, client.model_ref(), request, seed, shape)


def write_chunks(path: str | Path, count: int, chunks: Iterable[Augmented]) -> tuple[int, ...]:
    """Chunks of curves into one file by its suffix; the array's shape."""
    path = Path(path)
    suffix = path.suffix
    if suffix not in FORMATS:
        raise InvalidInput(f"{path}: write .npy, .npz or .parquet")
    it = iter(chunks)
    first = next(it, None)
    n_points = _curves(first).shape[1] if first is not None else 0
    shape = (count, n_points, 2)
    everything = _chained(first, it)
    if suffix == ".npy":
        with atomic_path(path) as tmp, open(tmp, "wb") as f:
            for block in npy_chunks(shape, (_curves(c) for c in everything)):
                f.write(block)
    elif suffix == ".npz":
        data = np.concatenate([_curves(c) for c in everything]) if first is not None else np.zeros(shape, np.float32)
        with atomic_path(path) as tmp, open(tmp, "wb") as f:
            np.savez(f, curves=data.astype(np.float32))
    else:
        _write_parquet(path, everything, n_points)
    return shape


def _curves(chunk: Augmented) -> np.ndarray:
    """A chunk's curves, one array (n, n_points, 2): an augmentation's curves all have the same length."""
    return chunk.stacked()


def _chained(first: Augmented | None, rest: Iterable[Augmented]) -> Iterable[Augmented]:
    if first is not None:
        yield first
        yield from rest


def _write_parquet(path: Path, chunks: Iterable[Augmented], n_points: int) -> None:
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as e:  # the optional extra
        raise ImportError("Parquet needs pyarrow: pip install 'curve-vae[parquet]'") from e
    schema = pa.schema([("index", pa.int64()), ("curve", pa.list_(pa.list_(pa.float32(), 2)))])
    with atomic_path(path) as tmp:
        with pq.ParquetWriter(str(tmp), schema) as writer:  # a row group per chunk: bounded memory
            for c in chunks:
                flat = pa.array(_curves(c).astype(np.float32, copy=False).reshape(-1), pa.float32())
                points = pa.FixedSizeListArray.from_arrays(flat, 2)
                offsets = pa.array(np.arange(len(c.curves) + 1, dtype=np.int32) * n_points)
                lists = pa.ListArray.from_arrays(offsets, points).cast(schema.field("curve").type)
                index = pa.array(np.arange(c.offset, c.offset + len(c.curves)), pa.int64())
                writer.write_table(pa.table({"index": index, "curve": lists}, schema=schema))


def read_batch(path: str | Path) -> np.ndarray:
    """The curves (count, n, 2) float32 of a file `write_augment` wrote."""
    path = Path(path)
    if path.suffix == ".npy":
        return np.load(path, allow_pickle=False)
    if path.suffix == ".npz":
        with np.load(path, allow_pickle=False) as z:
            return z["curves"]
    import pyarrow.parquet as pq

    table = pq.read_table(str(path))
    curves = table.column("curve").to_pylist()
    return np.asarray(curves, np.float32).reshape(len(curves), -1, 2)


def _write_manifest(
    path: str | Path, model: ModelRef, request: dict[str, Any], seed: int, shape: tuple[int, ...]
) -> dict[str, Any]:
    manifest = {
        "format": "curve-vae batch",
        "manifest_version": 1,
        "file": Path(path).name,
        "sha256": hashlib.sha256(Path(path).read_bytes()).hexdigest(),
        "shape": list(shape),
        "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "client_version": __version__,
        "model": model.json(),
        "request": request,
        "seed": seed,
    }
    atomic_write_text(manifest_path(path), json.dumps(manifest, indent=1) + "\n")
    return manifest


def regenerate(manifest: str | Path, out: str | Path, *, url: str | None = None, **client: Any) -> dict[str, Any]:
    """Make the file a manifest describes again, into `out`, from the server it names (or `url`); refuses a server
    whose model's sha256 differs from the manifest's (other weights, other curves)."""
    m = json.loads(Path(manifest).read_text())
    req = m["request"]
    if req["endpoint"] != "/augment":
        raise InvalidInput(f"{manifest}: made by {req['endpoint']}; only /augment batches are made again here")
    body = dict(req["body"])
    with Client(url or m["model"]["url"], **client) as c:
        if c.model_ref().sha256 != m["model"]["sha256"]:
            raise InvalidInput(
                f"{c.url} serves {c.model_ref().name} {c.model_ref().version} with other files than the manifest's "
                f"{m['model']['name']} {m['model']['version']}: its curves would differ"
            )
        curves, count, seed = body.pop("curves"), body.pop("count"), body.pop("seed")
        return write_augment(out, c, curves, count, seed=seed, chunk=req.get("chunk", 4096), **body)
