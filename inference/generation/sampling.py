"""New curves from a latent distribution (paper §4's generation; `/sample`).

`Sampler.draw` draws latents from a prior (the learned mixture shipped with the model, or N(0, I)) and decodes
them in the model plane, rejecting and redrawing curves that cross themselves or leave the region the reference
curves live in; `Sampler.sample` maps the result to the caller (`CurveRuntime.sample`). `fresh_seed` draws a seed
for a request that gave none.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from curve_vae.geometry import Frame, sample_bspline, self_intersects
from curve_vae.geometry.adapt import joined_ends
from curve_vae.inference.errors import InputError
from curve_vae.inference.generation.named_priors import NamedPrior
from curve_vae.inference.generation.prior import LatentPrior
from curve_vae.inference.model.graphs import ModelGraphs
from curve_vae.inference.placing import closed_rows, decoded_to_caller
from curve_vae.inference.results import Sampled

MAX_DRAWS = 10  # per sampled curve: the shipped prior rejects 25% of draws, so 10 fail with probability ~1e-6;
# and a distribution that rejects almost everything (the standard prior) costs at most 10 decodes a curve


@dataclass(frozen=True)
class Drawn:
    """What `Sampler.draw` made, in the model plane."""

    latents: np.ndarray  # (count, latent_dim)
    decoded: np.ndarray  # (count, n_points, 2)
    ctrl: np.ndarray | None
    params: np.ndarray | None
    prior: str
    rejected: int  # draws rejected and drawn again
    invalid: int  # curves still not valid after max_draws


class Sampler:
    """Draws from a model's latent priors through its decoder; valid curves stay inside a disc of the model plane
    (the paper's curves: their control points' radius-64 disc about the centre) and never cross themselves."""

    def __init__(
        self,
        graphs: ModelGraphs,
        prior: LatentPrior | None,
        disc_center: np.ndarray,
        disc_radius: float,
        named: dict[str, NamedPrior] | None = None,
    ):
        self.graphs = graphs
        self.prior = prior
        self.named = named or {}  # priors fitted to users' curves (inference.generation.named_priors), by name
        self.disc_center = np.asarray(disc_center, np.float64)
        self.disc_radius = float(disc_radius)

    @property
    def names(self) -> list[str]:
        """The priors a request may name: learned where the model ships it, standard, and the loaded ones."""
        return [*(["learned"] if self.prior is not None else []), "standard", *self.named]

    def draw(
        self,
        count: int,
        *,
        seed: int,
        temperature: float = 1.0,
        prior: str | None = None,
        valid: bool = True,
        max_draws: int = MAX_DRAWS,
        offset: int = 0,
    ) -> Drawn:
        """`count` curves decoded from latents of a distribution.

        prior "learned": the Gaussian mixture fitted to the training curves' latent means (the default where the
        model ships one); "standard": the VAE's N(0, I); any other: a prior fitted to a user's curves
        (inference.generation.named_priors), its validity judged against its own reference curves. temperature scales
        the spread
        (see inference/generation/prior.py). valid: a draw whose curve crosses itself or leaves the region of the data
        is
        rejected and item i draws again, at most max_draws times in all. Item i's draws come from its own generator
        default_rng([seed, i]), so the seed decides every curve, across rejections too; `offset` starts the
        sequence at item offset, so pages of it are the curves of one larger request.
        """
        g = self.graphs
        chosen = self.resolve(prior)
        rngs = [np.random.default_rng([seed, i]) for i in range(offset, offset + count)]
        named = self.named.get(chosen)
        learned = named.mixture if named is not None else self.prior
        plausible = named.plausible if named is not None else self.plausible

        def one(i: int) -> np.ndarray:
            if chosen != "standard":
                assert learned is not None
                return learned.draw(rngs[i], temperature)
            return rngs[i].standard_normal(g.latent_dim) * temperature

        z = np.array([one(i) for i in range(count)]).reshape(count, g.latent_dim)
        draws, ok, todo = np.ones(count, np.int64), np.zeros(count, bool), np.arange(count)
        out = np.zeros((count, g.n_points, 2), np.float32)
        ctrl = np.zeros((count, g.n_ctrl, 2), np.float32) if g.has_splines else None
        params = np.zeros((count, g.n_points), np.float32) if g.has_params else None
        while len(todo):  # each draw is decoded once; its curve is kept until the item draws again
            with np.errstate(all="ignore"):
                decoded, points, par = g.decode(z[todo])
            out[todo] = decoded
            if ctrl is not None and points is not None:
                ctrl[todo] = points
            if params is not None and par is not None:
                params[todo] = par
            if not valid:
                break
            good = plausible(self._as_returned(decoded, points, closed=named is not None and named.closed))
            ok[todo[good]] = True
            todo = todo[~good & (draws[todo] < max_draws)]
            for i in todo:
                z[i] = one(int(i))
                draws[i] += 1
        invalid = int((~ok).sum()) if valid else 0
        return Drawn(z, out, ctrl, params, chosen, rejected=int(draws.sum() - count), invalid=invalid)

    def resolve(self, prior: str | None) -> str:
        """The prior a request names (None: the learned one where the model ships it, else the standard), checked."""
        chosen = prior or ("learned" if self.prior is not None else "standard")
        if chosen == "learned" and self.prior is None:
            raise InputError(
                ("prior",), 'this model ships no learned prior (GET /model: prior is null); use "standard"'
            )
        if chosen not in self.names:
            known = ", ".join(self.names)
            raise InputError(("prior",), f"no prior named {chosen!r} on this server; it has: {known} (GET /model)")
        return chosen

    def _as_returned(self, decoded: np.ndarray, ctrl: np.ndarray | None, *, closed: bool) -> np.ndarray:
        """(B, n, 2) float64: the decoded curves as `CurveRuntime.sample` returns them, in the model plane: a closed
        family's closed, its ends joined on the control points (placing.joined), so what is judged is what is
        returned (the joined spline can cross itself where the decoder's open curve does not)."""
        out = decoded.astype(np.float64)
        if not closed:
            return out
        if ctrl is None:
            return joined_ends(out)
        return sample_bspline(joined_ends(ctrl), out.shape[1], self.graphs.spline_degree)

    def plausible(self, curves: np.ndarray) -> np.ndarray:
        """(B, n, 2) model-plane curves -> (B,) bool: finite, free of self-intersections and inside the disc."""
        finite = np.isfinite(curves).all(axis=(1, 2))
        inside = np.linalg.norm(np.where(finite[:, None, None], curves, 0) - self.disc_center, axis=-1).max(axis=1)
        ok = finite & (inside <= self.disc_radius)
        if ok.any():
            ok[ok] = ~self_intersects(curves[ok])
        return ok

    def sample(
        self,
        count: int,
        *,
        seed: int | None = None,
        temperature: float = 1.0,
        prior: str | None = None,
        valid: bool = True,
        max_draws: int = MAX_DRAWS,
        offset: int = 0,
        n_points: int | None = None,
        spacing: str = "parameter",
        frame: Frame | None = None,
    ) -> Sampled:
        """`draw`n curves mapped to the caller: into `frame`, or, drawn from a user's family, each into the frame of
        its nearest reference curve (loops kept loops); else left in the model plane. `seed` None: a fresh one,
        reported back."""
        root = fresh_seed() if seed is None else seed
        drawn = self.draw(
            count, seed=root, temperature=temperature, prior=prior, valid=valid, max_draws=max_draws, offset=offset
        )
        frames: list[Frame] | None = [frame] * count if frame else None
        out, ctrl = drawn.decoded, drawn.ctrl
        named = self.named.get(drawn.prior)
        if named is not None:
            if frames is None and named.reference.frames.size:
                frames = [named.reference.frame(int(i)) for i in named.nearest(drawn.latents)]
            if named.closed:
                out, ctrl = closed_rows(out, ctrl)
        placed = decoded_to_caller(
            self.graphs, out, ctrl, drawn.params, frames=frames, n_points=n_points, spacing=spacing
        )
        return Sampled(
            placed.curves,
            placed.frames,
            placed.splines,
            latents=drawn.latents,
            prior=drawn.prior,
            seed=root,
            offset=offset,
            rejected=drawn.rejected,
            invalid=drawn.invalid,
        )


def fresh_seed() -> int:
    """A random seed for a request that gave none, reported back so the answer can be repeated."""
    return int(np.random.SeedSequence().generate_state(1, np.uint64)[0] >> np.uint64(11))  # 53 bits: exact in JSON
