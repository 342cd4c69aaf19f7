"""A Python client of a curve-vae service: numpy arrays in and out, streamed augmentation, safe retries, datasets.

    from curve_vae.client import Client
    with Client("http://127.0.0.1:8000") as c:
        rec = c.reconstruct(curves)

`Client` / `AsyncClient` (client.py), their results (results.py), `ApiError` (errors.py); a PyTorch dataset
streaming seeded augmentation (dataset.py, with torch installed) and writers of .npy/.npz/Parquet files with a
manifest to make them again (writers.py). Needs httpx and numpy only (the base install has both).
"""

from curve_vae.client.client import AsyncClient, Client, fresh_seed
from curve_vae.client.errors import ApiError, RetriesExhausted
from curve_vae.client.results import (
    Augmented,
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
    "Client",
    "Curves",
    "Encoded",
    "Interpolated",
    "ModelRef",
    "Reconstructed",
    "RetriesExhausted",
    "Sampled",
    "fresh_seed",
]
