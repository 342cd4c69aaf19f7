"""Open (clamped) uniform cubic B-splines: random control points, sampling, least-squares fit.

The data set of the paper (§3.1) is built from these: 10 control points, one per random
angular sector of a radius-64 circle centred in the 128×128 plane, sampled at 161 points
uniformly in the curve parameter. scipy evaluates the basis; batches are a matrix product.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.interpolate import BSpline, make_lsq_spline

from curve_vae.errors import InvalidInput
from curve_vae.geometry.frame import cumulative_length
from curve_vae.geometry.metrics import diagonal


def clamped_uniform_knots(n_ctrl: int, degree: int = 3) -> np.ndarray:
    """Knot vector on [0, 1] of an open uniform B-spline: end knots repeated degree+1 times."""
    if n_ctrl <= degree:
        raise InvalidInput(f"need more than {degree} control points for degree {degree}, got {n_ctrl}")
    interior = np.linspace(0.0, 1.0, n_ctrl - degree + 1)[1:-1]
    return np.concatenate([np.zeros(degree + 1), interior, np.ones(degree + 1)])


def random_control_points(
    rng: np.random.Generator,
    count: int,
    *,
    n_ctrl: int = 10,
    radius: float = 64.0,
    center: tuple[float, float] = (64.0, 64.0),
) -> np.ndarray:
    """(count, n_ctrl, 2) control points, one per non-uniform angular sector of a circle.

    Sector boundaries start at angle 0 and are n_ctrl-1 sorted uniform angles in (0, 2π);
    inside its sector each point has a uniform angle and a radius uniform over the area
    (radius·√u), so points are spread over the disc rather than crowded at its centre.
    """
    cuts = np.sort(rng.uniform(0.0, 2 * np.pi, size=(count, n_ctrl - 1)), axis=1)
    bounds = np.concatenate([np.zeros((count, 1)), cuts, np.full((count, 1), 2 * np.pi)], axis=1)
    lo, hi = bounds[:, :-1], bounds[:, 1:]
    theta = lo + (hi - lo) * rng.uniform(size=(count, n_ctrl))
    r = radius * np.sqrt(rng.uniform(size=(count, n_ctrl)))
    pts = np.stack([center[0] + r * np.cos(theta), center[1] + r * np.sin(theta)], axis=-1)
    return pts


def sample_bspline(ctrl: np.ndarray, n_points: int = 161, degree: int = 3) -> np.ndarray:
    """Sample clamped uniform B-splines at n_points parameters evenly spaced in [0, 1].

    ctrl: (n_ctrl, 2) or (batch, n_ctrl, 2). Returns (n_points, 2) or (batch, n_points, 2).
    """
    ctrl = np.asarray(ctrl, dtype=np.float64)
    return _basis_times(_even_basis(ctrl.shape[-2], n_points, degree), ctrl)


def _basis_times(basis: np.ndarray, ctrl: np.ndarray) -> np.ndarray:
    """basis (p, n_ctrl) times each spline's control points (…, n_ctrl, d): (…, p, d), as one matrix product over
    all the splines at once (a batch of 256 at 257 points: 0.4 ms, against 17 ms as an einsum)."""
    lead, (n_ctrl, dim) = ctrl.shape[:-2], ctrl.shape[-2:]
    flat = np.moveaxis(ctrl.reshape(-1, n_ctrl, dim), 1, 0).reshape(n_ctrl, -1)  # (n_ctrl, B·d)
    out = (basis @ flat).reshape(len(basis), -1, dim)  # (p, B, d)
    return np.ascontiguousarray(np.moveaxis(out, 0, 1)).reshape(*lead, len(basis), dim)


@lru_cache(maxsize=64)
def _even_basis(n_ctrl: int, n_points: int, degree: int) -> np.ndarray:
    """(n_points, n_ctrl) basis at evenly spaced parameters: the same for every curve, so built once (read-only)."""
    u = np.linspace(0.0, 1.0, n_points)
    basis = BSpline.design_matrix(u, clamped_uniform_knots(n_ctrl, degree), degree).toarray()
    basis.setflags(write=False)
    return basis


def spline_head(n_ctrl: int, n_points: int, degree: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """The fixed linear B-spline output head: basis (n_points, n_ctrl) and its pseudo-inverse (n_ctrl, n_points).

    Point i of a curve sits at parameter i/(n_points-1) of a clamped uniform B-spline with
    n_ctrl control points. `pinv @ curve` are the least-squares control points and
    `basis @ pinv` the orthogonal projector onto the splines: it leaves every curve of the
    space unchanged and can only shorten the distance to one, so it never adds error on
    such curves. With n_ctrl = 7k + 3 the knots contain those of the paper's 10-point data
    (every 1/7), so data curves lie in the space exactly.
    """
    basis = BSpline.design_matrix(np.linspace(0.0, 1.0, n_points), clamped_uniform_knots(n_ctrl, degree), degree)
    dense = basis.toarray()
    return dense, np.linalg.pinv(dense)


def evaluate_bspline(control_points: np.ndarray, params: np.ndarray, degree: int = 3) -> np.ndarray:
    """Points (…, len(params), 2) of clamped uniform B-splines (…, n_ctrl, 2) at parameters in [0, 1]."""
    ctrl = np.asarray(control_points, dtype=np.float64)
    u = np.clip(np.asarray(params, dtype=np.float64), 0.0, 1.0)
    basis = BSpline.design_matrix(u, clamped_uniform_knots(ctrl.shape[-2], degree), degree).toarray()
    return _basis_times(basis, ctrl)


def spline_values(
    control_points: np.ndarray, params: np.ndarray, owner: np.ndarray | None = None, *, degree: int = 3, order: int = 0
) -> list[np.ndarray]:
    """Points of clamped uniform B-splines (B, n_ctrl, 2) at parameters (N,) in [0, 1], point k on spline `owner[k]`
    (default: every point on the first), and their first `order` derivatives in u: [(N, 2), …], order + 1 arrays.

    A batch of curves of any lengths in a few array operations, whatever the batch: on each knot span a spline is a
    polynomial of its place x in the span (`_span_polynomials`' basis times the span's degree + 1 control points),
    so each spline's span polynomials are made once, B × spans of them, and each parameter gathers its own and
    evaluates it by Horner's rule (3× faster than gathering the basis and the control points per parameter: 6.1
    against 18.3 ms for 41,000 parameters and two derivatives).
    """
    c = np.asarray(control_points, np.float64)
    u = np.clip(np.asarray(params, np.float64), 0.0, 1.0)
    who = np.zeros(len(u), np.int64) if owner is None else np.asarray(owner, np.int64)
    poly = span_polynomials_of(c.reshape(-1, c.shape[-2], 2), degree)
    spans = poly.shape[1]
    span = np.minimum((u * spans).astype(np.int64), spans - 1)
    x = (u * spans - span)[:, None]  # place in the span, [0, 1]
    mine = np.ascontiguousarray(poly).reshape(-1, degree + 1, 2)[who * spans + span]  # (N, powers, 2): its own
    out = []
    for d in range(order + 1):
        # the d-th derivative of x^k is k!/(k - d)!·x^(k - d); in u, times spans^d
        acc = mine[:, degree] * _FALLING[d, degree]
        for k in range(degree - 1, d - 1, -1):
            acc = acc * x + mine[:, k] * _FALLING[d, k]
        out.append(acc * float(spans) ** d if d else acc)
    # a clamped spline passes through its end control points: there exactly (a loop's two ends stay one point)
    at_end = np.flatnonzero((u <= 0.0) | (u >= 1.0))
    n_ctrl = c.shape[-2]
    out[0][at_end] = c.reshape(-1, 2)[who[at_end] * n_ctrl + np.where(u[at_end] >= 1.0, n_ctrl - 1, 0)]
    return out


def span_polynomials_of(control_points: np.ndarray, degree: int = 3) -> np.ndarray:
    """(B, spans, degree + 1 powers, 2): on knot span s of each clamped uniform B-spline (B, n_ctrl, 2), the curve as
    Σ_k poly[b, s, k]·x^k, x ∈ [0, 1] the place in the span (`_span_polynomials`' basis times the span's control
    points), per span one matrix product over all the splines."""
    c = np.asarray(control_points, np.float64)
    coef = _span_polynomials(c.shape[-2], degree)  # (spans, degree + 1 functions, degree + 1 powers)
    spans = len(coef)
    window = np.arange(spans)[:, None] + np.arange(degree + 1)  # span s: control points s … s + degree
    near = c[:, window]  # (B, spans, functions, 2)
    # (spans, powers, functions) @ (spans, functions, B·2)
    poly = coef.transpose(0, 2, 1) @ near.transpose(1, 2, 0, 3).reshape(spans, degree + 1, -1)
    return np.ascontiguousarray(poly.reshape(spans, degree + 1, -1, 2).transpose(2, 0, 1, 3))


#: k!/(k - d)! for d (rows) and k (columns) up to degree 7: the factor of x^(k - d) in the d-th derivative of x^k
_FALLING = np.array([[np.prod(np.arange(k - d + 1, k + 1)) if k >= d else 0.0 for k in range(8)] for d in range(8)])


@lru_cache(maxsize=16)
def _span_polynomials(n_ctrl: int, degree: int) -> np.ndarray:
    """(spans, degree + 1, degree + 1): on knot span s of a clamped uniform B-spline, basis function s + j is
    Σ_k coef[s, j, k]·x^k, x ∈ [0, 1] the place in the span — solved from the basis at degree + 1 places (exact up to
    rounding: the functions are polynomials of that degree there). Read-only."""
    knots = clamped_uniform_knots(n_ctrl, degree)
    spans = n_ctrl - degree
    x = np.linspace(0.0, 1.0, degree + 1)
    vander = np.vander(x, degree + 1, increasing=True)  # (places, powers)
    coef = np.empty((spans, degree + 1, degree + 1))
    for s in range(spans):
        u = np.clip((s + x) / spans, 0.0, 1.0)
        basis = BSpline.design_matrix(u, knots, degree).toarray()[:, s : s + degree + 1]  # (places, functions)
        coef[s] = np.linalg.solve(vander, basis).T
    coef.setflags(write=False)
    return coef


def arc_length_params(control_points: np.ndarray, n_points: int, *, degree: int = 3, dense: int = 4096) -> np.ndarray:
    """n_points parameters in [0, 1] of a clamped uniform B-spline (n_ctrl, 2), evenly spaced in its arc length."""
    return params_at_arc_fractions(control_points, np.linspace(0.0, 1.0, n_points), degree=degree, dense=dense)


def params_at_arc_fractions(
    control_points: np.ndarray, fractions: np.ndarray, *, degree: int = 3, dense: int = 4096
) -> np.ndarray:
    """The parameters (n,) of a clamped uniform B-spline (n_ctrl, 2) at `fractions` (n,) of its arc length.

    The length is that of the spline sampled at `dense` parameters; the parameters in between are
    interpolated linearly, which places points within ~1e-6 of the curve's length of where they belong.
    """
    at = np.clip(np.asarray(fractions, np.float64), 0.0, 1.0)
    u = np.linspace(0.0, 1.0, dense)
    pts = sample_bspline(control_points, dense, degree)
    s = cumulative_length(pts)
    if not s[-1] > 1e-9 * (1.0 + np.abs(pts).max()):
        return at  # a spline collapsed to a point (up to rounding): any spacing is even
    keep = np.concatenate([[True], np.diff(s) > 0])
    return np.interp(at * s[-1], s[keep], u[keep])


def closest_params(
    control_points: np.ndarray,
    points: np.ndarray,
    around: np.ndarray,
    *,
    window: float = 0.05,
    degree: int = 3,
    dense: int = 513,
) -> np.ndarray:
    """Parameter (n,) of the point of a clamped uniform B-spline (n_ctrl, 2) closest to each of `points` (n, 2),
    searched within `window` of its parameter `around` (n,): the foot points of curve fitting, kept near a first
    guess so that a point is never matched to another branch of a curve that comes back near itself.

    The nearest of `dense` samples in the window, then three Newton steps on the squared distance (clipped to the
    window and to [0, 1], each kept only where it brings the point closer).
    """
    ctrl = np.asarray(control_points, np.float64)
    pts = np.asarray(points, np.float64)
    a = np.clip(np.asarray(around, np.float64), 0.0, 1.0)
    grid = np.linspace(0.0, 1.0, dense)
    samples = sample_bspline(ctrl, dense, degree)
    width = int(np.ceil(2 * window * (dense - 1))) + 2  # samples a window can hold
    if width >= dense:  # the window spans the curve: every sample
        d2 = ((pts[:, None, :] - samples[None]) ** 2).sum(-1)  # (n, dense)
        d2[np.abs(grid[None, :] - a[:, None]) > window] = np.inf
        u = grid[d2.argmin(axis=1)]
    else:  # only the samples of each point's window: (n, width), those beyond it at infinity
        first = np.clip(np.ceil((a - window) * (dense - 1) - 1e-9).astype(int), 0, dense - 1)
        idx = np.minimum(first[:, None] + np.arange(width)[None, :], dense - 1)
        d2 = ((pts[:, None, :] - samples[idx]) ** 2).sum(-1)
        d2[np.abs(grid[idx] - a[:, None]) > window] = np.inf
        u = grid[idx[np.arange(len(pts)), d2.argmin(axis=1)]]
    lo, hi = np.clip(a - window, 0.0, 1.0), np.clip(a + window, 0.0, 1.0)
    spline = BSpline(clamped_uniform_knots(len(ctrl), degree), ctrl, degree)
    d1, d2s = spline.derivative(1), spline.derivative(2)
    for _ in range(3):
        r, t, c = spline(u) - pts, d1(u), d2s(u)
        grad, curv = (r * t).sum(-1), (t * t).sum(-1) + (r * c).sum(-1)
        step = np.where(curv > 0, grad / np.where(curv > 0, curv, 1.0), 0.0)
        moved = np.clip(u - step, lo, hi)
        closer = ((spline(moved) - pts) ** 2).sum(-1) < (r**2).sum(-1)  # a step never takes a point further
        u = np.where(closer, moved, u)
    return u


@lru_cache(maxsize=16)
def _basis_splines(n_ctrl: int, degree: int) -> tuple[BSpline, BSpline]:
    """The basis functions of a clamped uniform B-spline as one spline with identity coefficients, and its
    derivative: evaluated at u they give the basis matrix and its slope (twice as fast as a design matrix)."""
    basis = BSpline(clamped_uniform_knots(n_ctrl, degree), np.eye(n_ctrl), degree)
    return basis, basis.derivative()


def basis_and_slope(u: np.ndarray, n_ctrl: int, degree: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Basis (m, n_ctrl) of a clamped uniform B-spline at parameters u (m,), clipped to [0, 1], and its derivative
    in u."""
    basis, slope = _basis_splines(n_ctrl, degree)
    u = np.clip(u, 0.0, 1.0)
    return basis(u), slope(u)


@dataclass(frozen=True)
class BSplineFit:
    """A least-squares B-spline: control points, knots and how far the curve is from it."""

    control_points: np.ndarray  # (n_ctrl, 2)
    knots: np.ndarray  # (n_ctrl + degree + 1,)
    degree: int
    params: np.ndarray  # (n_points,) parameter of each input point
    rms_error: float  # root mean squared distance, input points to fitted curve at params
    max_error: float

    def evaluate(self, n_points: int) -> np.ndarray:
        """(n_points, 2) points of the fitted spline, evenly spaced in its parameter."""
        return BSpline(self.knots, self.control_points, self.degree)(np.linspace(0, 1, n_points))


def _lsq(u: np.ndarray, pts: np.ndarray, knots: np.ndarray, degree: int) -> BSpline:
    n_ctrl = len(knots) - degree - 1
    try:
        spline = make_lsq_spline(u, pts, knots, k=degree)
    except (ValueError, np.linalg.LinAlgError) as e:
        raise InvalidInput(f"cannot fit {n_ctrl} control points to these points: {e}") from e
    if not np.isfinite(spline.c).all():
        # Schoenberg-Whitney fails: some knot span holds too few points (bunched points).
        raise InvalidInput(
            f"cannot fit {n_ctrl} control points: the points bunch up along the curve, leaving "
            "a knot span empty; use fewer control points or resample the curve"
        )
    return spline


def fit_bspline(
    points: np.ndarray, n_ctrl: int = 10, *, degree: int = 3, param: str = "uniform", refine: int | None = None
) -> BSplineFit:
    """Least-squares clamped uniform B-spline through a polyline.

    param: "uniform" gives point i the parameter i/(n-1), which recovers a B-spline exactly
    from its own evenly-parameterised samples (the paper's data); "chord" uses cumulative
    chord length, better for curves drawn or resampled by arc length.
    refine: rounds of parameter correction — each point's parameter moves towards its foot
    point on the fitted curve, then the spline is refitted (Hoschek 1988). Default 20 for
    "chord" (on the data set's curves the median RMS error drops from 1.84 to 0.62 px), 0
    for "uniform".
    """
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise InvalidInput(f"points must have shape (n, 2), got {pts.shape}")
    if len(pts) < n_ctrl:
        raise InvalidInput(f"need at least n_ctrl={n_ctrl} points to fit, got {len(pts)}")
    if param == "uniform":
        u = np.linspace(0.0, 1.0, len(pts))
    elif param == "chord":
        cum = cumulative_length(pts)
        if cum[-1] <= 0:
            raise InvalidInput("all points coincide: a curve needs at least 2 distinct points")
        u = cum / cum[-1]  # ends exactly at 1 (dividing by a separately summed total may not)
    else:
        raise InvalidInput(f"param must be 'uniform' or 'chord', got {param!r}")
    knots = clamped_uniform_knots(n_ctrl, degree)
    spline = _lsq(u, pts, knots, degree)
    for _ in range(refine if refine is not None else (20 if param == "chord" else 0)):
        d, d1 = spline(u) - pts, spline(u, 1)
        step = np.sum(d * d1, axis=1) / np.maximum(np.sum(d1 * d1, axis=1), 1e-12)  # Gauss-Newton
        u = np.maximum.accumulate(np.clip(u - np.clip(step, -0.02, 0.02), 0.0, 1.0))
        u[0], u[-1] = 0.0, 1.0
        spline = _lsq(u, pts, knots, degree)
    err = np.linalg.norm(spline(u) - pts, axis=1)
    return BSplineFit(
        control_points=np.asarray(spline.c),
        knots=knots,
        degree=degree,
        params=u,
        rms_error=float(np.sqrt(np.mean(err**2))),
        max_error=float(err.max()),
    )


#: Control-point counts `fit_bspline_auto` tries, in order: dense where few points matter, sparser above.
AUTO_CTRL = (4, 5, 6, 7, 8, 10, 12, 14, 17, 20, 24, 28, 32, 40, 48, 56, 64)


def fit_bspline_auto(
    points: np.ndarray, *, tolerance: float = 1e-3, param: str = "chord", max_ctrl: int = 64
) -> BSplineFit:
    """The fit with the fewest control points (from 4 up) whose RMS error is within `tolerance` × the curve's
    bounding-box diagonal; the most accurate one tried when none is (at most min(points, max_ctrl) control points).
    """
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 4:
        raise InvalidInput(f"points must have shape (n ≥ 4, 2), got {pts.shape}")
    goal = tolerance * float(diagonal(pts))
    limit = min(len(pts), max_ctrl)
    best: BSplineFit | None = None
    for n in [*(k for k in AUTO_CTRL if k < limit), limit]:
        try:
            fit = fit_bspline(pts, n, param=param)
        except ValueError:
            continue  # too many control points for how the points bunch up: try the next count
        if best is None or fit.rms_error < best.rms_error:
            best = fit
        if fit.rms_error <= goal:
            return fit
    if best is None:
        raise InvalidInput("no B-spline fits these points with 4 or more control points")
    return best
