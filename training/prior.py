"""Fit the learned latent distribution (inference/generation/prior.py) to the latent means of training curves, at
export.

A full-covariance Gaussian mixture: 8 components bring the share of self-intersecting samples
from 25% (one Gaussian) to 14% and the samples' nearest-neighbour distances to the real curves'
own (1.00×), in a 4-second fit; 32 gain little more (scripts/prior_components.py, docs/RESULTS.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from curve_vae.errors import InvalidInput
from curve_vae.inference.generation.prior import LatentPrior

if TYPE_CHECKING:
    from curve_vae.inference.generation.named_priors import NamedPrior
    from curve_vae.inference.reading import Reading
    from curve_vae.inference.runtime import CurveRuntime

COMPONENTS = 8  # measured: 1 → 25% self-intersecting samples, 8 → 13.8%, 32 → 11.6%
FIT_CURVES = 20_000  # latent means of this many training curves: enough for 8 × 32-dim full covariances


def fit_prior(latents: np.ndarray, *, components: int = COMPONENTS, seed: int = 0) -> LatentPrior:
    """A Gaussian mixture of `components` full-covariance components fitted to latents (N, Z) by EM."""
    from sklearn.mixture import GaussianMixture

    gm = GaussianMixture(components, covariance_type="full", reg_covar=1e-4, random_state=seed, max_iter=200)
    gm.fit(np.asarray(latents, np.float64))
    return LatentPrior(
        weights=gm.weights_ / gm.weights_.sum(),
        means=gm.means_,
        cholesky=np.linalg.cholesky(gm.covariances_),
    )


#: Most components `curve-vae prior` tries when it chooses their number by BIC.
MAX_COMPONENTS = 10


def fit_by_bic(
    latents: np.ndarray, *, components: int | None = None, max_components: int = MAX_COMPONENTS, seed: int = 0
) -> tuple[LatentPrior, dict[int, float]]:
    """A full-covariance Gaussian mixture of latents (N, Z): `components` of them, or the count from 1 to
    `max_components` (and at most one per 20 latents) with the lowest Bayesian information criterion; the prior and
    the BIC of each count tried."""
    from sklearn.mixture import GaussianMixture

    x = np.asarray(latents, np.float64)
    counts = [components] if components else list(range(1, max(1, min(max_components, len(x) // 20)) + 1))
    fits, bic = {}, {}
    for k in counts:
        gm = GaussianMixture(k, covariance_type="full", reg_covar=1e-4, random_state=seed, max_iter=300).fit(x)
        fits[k], bic[k] = gm, float(gm.bic(x))
    best = fits[min(bic, key=bic.__getitem__)]
    prior = LatentPrior(best.weights_ / best.weights_.sum(), best.means_, np.linalg.cholesky(best.covariances_))
    return prior, bic


#: Manifold Parzen windows (Vincent & Bengio 2003) over a user's curves' latents: one component per curve, its
#: covariance its NEIGHBOURS nearest latents' spread about it, scaled by PARZEN_SCALE² (measured on UIUC airfoils,
#: docs/RESULTS.md: samples as close to held-out airfoils as the training ones, 2% near-copies).
NEIGHBOURS = 5
PARZEN_SCALE = 0.3
#: Fitting steps on each of a user's curves before its latent joins the prior: the decoder's best latent for it.
PRIOR_REFINE = 10


def fit_parzen(latents: np.ndarray, *, neighbours: int = NEIGHBOURS, scale: float = PARZEN_SCALE) -> LatentPrior:
    """A mixture of one Gaussian per latent (N, Z), its covariance the spread of its `neighbours` nearest latents
    about it × scale², plus 1e-6·I: samples stay along the data's own directions."""
    z = np.asarray(latents, np.float64)
    d = ((z[:, None] - z[None]) ** 2).sum(-1)
    np.fill_diagonal(d, np.inf)
    near = np.argsort(d, axis=1)[:, : min(neighbours, len(z) - 1)]
    diffs = z[near] - z[:, None]  # (N, k, Z)
    cov = np.einsum("nki,nkj->nij", diffs, diffs) / near.shape[1] * scale**2 + 1e-6 * np.eye(z.shape[1])
    return LatentPrior(np.full(len(z), 1.0 / len(z)), z, np.linalg.cholesky(cov))


def prior_reading(model: Reading, refine: int) -> Reading:
    """How a prior's curves are read: in the canonical pose whatever the model's own (the search would read one
    airfoil in one pose and its neighbour in another, and their latents would not lie together), at the model's own
    spacing where it has one, else as given; with `refine` fitting steps."""
    from curve_vae.inference.choices import Spacing
    from curve_vae.inference.reading import Reading

    spacing: Spacing = "parameter" if model.spacing == "search" else model.spacing
    return Reading(frame=model.frame, pose="canonical", spacing=spacing, refine=refine)


def fit_named_prior(
    runtime: CurveRuntime,
    curves: list[np.ndarray],
    *,
    name: str,
    kind: str = "parzen",
    components: int | None = None,
    refine: int = PRIOR_REFINE,
    seed: int = 0,
    source: str = "",
) -> NamedPrior:
    """The NamedPrior (inference/generation/named_priors.py) of a user's curves: read as `prior_reading` says, with
    `refine`
    fitting steps, a mixture over their latents — `kind` "parzen" (fit_parzen) or "gmm" (`components`, or chosen by
    BIC) — and the reference statistics its samples are placed and judged by."""
    from curve_vae.geometry import self_intersects
    from curve_vae.geometry.adapt import is_closed, joined_ends
    from curve_vae.geometry.frame import MODEL_CENTER
    from curve_vae.inference.generation.named_priors import NamedPrior, Reference, frames_array, model_identity

    reading = prior_reading(runtime.reading(), refine)
    prep = runtime.prepare(curves, reading)
    latents = prep.mean.astype(np.float64)
    assert all(r.decoded_yet for r in prep.rows), "prepare decodes (decoded=True)"
    decoded = np.stack([r.decoded for r in prep.rows if r.decoded is not None]).astype(np.float64)
    closed = [is_closed(c) for c in prep.inputs]
    reach = float(np.linalg.norm(decoded - np.asarray(MODEL_CENTER), axis=-1).max())
    reference = Reference(
        latents,
        frames_array(prep.frames, closed) if prep.frames[0] is not None else np.zeros((len(latents), 7)),
        reach,
        # a closed curve's reconstruction is returned closed (its ends joined): that loop is what may cross itself
        float(np.mean(self_intersects(np.stack([joined_ends(d) if c else d for d, c in zip(decoded, closed)])))),
        float(np.mean(closed)),
    )
    if kind == "parzen":
        mixture = fit_parzen(latents)
        fit: dict[str, float | dict[str, float]] = {"neighbours": NEIGHBOURS, "scale": PARZEN_SCALE}
        chosen = f"one component per curve (manifold Parzen windows, {NEIGHBOURS} neighbours, scale {PARZEN_SCALE})"
    elif kind == "gmm":
        mixture, bic = fit_by_bic(latents, components=components, seed=seed)
        fit = {"bic": {str(k): v for k, v in bic.items()}}
        chosen = "given" if components else f"BIC over {', '.join(map(str, bic))} components"
    else:
        raise InvalidInput(f"kind must be parzen or gmm, got {kind!r}")
    meta = {
        "kind": kind,
        "reading": {"pose": reading.pose, "spacing": reading.spacing, "refine": reading.refine},
        "components": len(mixture.weights),
        "chosen_by": chosen,
        **fit,
        "source": source,
        "model_name": runtime.manifest.name,
        "model_version": runtime.manifest.version,
    }
    return NamedPrior(name, mixture, reference, model_identity(runtime.manifest), meta)
