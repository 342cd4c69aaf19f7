"""Looking again: the encoder as the decoder's inverse, a few fixed-point steps after a curve is read.

    x (what the encoder read) --E--> z0;  z ← z + (E(x) − E(D(z)))   one encoder and one decoder pass a step

Where E(D(z)) = E(x), the decoding reads back as the input does; the model's encoder is a good inverse of its decoder
near the data, so each step moves the decoding towards the input without training and without a Jacobian (`refine`,
Levenberg–Marquardt, is the closer fit for several times the cost). A step is kept only for the curves it brings
closer (the distance the reader compares candidates by: each caller point to its closest point on the decoded spline,
or the decoded points to the encoder's, in the model plane); a curve a step did not bring closer stops there, since
the same step from the same latent would be taken again. All curves of a request step together, one batch a pass.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from curve_vae.inference.model.graphs import ModelGraphs
from curve_vae.inference.prepared import ReadCurve

#: Decodes rows (with their caller curves) and says how far each decoding lies from its input: Reader._decoded.
Decoder = Callable[[list[np.ndarray], list[ReadCurve]], tuple[list[ReadCurve], np.ndarray]]


def look_again(
    graphs: ModelGraphs,
    inputs: list[np.ndarray],
    rows: list[ReadCurve],
    err: np.ndarray,
    steps: int,
    decoded: Decoder,
) -> tuple[list[ReadCurve], np.ndarray]:
    """`steps` fixed-point steps on decoded rows (`err`: each one's distance from its input); the rows and distances
    after them, each row's latent moved only where a step brought its decoding closer. The log-variance stays the
    encoder's of what it read."""
    rows, err = list(rows), np.asarray(err, np.float64).copy()
    anchor = np.stack([r.mean for r in rows]).astype(np.float64) if rows else np.zeros((0, graphs.latent_dim))
    active = np.arange(len(rows))
    for _ in range(steps):
        if not len(active):
            break
        with np.errstate(all="ignore"):
            back, _ = graphs.encode(np.stack([_decoded(rows[i]) for i in active]))
            z = np.stack([rows[i].mean for i in active]).astype(np.float64) + anchor[active] - back
        moved = [rows[i].moved_to(z[k].astype(np.float32)) for k, i in enumerate(active)]
        tried, tried_err = decoded([inputs[i] for i in active], moved)
        closer = tried_err < err[active]
        for k in np.flatnonzero(closer):
            rows[active[k]] = tried[k]
            err[active[k]] = tried_err[k]
        active = active[closer]
    return rows, err


def _decoded(row: ReadCurve) -> np.ndarray:
    assert row.decoded is not None, "a row looks again once it is decoded"
    return row.decoded
