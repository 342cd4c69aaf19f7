"""curve_vae.client.dataset: seeded augmentation streamed into a PyTorch loop; against a live server the same batches
for 0 and 2 DataLoader workers, the server's own curves; against a stand-in transport, which items each worker asks
for, and one sequence per epoch."""

from __future__ import annotations

import io
import json

import httpx
import numpy as np
import pytest

from curve_vae.client import Client
from curve_vae.errors import InvalidInput

torch = pytest.importorskip("torch")

from curve_vae.client.dataset import AugmentDataset  # noqa: E402  (needs torch)

C1 = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
C2 = [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]]
C3 = [[0, 4], [2, 5], [4, 4], [6, 2], [8, 1], [10, 2], [12, 4]]


def test_the_dataset_gives_the_same_curves_for_0_and_2_workers(live_server):
    from torch.utils.data import DataLoader

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


def _recording(asked: list[dict]) -> httpx.MockTransport:
    """A server whose item i of a sequence is the curve of points all (seed mod 1000) + i."""

    def handle(request: httpx.Request) -> httpx.Response:
        if request.url.path == "/model":
            return httpx.Response(200, json={"name": "m", "version": "1", "files": {}})
        body = json.loads(request.content)
        asked.append(body)
        items = np.arange(body["offset"], body["offset"] + body["count"], dtype=np.float32) + body["seed"] % 1000
        buf = io.BytesIO()
        np.save(buf, np.repeat(np.repeat(items[:, None, None], 3, 1), 2, 2))
        return httpx.Response(200, content=buf.getvalue())

    return httpx.MockTransport(handle)


def test_each_item_is_a_batch_of_the_sequence_in_order():
    asked: list[dict] = []
    ds = AugmentDataset("http://x", [C1, C2], 10, seed=7, batch=4, client={"transport": _recording(asked)}, mode="pair")
    batches = list(ds)
    assert len(ds) == 3 and [b.shape for b in batches] == [(4, 3, 2), (4, 3, 2), (2, 3, 2)]
    assert torch.cat(batches)[:, 0, 0].tolist() == [7.0 + i for i in range(10)]
    assert [(a["offset"], a["count"], a["seed"], a["mode"]) for a in asked] == [(0, 4, 7, "pair"), (4, 4, 7, "pair"),
                                                                                (8, 2, 7, "pair")]  # fmt: skip


def test_another_epoch_is_another_sequence_the_same_each_time():
    ds = AugmentDataset("http://x", [C1, C2], 4, seed=7, batch=4, client={"transport": _recording([])})
    first = next(iter(ds))
    ds.set_epoch(1)
    one = ds.epoch_seed()
    assert one != 7 and 0 <= one < 2**53 and AugmentDataset("u", [C1], 1, seed=7).epoch_seed() == 7
    ds.set_epoch(2)
    assert ds.epoch_seed() not in (7, one)
    ds.set_epoch(1)
    assert ds.epoch_seed() == one and not torch.equal(next(iter(ds)), first)


def test_one_seed_curve_is_refused_when_the_dataset_is_made():
    with pytest.raises(InvalidInput, match="AugmentDataset needs at least 2 curves, got one curve"):
        AugmentDataset("http://x", np.array(C1), 4, seed=1)
