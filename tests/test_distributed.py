"""The Ray Data job on a local cluster writes the curves the command line makes for the same request."""

from __future__ import annotations

import json

import numpy as np
import pytest

from curve_vae.cli import main
from tests.helpers import SHIPPED

pytestmark = [pytest.mark.integration, pytest.mark.slow]
ray = pytest.importorskip("ray")


def test_the_ray_job_writes_the_commands_curves(tmp_path):
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
