"""A learned part's weights file beside a model's graphs (ranker.npz, spacer.npz): numpy arrays and the `kind` of
network they belong to, checked before anything is read as weights."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from curve_vae.errors import InvalidInput


def read_weights(path: str | Path, kind: str, what: str) -> dict[str, np.ndarray]:
    """The arrays of an .npz of weights whose `kind` is `kind` (else InvalidInput naming both; `what` names the
    part, "a reading ranker"), without the kind itself."""
    with np.load(path) as d:
        found = str(d["kind"]) if "kind" in d else ""
        if found != kind:
            raise InvalidInput(f"{path}: {what} of kind {found!r}; this runtime reads {kind!r}")
        return {k: d[k] for k in d.files if k != "kind"}
