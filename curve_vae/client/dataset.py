"""Seeded augmentation streamed from a server into a PyTorch training loop (needs torch: the `train` extra).

    ds = AugmentDataset("http://127.0.0.1:8000", seeds, count=100_000, seed=1, batch=512)
    for batch in DataLoader(ds, batch_size=None, num_workers=4):   # (512, n, 2) float32 tensors
        ...

Each item is a batch of `batch` curves: one /augment .npy request, items offset … of the seeded sequence. Batch j
goes to worker j mod (number of workers), and DataLoader takes the workers' batches in turn, so 0, 1 or 4 workers
give the same batches in the same order (use `batch_size=None`: the dataset batches). `set_epoch(e)` draws another
sequence for each epoch, the same for the same (seed, e).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import torch
from torch.utils.data import IterableDataset, get_worker_info

from curve_vae.client.client import Client
from curve_vae.client.inputs import CurvesLike, as_batch


class AugmentDataset(IterableDataset):
    """`count` curves between `seeds`, `batch` at a time, from the server at `url` (see the module docstring)."""

    def __init__(
        self,
        url: str,
        seeds: CurvesLike,
        count: int,
        *,
        seed: int,
        batch: int = 256,
        client: dict[str, Any] | None = None,
        **fields: Any,
    ) -> None:
        super().__init__()
        self.url, self.count, self.seed, self.batch = url, count, seed, batch
        # one curve is refused here, in the process that made the dataset, not later in each worker
        self.seeds = [np.asarray(c, np.float64) for c in as_batch(seeds, "AugmentDataset", at_least=2)]
        self.client_options = client or {}
        self.fields = fields  # /augment's other fields: mode, neighbours, n_points, pose, spacing, …
        self.epoch = 0

    def set_epoch(self, epoch: int) -> None:
        self.epoch = epoch

    def epoch_seed(self) -> int:
        if self.epoch == 0:
            return self.seed
        return int(np.random.SeedSequence([self.seed, self.epoch]).generate_state(1, np.uint64)[0] >> np.uint64(11))

    def __len__(self) -> int:
        return -(-self.count // self.batch)

    def __iter__(self) -> Iterator[torch.Tensor]:
        info = get_worker_info()
        worker, workers = (info.id, info.num_workers) if info is not None else (0, 1)
        seed = self.epoch_seed()
        with Client(self.url, **self.client_options) as c:
            for j in range(worker, len(self), workers):
                start = j * self.batch
                n = min(self.batch, self.count - start)
                (chunk,) = c.augment_chunks(self.seeds, n, seed=seed, offset=start, chunk=n, **self.fields)
                yield torch.from_numpy(np.ascontiguousarray(chunk.stacked(), np.float32))
