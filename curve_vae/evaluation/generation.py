"""How good generated curves are, measured as the field measures them: each metric a small pure function on sets of
curves (N, n, 2) — flattened to (N, 2n) where a metric compares shapes — with its definition and source.

Sources: IDEALLab/bezier-gan (`beziergan/mmd.py`, `consistency.py`, `utils.py`), IDEALLab/CEBGAN_JMD_2021
(`src/utils/metrics.py`), IDEALLab/EngiOpt (`engiopt/evaluation/metrics`), Naeem et al. 2020 ("Reliable fidelity and
diversity metrics for generative models": precision, recall, density, coverage with k nearest neighbours). Where the
sources differ (IDEALLab's "Gaussian" kernel is exp(−‖x−y‖ / 2σ²) on the distance, EngiOpt's exp(−‖x−y‖² / 2σ²)),
both are here under their own names. numpy and scipy; the kernel-density log-likelihood needs scikit-learn.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial.distance import cdist

#: IDEALLab's repeats of a metric and its interval: mean ± 1.96·σ/√n over n runs (utils.mean_err, np.std).
Z95 = 1.96


def flat(curves: np.ndarray) -> np.ndarray:
    """(N, n, 2) -> (N, 2n): a shape as one vector (BézierGAN's X.reshape((N, -1)))."""
    a = np.asarray(curves, np.float64)
    return a.reshape(len(a), -1)


def interval(values: np.ndarray | list[float]) -> tuple[float, float]:
    """(mean, half-width) of repeated measurements: mean ± 1.96·std/√n, std with ddof 0 (BézierGAN utils.mean_err)."""
    v = np.asarray(values, np.float64)
    return float(v.mean()), float(Z95 * v.std() / np.sqrt(len(v)))


# ------------------------------------------------------------------------------------------ distributions


def mmd_ideallab(gen: np.ndarray, ref: np.ndarray, sigma: float = 1.0) -> float:
    """Maximum mean discrepancy as BézierGAN computes it (beziergan/mmd.py): the biased estimate
    mean k(G,G) − 2·mean k(G,R) + mean k(R,R), diagonals included, no square root, with k(x, y) = exp(−‖x−y‖ / 2σ²)
    on the Euclidean distance of the flattened shapes, σ = 1. (CEBGAN reports its square root.)"""
    g, r = flat(gen), flat(ref)
    k = lambda a, b: np.exp(-cdist(a, b) / (2 * sigma**2))  # noqa: E731
    return float(k(g, g).mean() - 2 * k(g, r).mean() + k(r, r).mean())


def median_bandwidth(x: np.ndarray, *, max_samples: int = 500, seed: int = 42) -> float:
    """EngiOpt's median heuristic: σ = sqrt(median squared pairwise distance / 2) over at most 500 samples."""
    a = flat(x)
    if len(a) > max_samples:
        a = a[np.random.default_rng(seed).choice(len(a), max_samples, replace=False)]
    d = cdist(a, a, "sqeuclidean")
    return max(float(np.sqrt(np.median(d[np.triu_indices(len(a), 1)]) / 2)), 1e-6)


def gaussian_kernel(a: np.ndarray, b: np.ndarray, sigma: float) -> np.ndarray:
    """exp(−‖x−y‖² / 2σ²) (EngiOpt)."""
    return np.exp(-cdist(flat(a), flat(b), "sqeuclidean") / (2 * sigma**2))


def mmd_gaussian(gen: np.ndarray, ref: np.ndarray, sigma: float | None = None) -> float:
    """MMD² with a true Gaussian kernel (EngiOpt: biased, no square root); σ by the median heuristic of the reference
    set when not given."""
    s = median_bandwidth(ref) if sigma is None else sigma
    return float(
        gaussian_kernel(gen, gen, s).mean()
        - 2 * gaussian_kernel(gen, ref, s).mean()
        + gaussian_kernel(ref, ref, s).mean()
    )


def mean_log_likelihood(gen: np.ndarray, ref: np.ndarray, *, folds: int = 5) -> float:
    """CEBGAN's mean log-likelihood: a Gaussian kernel density fitted to the generated shapes (flattened), its
    bandwidth chosen by `folds`-fold cross-validation over logspace(−3, 1, 20), scored on the reference shapes:
    total log-likelihood ÷ number of reference shapes."""
    from sklearn.model_selection import GridSearchCV
    from sklearn.neighbors import KernelDensity

    grid = GridSearchCV(KernelDensity(), {"bandwidth": np.logspace(-3, 1, 20)}, cv=folds)
    grid.fit(flat(gen))
    return float(grid.best_estimator_.score(flat(ref)) / len(ref))


# ------------------------------------------------------------------------------------------ fidelity and coverage


def prdc(gen: np.ndarray, ref: np.ndarray, k: int = 5) -> dict[str, float]:
    """Precision, recall, density and coverage with k nearest neighbours (Naeem et al. 2020): each point's ball is
    its distance to its k-th nearest neighbour in its own set. precision: share of generated shapes inside some
    reference ball; recall: share of reference shapes inside some generated ball; density: mean number of reference
    balls a generated shape falls in, ÷ k; coverage: share of reference balls holding a generated shape."""
    g, r = flat(gen), flat(ref)
    r_radius = np.sort(cdist(r, r), axis=1)[:, k]  # column 0 is the point itself
    g_radius = np.sort(cdist(g, g), axis=1)[:, k]
    d = cdist(r, g)  # (R, G)
    inside = d <= r_radius[:, None]
    return {
        "precision": float(inside.any(axis=0).mean()),
        "recall": float((d <= g_radius[None, :]).any(axis=1).mean()),
        "density": float(inside.sum(axis=0).mean() / k),
        "coverage": float((d.min(axis=1) <= r_radius).mean()),
    }


#: EngiOpt's coverage radius: this quantile of the reference set's own nearest-neighbour distances.
COVERAGE_QUANTILE = 0.05


def coverage_radius(ref: np.ndarray) -> float:
    """The 95th percentile of the reference shapes' distances to their nearest other reference shape (EngiOpt)."""
    r = flat(ref)
    d = cdist(r, r)
    np.fill_diagonal(d, np.inf)
    return float(np.quantile(d.min(axis=1), 1.0 - COVERAGE_QUANTILE))


def coverage(gen: np.ndarray, ref: np.ndarray) -> float:
    """Share of reference shapes with a generated shape within `coverage_radius` of them (EngiOpt)."""
    return float((cdist(flat(ref), flat(gen)).min(axis=1) <= coverage_radius(ref)).mean())


def nearest_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(len(a),) each shape of `a`'s distance to its nearest shape of `b` (flattened, Euclidean)."""
    return cdist(flat(a), flat(b)).min(axis=1)


def novelty(gen: np.ndarray, train: np.ndarray) -> float:
    """Mean distance from each generated shape to its nearest training shape (EngiOpt baselines `novelty`)."""
    return float(nearest_distance(gen, train).mean())


#: A generated shape closer to a training shape than this quantile of the training shapes' own nearest-neighbour
#: distances is a copy (no source sets a threshold; this one says "as close as the closest 5% of training pairs").
COPY_QUANTILE = 0.05


def copy_rate(gen: np.ndarray, train: np.ndarray, *, max_probes: int = 2000, seed: int = 0) -> float:
    """Share of generated shapes within the 5th percentile of the training set's own nearest-neighbour distances of
    some training shape: near-duplicates of the data. The percentile is estimated from at most `max_probes` training
    shapes (seeded), each against all the others."""
    t = flat(train)
    probes = np.arange(len(t))
    if len(t) > max_probes:
        probes = np.sort(np.random.default_rng(seed).choice(len(t), max_probes, replace=False))
    d = cdist(t[probes], t)
    d[np.arange(len(probes)), probes] = np.inf
    threshold = float(np.quantile(d.min(axis=1), COPY_QUANTILE))
    return float((nearest_distance(gen, train) <= threshold).mean())


# ------------------------------------------------------------------------------------------ diversity and smoothness


def diversity_ratio(gen: np.ndarray, train: np.ndarray) -> float:
    """CEBGAN's relative diversity: trace(cov(generated)) ÷ trace(cov(training)), the flattened shapes' covariance
    (each trace ÷ its dimension, as CEBGAN writes it: the same dimension on both sides)."""
    return float(np.trace(np.cov(flat(gen).T)) / np.trace(np.cov(flat(train).T)))


def vendi(gen: np.ndarray, sigma: float | None = None) -> float:
    """The Vendi score (EngiOpt): exp(entropy of the eigenvalues of K/n), K the Gaussian kernel matrix; between 1
    (all alike) and n (all different). σ: the median heuristic of `gen` when not given."""
    s = median_bandwidth(gen) if sigma is None else sigma
    lam = np.linalg.eigvalsh(gaussian_kernel(gen, gen, s) / len(gen))
    lam = lam[lam > 1e-12]
    return float(np.exp(-(lam * np.log(lam)).sum()))


def dpp_diversity(gen: np.ndarray, sigma: float | None = None) -> float:
    """EngiOpt's DPP diversity as a geometric mean: exp(log det(K + 1e-6·I) / n), in (0, 1]; 1 for shapes all far
    apart."""
    s = median_bandwidth(gen) if sigma is None else sigma
    k = gaussian_kernel(gen, gen, s) + 1e-6 * np.eye(len(gen))
    sign, logdet = np.linalg.slogdet(k)
    return float(np.exp(logdet / len(gen))) if sign > 0 else 0.0


def variation(curves: np.ndarray) -> float:
    """CEBGAN's variation of a set: per shape, the trace of the covariance of its consecutive point differences ÷ 2,
    averaged over the shapes."""
    out = 0.0
    for c in np.asarray(curves, np.float64):
        out += np.trace(np.cov(np.diff(c, axis=0).T)) / 2
    return out / len(curves)


def rvod(gen: np.ndarray, ref: np.ndarray) -> float:
    """CEBGAN's smoothness ratio RVOD: variation(reference) ÷ variation(generated); 1 is as smooth as the data."""
    return float(variation(ref) / variation(gen))


# ------------------------------------------------------------------------------------------ the latent space


def lsc(
    decode: Callable[[np.ndarray], np.ndarray],
    bounds: tuple[np.ndarray, np.ndarray],
    rng: np.random.Generator,
    *,
    lines: int = 100,
    points: int = 50,
) -> float:
    """BézierGAN's latent space consistency (beziergan/consistency.py): along `lines` random axis-parallel lines of
    the latent box `bounds` (each through a uniform point, `points` steps across the whole range of one random
    axis), the Pearson correlation between the latents' distances from the line's first point and their decoded
    shapes' distances from its shape; averaged over the lines. 1: moving further in the latent space always moves
    the shape further."""
    lo, hi = (np.asarray(b, np.float64) for b in bounds)
    dim = len(lo)
    total = 0.0
    for _ in range(lines):
        axis = int(rng.integers(dim))
        c = np.tile(rng.random(dim), (points, 1))
        c[:, axis] = np.linspace(0.0, 1.0, points)
        z = lo + (hi - lo) * c
        x = flat(decode(z))
        dz, dx = np.linalg.norm(z - z[0], axis=1), np.linalg.norm(x - x[0], axis=1)
        total += float(np.corrcoef(dz, dx)[0, 1])
    return total / lines
