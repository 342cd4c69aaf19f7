"""The client's datasets and files: the same curves for any number of DataLoader workers, Parquet and .npz files
that round-trip with their manifest."""

from __future__ import annotations

import json

import numpy as np
import pytest

from curve_vae.client import Client
from curve_vae.client.writers import manifest_path, read_batch, regenerate, write_augment

C1 = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
C2 = [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]]
C3 = [[0, 4], [2, 5], [4, 4], [6, 2], [8, 1], [10, 2], [12, 4]]


def test_the_dataset_gives_the_same_curves_for_0_and_2_workers(live_server):
    torch = pytest.importorskip("torch")
    from torch.utils.data import DataLoader

    from curve_vae.client.dataset import AugmentDataset

    ds = AugmentDataset(live_server.url, [C1, C2, C3], 70, seed=3, batch=16, n_points=30)
    alone = [b for b in DataLoader(ds, batch_size=None, num_workers=0)]
    shared = [b for b in DataLoader(ds, batch_size=None, num_workers=2)]
    assert [len(b) for b in alone] == [16, 16, 16, 16, 6] and len(shared) == len(alone)
    for a, b in zip(alone, shared, strict=True):
        torch.testing.assert_close(a, b)
    with Client(live_server.url) as c:
        np.testing.assert_allclose(torch.cat(alone).numpy(), c.augment([C1, C2, C3], 70, seed=3, n_points=30).curves,
                                   atol=1e-5)  # fmt: skip
    ds.set_epoch(1)
    other = next(iter(DataLoader(ds, batch_size=None)))
    assert not torch.allclose(other, alone[0])


@pytest.mark.parametrize("suffix", [".parquet", ".npz", ".npy"])
def test_a_batch_file_round_trips_with_its_manifest(live_server, tmp_path, suffix):
    if suffix == ".parquet":
        pytest.importorskip("pyarrow")
    path = tmp_path / f"batch{suffix}"
    with Client(live_server.url) as c:
        m = write_augment(path, c, [C1, C2, C3], 50, seed=11, chunk=16, mode="triplet", n_points=24)
        want = c.augment([C1, C2, C3], 50, seed=11, mode="triplet", n_points=24).curves
        served = c.model_ref()
    got = read_batch(path)
    assert got.shape == (50, 24, 2) and got.dtype == np.float32
    np.testing.assert_allclose(got, want, atol=1e-5)
    saved = json.loads(manifest_path(path).read_text())
    assert saved == m and saved["seed"] == 11 and saved["shape"] == [50, 24, 2]
    assert saved["model"]["sha256"] == served.sha256 and saved["model"]["version"] == served.version
    assert saved["request"]["body"]["mode"] == "triplet"
    again = tmp_path / f"again{suffix}"
    regenerate(manifest_path(path), again)
    np.testing.assert_array_equal(read_batch(again), got)


def test_a_manifest_of_another_model_is_refused(live_server, tmp_path):
    path = tmp_path / "b.npz"
    with Client(live_server.url) as c:
        write_augment(path, c, [C1, C2], 8, seed=1)
    m = json.loads(manifest_path(path).read_text())
    m["model"]["sha256"]["decoder.onnx"] = "0" * 64
    manifest_path(path).write_text(json.dumps(m))
    with pytest.raises(ValueError, match="its curves would differ"):
        regenerate(manifest_path(path), tmp_path / "c.npz")
