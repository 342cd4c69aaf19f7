"""New curves from the model's latent distribution (paper §4's generation; `/sample`).

`Sampling` gives `CurveRuntime` its `sample` and `plausible` methods (it needs `decode_model_splines`, `_place`,
the prior, the latent size and the data's disc); `fresh_seed` draws a seed for a request that gave none.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from curve_vae.geometry import Frame, self_intersects
from curve_vae.inference.errors import InputError
from curve_vae.inference.prior import LatentPrior

if TYPE_CHECKING:
    from curve_vae.inference.runtime import Spacing, Spline

Prior = Literal["learned", "standard"]
MAX_DRAWS = 10  # per sampled curve: the shipped prior rejects 25% of draws, so 10 fail with probability ~1e-6;
# and a distribution that rejects almost everything (the standard prior) costs at most 10 decodes a curve


@dataclass(frozen=True)
class Sampled:
    """What `CurveRuntime.sample` made: latents (count, Z), curves, the prior used and the bookkeeping of rejection."""

    latents: np.ndarray
    curves: np.ndarray
    prior: str
    rejected: int  # draws rejected (self-intersecting or outside the disc) and drawn again
    invalid: int  # curves still not valid after max_draws (0 unless the distribution is far off)


class Sampling:
    """The sampling methods of CurveRuntime."""

    prior: LatentPrior | None
    latent_dim: int
    n_points: int
    knots: np.ndarray | None
    spline_degree: int
    disc_center: np.ndarray
    disc_radius: float
    has_splines: Any
    decode_model_splines: Any
    has_params: Any
    _place: Any

    def sample(
        self,
        count: int,
        *,
        seed: int | None = None,
        temperature: float = 1.0,
        prior: Prior | None = None,
        valid: bool = True,
        max_draws: int = MAX_DRAWS,
        n_points: int | None = None,
        spacing: Spacing = "parameter",
        frame: Frame | None = None,
        splines: list[Spline] | None = None,
    ) -> Sampled:
        """New curves from a latent distribution, decoded into the model plane (or mapped into `frame`).

        prior "learned": the Gaussian mixture fitted to the training curves' latent means (the default where the
        model ships one); "standard": the VAE's N(0, I). temperature scales the spread (see inference/prior.py).
        valid: a draw whose curve crosses itself or leaves the data's disc is rejected and item i draws again, at
        most max_draws times in all. Item i's draws come from its own generator default_rng([seed, i]), so the
        seed decides every curve, across rejections too, and the first items of a larger count are the items of
        a smaller one.
        """
        chosen = prior or ("learned" if self.prior is not None else "standard")
        if chosen == "learned" and self.prior is None:
            raise InputError(
                ("prior",), 'this model ships no learned prior (GET /model: prior is null); use "standard"'
            )
        root = fresh_seed() if seed is None else seed
        rngs = [np.random.default_rng([root, i]) for i in range(count)]

        def draw(i: int) -> np.ndarray:
            if chosen == "learned":
                assert self.prior is not None
                return self.prior.draw(rngs[i], temperature)
            return rngs[i].standard_normal(self.latent_dim) * temperature

        z = np.array([draw(i) for i in range(count)]).reshape(count, self.latent_dim)
        draws, ok, todo = np.ones(count, np.int64), np.zeros(count, bool), np.arange(count)
        out = np.zeros((count, self.n_points, 2), np.float32)
        ctrl = np.zeros((count, len(self.knots) - self.spline_degree - 1, 2), np.float32) if self.has_splines else None
        params = np.zeros((count, self.n_points), np.float32) if self.has_params else None
        while len(todo):  # each draw is decoded once; its curve is kept until the item draws again
            with np.errstate(all="ignore"):
                decoded, points, par = self.decode_model_splines(z[todo])
            out[todo] = decoded
            if ctrl is not None and points is not None:
                ctrl[todo] = points
            if params is not None and par is not None:
                params[todo] = par
            if not valid:
                break
            good = self.plausible(decoded.astype(np.float64))
            ok[todo[good]] = True
            todo = todo[~good & (draws[todo] < max_draws)]
            for i in todo:
                z[i] = draw(int(i))
                draws[i] += 1
        invalid = int((~ok).sum()) if valid else 0
        frames = [frame] * count if frame else None
        curves = self._place(out, ctrl, params, frames=frames, n_points=n_points, spacing=spacing, splines=splines)
        return Sampled(z, curves, chosen, rejected=int(draws.sum() - count), invalid=invalid)

    def plausible(self, curves: np.ndarray) -> np.ndarray:
        """(B, n, 2) model-plane curves -> (B,) bool: finite, free of self-intersections and inside the data's disc."""
        finite = np.isfinite(curves).all(axis=(1, 2))
        inside = np.linalg.norm(np.where(finite[:, None, None], curves, 0) - self.disc_center, axis=-1).max(axis=1)
        ok = finite & (inside <= self.disc_radius)
        if ok.any():
            ok[ok] = ~self_intersects(curves[ok])
        return ok


def fresh_seed() -> int:
    """A random seed for a request that gave none, reported back so the answer can be repeated."""
    return int(np.random.SeedSequence().generate_state(1, np.uint64)[0] >> np.uint64(11))  # 53 bits: exact in JSON
