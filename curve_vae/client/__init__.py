"""A Python client of a curve-vae service: numpy arrays in and out, streamed augmentation, safe retries, datasets.

    from curve_vae.client import Client
    with Client("http://127.0.0.1:8000") as c:
        rec = c.reconstruct(curves)            # a batch: rec.curves, a list of (n_i, 2) arrays
        one = c.reconstruct(np.c_[x, y])       # one curve: answered as a batch of one, one.curve (n, 2)

`Client` / `AsyncClient` (client.py), what a `curves` argument takes (inputs.py), their results (results.py;
design.py: /fit's and /revolve's), `ApiError` (errors.py); a PyTorch dataset
streaming seeded augmentation (dataset.py, with torch installed) and writers of .npy/.npz/Parquet files with a
manifest to make them again (writers.py). Needs httpx and numpy only (the base install has both).
"""

from curve_vae.client.client import AsyncClient, Client, fresh_seed
from curve_vae.client.design import BSplineFit, Fitted, Revolved
from curve_vae.client.errors import ApiError, RetriesExhausted
from curve_vae.client.results import (
    Augmented,
    Closeness,
    Curves,
    Encoded,
    Interpolated,
    ModelRef,
    Reconstructed,
    Sampled,
)

__all__ = [
    "ApiError",
    "AsyncClient",
    "Augmented",
    "BSplineFit",
    "Client",
    "Closeness",
    "Curves",
    "Encoded",
    "Fitted",
    "Interpolated",
    "ModelRef",
    "Reconstructed",
    "RetriesExhausted",
    "Revolved",
    "Sampled",
    "fresh_seed",
]
