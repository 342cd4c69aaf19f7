"""The VAE at inference time: a model directory's graphs and the geometry that brings any curve to them and back.

    rt = CurveRuntime.load("models")
    rec = rt.reconstruct(curves)                  # Reconstruction: curves, mse, latents, frames, splines
    mix = rt.interpolate(curves[:2], [[0.5, 0.5]])  # Interpolation
    new = rt.sample(16, seed=0)                   # Sampled

`CurveRuntime.load(model_dir)` checks the manifest and the sha256 of every file (`inference.model.manifest`), opens the
sessions (`inference.model.graphs`) and reads the learned prior. Its methods take numpy arrays and return result objects
(`inference.results`), so everything the service does can be used and tested without HTTP:

    caller's curve (n, 2) --Reader (frame, pose, spacing; encoder; decoder; placement)--> latent, spline
        --(affine mix of latents: interpolation, augmentation)--> decoder --placing--> the caller's frame

How a curve is read is one `Reading` (frame, pose, spacing, refine): by default the model's own — one encoding per
curve for a model trained in the canonical pose — or the search (`inference.reader`). Curves read before come from
the encoding cache (`inference.prepared`). Nothing here imports torch.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TypeVar

import numpy as np

from curve_vae.geometry import Frame
from curve_vae.inference.choices import SOURCES_PER_MODE, Providers
from curve_vae.inference.errors import InputError
from curve_vae.inference.fitting import Fitter
from curve_vae.inference.generation.augmenting import AugmentPlan, augmented, neighbour_pools
from curve_vae.inference.generation.exploring import Explored, explore
from curve_vae.inference.generation.mixing import mix
from curve_vae.inference.generation.named_priors import NamedPrior
from curve_vae.inference.generation.prior import LatentPrior
from curve_vae.inference.generation.sampling import MAX_DRAWS, Sampler
from curve_vae.inference.model.graphs import ModelGraphs
from curve_vae.inference.model.manifest import Manifest, ModelLoadError  # noqa: F401  (ModelLoadError: part of its API)
from curve_vae.inference.model.opening import open_model, warm_up_request
from curve_vae.inference.model.sessions import SessionConfig
from curve_vae.inference.placing import (
    check_range,
    decoded_to_caller,
    each_to_caller,
    placed_to_caller,
)
from curve_vae.inference.prepared import DEFAULT_CACHE_BYTES, EncodingCache, Prepared
from curve_vae.inference.ranker import Ranker
from curve_vae.inference.reader import Reader
from curve_vae.inference.reading import Reading
from curve_vae.inference.results import (
    Augmented,
    Closeness,
    Curves,
    Encoding,
    Interpolation,
    Reconstruction,
    Sampled,
    Spline,
    head_splines,
    no_closeness,
)
from curve_vae.inference.spacer import Spacer

DEFAULT = Reading()
T = TypeVar("T")


class CurveRuntime:
    """An exported model: its graphs, its prior and the reading of caller curves (see the module docstring)."""

    def __init__(
        self,
        graphs: ModelGraphs,
        *,
        prior: LatentPrior | None = None,
        closest: bool | None = None,
        cache: EncodingCache | None = None,
        model_dir: str | Path | None = None,
        priors: dict[str, NamedPrior] | None = None,
        ranker: Ranker | None = None,
        spacer: Spacer | None = None,
    ) -> None:
        self.graphs = graphs
        self.manifest: Manifest = graphs.manifest
        self.model_dir = Path(model_dir) if model_dir is not None else Path(".")
        self.prior = prior
        spline = self.manifest.spline
        placed = bool(spline and spline.placement == "closest") if closest is None else closest
        self.fitter = Fitter(graphs) if graphs.has_splines else None
        self.cache = cache
        self.reader = Reader(
            graphs,
            closest=placed and graphs.has_splines,
            fitter=self.fitter,
            cache=cache,
            ranker=ranker,
            spacer=spacer,
        )
        disc = np.asarray(self.manifest.frame.center, np.float64)
        self.priors = priors or {}
        self.sampler = Sampler(graphs, prior, disc, self.manifest.disc_radius, self.priors)

    @classmethod
    def load(
        cls,
        model_dir: str | Path,
        *,
        providers: Providers = "auto",
        intra_op_threads: int = 0,
        batch_size: int = 64,
        warm_up: bool = True,
        sessions: SessionConfig | None = None,
        placement: str = "model",
        cache_bytes: int = DEFAULT_CACHE_BYTES,
        priors_dir: str | Path | None = None,
    ) -> CurveRuntime:
        """Open a model directory; ModelLoadError says what to fix when it cannot serve.

        `sessions` sets threads, spinning and the number of session pairs (inference.model.sessions); without it, one
        pair of `intra_op_threads` threads. `placement`: "model" places a reconstruction's points as the manifest's
        spline.placement says; "closest" or "index" whatever it says (CURVE_VAE_PLACEMENT). `cache_bytes`: the
        encoding cache's bound (0: no cache). `priors_dir`: priors fitted to users' curves (`curve-vae prior`), by
        their files' stems; one fitted to another model is a ModelLoadError."""
        parts = open_model(
            model_dir,
            providers=providers,
            batch_size=batch_size,
            warm_up=warm_up,
            sessions=sessions or SessionConfig(intra_op_threads=intra_op_threads),
            placement=placement,
            cache_bytes=cache_bytes,
            priors_dir=priors_dir,
        )
        runtime = cls(**parts)
        if warm_up:
            runtime.warm_up(graphs=False)  # the graphs were warmed as they opened
        return runtime

    def warm_up(self, *, graphs: bool = True) -> None:
        """The graphs' first runs (ModelGraphs.warm_up) and one default request before the first caller's
        (inference.model.opening.warm_up_request: the compiled kernels load, or compile on a first start);
        ModelLoadError
        where either fails."""
        if graphs:
            self.graphs.warm_up()
        warm_up_request(self)

    # ----------------------------------------------------------------------- what the model is

    @property
    def n_points(self) -> int:
        return self.graphs.n_points

    @property
    def latent_dim(self) -> int:
        return self.graphs.latent_dim

    @property
    def model_size(self) -> float:
        return self.graphs.model_size

    @property
    def has_splines(self) -> bool:
        return self.graphs.has_splines

    @property
    def closest_placement(self) -> bool:
        """Whether a reconstruction's points are placed at the caller's points' closest points on its spline."""
        return self.reader.closest

    @closest_placement.setter
    def closest_placement(self, closest: bool) -> None:
        self.reader.closest = bool(closest) and self.graphs.has_splines

    def reading(self, reading: Reading | None = None) -> Reading:
        """A request's reading with "auto" made concrete: the model's own pose and spacing (its manifest's)."""
        return (reading or DEFAULT).resolved(self.manifest.reading)

    # ----------------------------------------------------------------------- curves in and out

    def prepare(
        self,
        curves: Sequence[np.ndarray],
        reading: Reading | None = None,
        *,
        decoded: bool = True,
        together: bool = False,
    ) -> Prepared:
        """Each caller curve (n_i, 2), n_i ≥ 4, read into the model (inference.reader). together: the curves are one
        set, read in one pose, as `interpolate` and `plan_augment` read the curves they mix."""
        return self.reader.read(curves, self.reading(reading), decoded=decoded, shared=together)

    def encode(
        self, curves: Sequence[np.ndarray], reading: Reading | None = None, *, together: bool = False
    ) -> Encoding:
        """Latent mean and log-variance of each curve, and the frame (with its pose) each was mapped from; with
        refine, the means are the fitted latents. together: read as one set (`prepare`)."""
        prep = self.prepare(curves, reading, decoded=False, together=together)
        decoded = bool(prep.rows) and all(r.decoded_yet for r in prep.rows)  # closest placement decodes to read
        return Encoding(
            prep.mean, prep.log_var, prep.frames, Closeness.of(prep.inputs, self._at_inputs(prep)) if decoded else None
        )

    def decode(
        self,
        latents: np.ndarray,
        *,
        n_points: int | None = None,
        frames: Sequence[Frame] | None = None,
        spacing: str = "parameter",
    ) -> Curves:
        """Curves (B, n, 2) for latents (B, latent_dim): in the model plane, or mapped to `frames`."""
        z = np.asarray(latents, np.float64)
        if z.ndim != 2 or z.shape[1] != self.latent_dim:
            raise InputError(("latents",), f"expected rows of {self.latent_dim} numbers, got shape {list(z.shape)}")
        check_range(z, "latents")
        with np.errstate(all="ignore"):
            out, ctrl, params = self.graphs.decode(z)
        return decoded_to_caller(self.graphs, out, ctrl, params, frames=frames, n_points=n_points, spacing=spacing)

    def reconstruct(
        self,
        curves: Sequence[np.ndarray],
        reading: Reading | None = None,
        *,
        n_points: int | None = None,
        together: bool = False,
    ) -> Reconstruction:
        """Encode the means, decode them: the curves in the caller's frame and their MSE (paper eq. 4) there.

        The MSE compares each input with its reconstruction at the input's own points, whatever `n_points` asks
        for the returned curves. A closed input (its last point its first) comes back closed: the reconstruction's
        ends are joined at their midpoint. A model placed closest (and any refine) returns each input point at its
        closest point on the reconstruction. together: the curves read as one set, in one pose (`prepare`): the
        ends of a sweep between them.
        """
        r = self.reading(reading)
        prep = self.reader.read(curves, r, shared=together)
        with np.errstate(all="ignore"):
            placed: tuple[list[np.ndarray], Sequence[Spline | None], np.ndarray] | None
            placed = placed_to_caller(self.graphs, prep) if n_points is None else None  # every curve at once
            if placed is None:  # curve by curve: n_points asked, no frames, or a head without closest placement
                placed = each_to_caller(self.graphs, prep, n_points=n_points, spacing=r.spacing)
        curves_out, splines, mse = placed
        own = curves_out if n_points is None else self._at_inputs(prep)
        return Reconstruction(
            curves_out,
            mse,
            prep.mean,
            prep.frames,
            head_splines(splines, self.has_splines),
            closeness=Closeness.of(prep.inputs, own),
            repaired=np.array([r.repair is not None for r in prep.rows], bool),
        )

    def interpolate(
        self,
        curves: Sequence[np.ndarray],
        weights: np.ndarray,
        reading: Reading | None = None,
        *,
        n_points: int | None = None,
    ) -> Interpolation:
        """Decode affine combinations of the curves' latent means (paper eqs. 9, 10), one per weight row.

        weights: (rows, len(curves)), rows summing to 1. With frame "auto" each interpolant comes back in the same
        blend of the inputs' frames. Length: n_points; else the inputs' common length, at the blend of their
        points' positions; else the model's. The curves are read as one set, in one pose
        (geometry.batch.shared_pose_frames; a curve listed the other way round from the first is read reversed), so
        the in-betweens turn and move as the curves do: a row [1, 0, …] is `reconstruct(curves, together=True)`'s
        first curve. With refine the means are the fitted latents, and the positions blended are the input points'
        closest points on their fitted splines. When every input is closed, so is every interpolant.
        """
        r = self.reading(reading)
        prep = self.reader.read(curves, r, decoded=False, shared=True)  # only the latents are mixed
        made = self.mix(prep, np.asarray(weights, np.float64), n_points=n_points, spacing=r.spacing)
        return dataclasses.replace(made, ends=self._ends(prep))

    def _ends(self, prep: Prepared) -> Closeness:
        """How close each input's own reconstruction in the set's reading comes (a sweep's ends); none where the
        reading did not decode them (a model placed by index decodes only the mixes)."""
        if not all(r.decoded_yet for r in prep.rows):
            return no_closeness(len(prep.rows))
        return Closeness.of(prep.inputs, self._at_inputs(prep))

    def _at_inputs(self, prep: Prepared) -> list[np.ndarray]:
        """Each decoded curve at its input's own points, in the caller's frame: what the closeness compares."""
        with np.errstate(all="ignore"):
            placed = placed_to_caller(self.graphs, prep) or each_to_caller(
                self.graphs, prep, n_points=None, spacing="parameter"
            )
        return placed[0]

    def mix(
        self, prep: Prepared, weights: np.ndarray, *, n_points: int | None = None, spacing: str = "parameter"
    ) -> Interpolation:
        """Decode weight rows (rows, len(prep.inputs)) over the prepared curves' means; see `interpolate`."""
        length = self.mix_length(prep, n_points)
        return mix(self.graphs, prep, weights, n_points=n_points, spacing=spacing, length=length)

    def mix_length(self, prep: Prepared, n_points: int | None) -> int:
        """Points per curve that mixing `prep`'s curves returns: n_points, else their common length, else 161."""
        return n_points or _common_length(prep) or self.n_points

    # ----------------------------------------------------------------------- new curves

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
        """New curves from a latent distribution (inference.generation.sampling), in the model plane or mapped into
        `frame`."""
        return self.sampler.sample(
            count,
            seed=seed,
            temperature=temperature,
            prior=prior,
            valid=valid,
            max_draws=max_draws,
            offset=offset,
            n_points=n_points,
            spacing=spacing,
            frame=frame,
        )

    def explore(
        self,
        curve: np.ndarray,
        reading: Reading | None = None,
        *,
        steps: int = 3,
        spread: float = 1.0,
        directions: int = 2,
        prior: str | None = None,
        n_points: int | None = None,
    ) -> Explored:
        """Curves around `curve`: its latent mean moved along the `directions` principal directions of a latent
        distribution (inference.generation.exploring), a grid of `steps` offsets per direction from −spread to spread
        standard
        deviations, decoded in the curve's own frame. The middle of the grid is the curve's own reconstruction."""
        return explore(self, curve, reading, steps=steps, spread=spread, directions=directions, prior=prior,
                       n_points=n_points)  # fmt: skip

    def plan_augment(
        self,
        curves: Sequence[np.ndarray],
        *,
        seed: int,
        mode: str = "pair",
        neighbours: int | None = None,
        reading: Reading | None = None,
    ) -> AugmentPlan:
        """Encode the seed curves once and fix who may be mixed with whom (`neighbour_pools`); see `AugmentPlan`."""
        prep = self.reader.read(curves, self.reading(reading), decoded=False, shared=True)  # mixed: in one pose
        mean = prep.mean.astype(np.float64)
        pools = neighbour_pools(mean, mode, neighbours)
        return AugmentPlan(prep=prep, mean=mean, k=SOURCES_PER_MODE[mode], seed=seed, pools=pools)

    def augment(
        self, plan: AugmentPlan, start: int, stop: int, *, n_points: int | None = None, spacing: str = "parameter"
    ) -> Augmented:
        """Items start … stop-1 of the plan's sequence, each free of self-crossings
        (inference.generation.augmenting)."""
        length = self.mix_length(plan.prep, n_points)
        return augmented(self.graphs, plan, start, stop, n_points=n_points, spacing=spacing, length=length)

    def augment_chunks(
        self,
        plan: AugmentPlan,
        start: int,
        stop: int,
        *,
        n_points: int | None = None,
        spacing: str = "parameter",
        chunk: int | None = None,
    ) -> Iterator[np.ndarray]:
        """The curves of items start … stop-1, `chunk` at a time (default batch_size): bounded memory for any count."""
        step = chunk or self.graphs.batch_size
        for i in range(start, stop, step):
            yield self.augment(plan, i, min(i + step, stop), n_points=n_points, spacing=spacing).curves


def _common_length(prep: Prepared) -> int | None:
    lengths = {len(c) for c in prep.inputs}
    return lengths.pop() if len(lengths) == 1 else None
