"""Generation past one machine: millions of augmented curves made offline on a Ray cluster (Ray Data), each worker
an actor holding the onnxruntime sessions of a model directory, writing Parquet shards.

    import ray
    ray.init()                                   # or ray.init(address="auto") on a cluster
    augment_on_ray(seeds, 10_000_000, seed=1, out="s3://bucket/batch/", concurrency=64, block=65_536)

Item i of the sequence depends on (seed, i) alone (inference.generation.augmenting.AugmentPlan), so the shards hold
exactly the
curves `curve-vae augment … --seed 1` and POST /augment make for the same request, however the blocks are cut or
scheduled. Each shard's rows: `index` (the item's place in the sequence), `curve` (its points, a list of [x, y]
float32), `sources` and `weights` (its seed curves, anchor first, and their weights) — the schema
curve_vae.client.writers uses, so `read_parquet_dir` reads them back in order. Needs the `ray` extra.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae.inference.reading import Reading


class AugmentActor:
    """One Ray worker: a model's sessions opened once (in __init__), the seed curves read once, then blocks of the
    sequence on demand."""

    def __init__(
        self,
        model_dir: str,
        seeds: list[list[list[float]]],
        seed: int,
        mode: str,
        neighbours: int | None,
        reading: dict[str, Any],
        n_points: int | None,
    ) -> None:
        from curve_vae.inference.model.cpus import limit_blas_threads
        from curve_vae.inference.runtime import CurveRuntime

        self.runtime = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1, warm_up=False)
        limit_blas_threads(1)  # one core an actor: numpy's BLAS too (inference/model/cpus.py)
        self.plan = self.runtime.plan_augment(
            [np.asarray(c, np.float64) for c in seeds],
            seed=seed,
            mode=mode,
            neighbours=neighbours,
            reading=Reading(**reading),
        )
        self.spacing = self.runtime.reading(Reading(**reading)).spacing
        self.n_points = n_points

    def __call__(self, batch: dict[str, np.ndarray]) -> Any:
        import pyarrow as pa

        tables = []
        for start, stop in zip(batch["start"].tolist(), batch["stop"].tolist()):
            made = self.runtime.augment(self.plan, start, stop, n_points=self.n_points, spacing=self.spacing)
            tables.append(_table(start, made.curves, made.sources, made.weights))
        return pa.concat_tables(tables)


def _table(start: int, curves: np.ndarray, sources: np.ndarray, weights: np.ndarray) -> Any:
    import pyarrow as pa

    n, points = len(curves), curves.shape[1]
    flat = pa.FixedSizeListArray.from_arrays(pa.array(curves.astype(np.float32).reshape(-1), pa.float32()), 2)
    curve = pa.ListArray.from_arrays(pa.array(np.arange(n + 1, dtype=np.int32) * points), flat)
    k = sources.shape[1]
    src = pa.FixedSizeListArray.from_arrays(pa.array(sources.reshape(-1), pa.int64()), k)
    wts = pa.FixedSizeListArray.from_arrays(pa.array(weights.reshape(-1), pa.float64()), k)
    index = pa.array(np.arange(start, start + n), pa.int64())
    return pa.table(
        {"index": index, "curve": curve.cast(pa.list_(pa.list_(pa.float32(), 2))), "sources": src, "weights": wts}
    )


def augment_on_ray(
    seeds: Sequence[Any],
    count: int,
    *,
    seed: int,
    out: str | Path,
    model_dir: str | Path | None = None,
    block: int = 8192,
    concurrency: int | None = None,
    mode: str = "pair",
    neighbours: int | None = None,
    reading: Reading | None = None,
    n_points: int | None = None,
) -> str:
    """Items 0 … count-1 of the seeded augmentation sequence of `seeds`, `block` items a Ray task, on `concurrency`
    actors (default: Ray's autoscaling from 1 to the cluster's CPUs), written as Parquet shards under `out`;
    returns `out`. Needs a running Ray (ray.init)."""
    import ray

    from curve_vae.inference.model.shipped import model_directory

    r = reading or Reading()
    blocks = [{"start": s, "stop": min(s + block, count)} for s in range(0, count, block)]
    kwargs = {
        "model_dir": str(model_directory(model_dir)),
        "seeds": [np.asarray(c, np.float64).tolist() for c in seeds],
        "seed": seed,
        "mode": mode,
        "neighbours": neighbours,
        "reading": asdict(r),
        "n_points": n_points,
    }
    ds = ray.data.from_items(blocks, override_num_blocks=len(blocks)).map_batches(
        AugmentActor,
        fn_constructor_kwargs=kwargs,
        batch_size=1,
        batch_format="numpy",
        concurrency=concurrency or (1, max(1, int(ray.cluster_resources().get("CPU", 1)))),
        num_cpus=1,
    )
    ds.write_parquet(str(out))
    return str(out)


def read_parquet_dir(path: str | Path) -> dict[str, np.ndarray]:
    """The shards under `path` in the sequence's order: `index` (m,), `curves` (m, n, 2) float32, `sources` and
    `weights` (m, k)."""
    import pyarrow.dataset as pds

    table = pds.dataset(str(path), format="parquet").to_table()
    order = np.argsort(table.column("index").to_numpy())
    curves = np.asarray(table.column("curve").to_pylist(), np.float32)
    return {
        "index": table.column("index").to_numpy()[order],
        "curves": curves.reshape(len(curves), -1, 2)[order],
        "sources": np.asarray(table.column("sources").to_pylist(), np.int64)[order],
        "weights": np.asarray(table.column("weights").to_pylist(), np.float64)[order],
    }
