"""curve_vae.distributed: the Ray Data job on a local cluster writes the curves the command line makes for the same
request; its Parquet shards are read back in the sequence's order, whatever order they were written in."""

from __future__ import annotations

import json

import numpy as np
import pytest

from curve_vae.cli import main
from tests.helpers import SHIPPED


@pytest.mark.integration
@pytest.mark.slow
def test_the_ray_job_writes_the_commands_curves(tmp_path):
    ray = pytest.importorskip("ray")
    from curve_vae.distributed import augment_on_ray, read_parquet_dir

    t = np.linspace(0, 1, 40)
    seeds = [np.stack([t * 8, np.sin(np.pi * t) * k], 1) for k in (2.0, 3.0, -1.0, 1.5)]
    (tmp_path / "seeds.json").write_text(json.dumps([s.tolist() for s in seeds]))
    out = tmp_path / "cli.json"
    args = [
        "augment",
        str(tmp_path / "seeds.json"),
        "--count",
        "300",
        "--seed",
        "7",
        "--mode",
        "triplet",
        "-o",
        str(out),
    ]
    assert main([*args, "--model-dir", str(SHIPPED), "--no-progress"]) == 0
    want = json.loads(out.read_text())
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        augment_on_ray(
            seeds, 300, seed=7, mode="triplet", out=tmp_path / "shards", block=100, concurrency=2, model_dir=SHIPPED
        )
    finally:
        ray.shutdown()
    got = read_parquet_dir(tmp_path / "shards")
    assert got["index"].tolist() == list(range(300)) and len(list((tmp_path / "shards").glob("*.parquet"))) >= 2
    np.testing.assert_allclose(got["curves"], np.array(want["curves"]), atol=1e-4)  # float32 shards, float64 JSON
    np.testing.assert_array_equal(got["sources"], want["sources"])
    np.testing.assert_allclose(got["weights"], want["weights"], rtol=1e-12)


def test_shards_are_read_back_in_the_sequences_order(tmp_path):
    """Shards of items 4-6 and 0-3 (written in that order, as Ray may finish them), in the job's schema."""
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    from curve_vae.distributed import read_parquet_dir

    curve_type = pa.list_(pa.list_(pa.float32(), 2))
    for name, items in (("a.parquet", [4, 5, 6]), ("b.parquet", [0, 1, 2, 3])):
        table = pa.table(
            {
                "index": pa.array(items, pa.int64()),
                "curve": pa.array([[[i, -i]] * 3 for i in items], curve_type),
                "sources": pa.array([[i % 2, 2] for i in items], pa.list_(pa.int64(), 2)),
                "weights": pa.array([[i / 10, 1 - i / 10] for i in items], pa.list_(pa.float64(), 2)),
            }
        )
        pq.write_table(table, tmp_path / name)
    got = read_parquet_dir(tmp_path)
    assert got["index"].tolist() == list(range(7))
    assert got["curves"].dtype == np.float32 and got["curves"].shape == (7, 3, 2)
    np.testing.assert_array_equal(got["curves"][:, 1], [[i, -i] for i in range(7)])
    assert got["sources"].tolist() == [[i % 2, 2] for i in range(7)]
    np.testing.assert_allclose(got["weights"][:, 0], np.arange(7) / 10, rtol=0, atol=0)
