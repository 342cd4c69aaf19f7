"""Priors fitted to a user's own curves: more curves like these, in their own frame.

A `NamedPrior` (`<name>.npz`, written by `curve-vae prior`) is a Gaussian mixture over the latents of a set of curves
read with the model's default reading, with what sampling it needs besides: the model it belongs to (the sha256 of
both graphs: another model's latents mean other shapes), the reading, and its reference curves' statistics — each
curve's latent and frame (a sample comes back in the frame of its nearest reference curve: their position, size and
orientation), whether they are closed (then samples are closed too), how far from the plane's centre they reach and
whether they cross themselves (the validity of a sample is judged against these). The service loads every prior of
CURVE_VAE_PRIORS_DIR at start (a prior's name is its file's stem) and refuses one fitted to another model.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae.files import atomic_path
from curve_vae.geometry import Frame, self_intersects
from curve_vae.geometry.frame import MODEL_CENTER
from curve_vae.inference.generation.prior import LatentPrior
from curve_vae.inference.model.manifest import Manifest, ModelLoadError

NAMED_PRIOR_VERSION = 1
#: A valid sample reaches no further from the plane's centre than the furthest reference curve × this.
REACH_MARGIN = 1.05


@dataclass(frozen=True)
class Reference:
    """What the curves a prior was fitted to look like, for placing and judging its samples."""

    latents: np.ndarray  # (N, Z) their latents
    frames: np.ndarray  # (N, 7): centre x, y, size, rotation, mirror, reverse, closed — each curve's frame
    reach: float  # the furthest any reference reconstruction gets from the plane's centre (model plane)
    crossing: float  # share of the reference reconstructions that cross or touch themselves
    closed: float  # share of the reference curves that are closed

    def frame(self, i: int) -> Frame:
        cx, cy, size, rotation, mirror, reverse, _ = self.frames[i]
        return Frame((float(cx), float(cy)), float(size), float(rotation), bool(mirror), bool(reverse))


@dataclass(frozen=True)
class NamedPrior:
    name: str
    mixture: LatentPrior
    reference: Reference
    model: dict[str, str]  # the sha256 of the graphs it was fitted through
    meta: dict[str, Any]  # how it was fitted: reading, components, BIC per count, curves, source

    @property
    def closed(self) -> bool:
        return self.reference.closed > 0.5

    def describe(self) -> dict[str, Any]:
        """What GET /model says of it."""
        return {
            "components": len(self.mixture.weights),
            "curves": len(self.reference.latents),
            "closed": self.closed,
            **{k: self.meta[k] for k in ("kind", "reading", "source", "chosen_by") if k in self.meta},
        }

    def nearest(self, z: np.ndarray) -> np.ndarray:
        """(B,) index of each latent's nearest reference latent."""
        d = ((np.asarray(z)[:, None, :] - self.reference.latents[None]) ** 2).sum(-1)
        return d.argmin(axis=1)

    def plausible(self, curves: np.ndarray) -> np.ndarray:
        """(B, n, 2) model-plane curves -> (B,) bool: finite, within the reference's reach of the plane's centre, and
        free of self-intersections where the reference curves are."""
        finite = np.isfinite(curves).all(axis=(1, 2))
        safe = np.where(finite[:, None, None], curves, 0)
        reach = np.linalg.norm(safe - np.asarray(MODEL_CENTER), axis=-1).max(axis=1)
        ok = finite & (reach <= self.reference.reach * REACH_MARGIN)
        if ok.any() and self.reference.crossing < 0.5:  # (a closed family's curves come here closed: Sampler)
            ok[ok] = ~self_intersects(curves[ok])
        return ok

    # ------------------------------------------------------------------------------------------ files

    def save(self, path: str | Path) -> None:
        r, m = self.reference, self.mixture
        meta = {
            "version": NAMED_PRIOR_VERSION,
            "name": self.name,
            "model": self.model,
            **self.meta,
            "reach": r.reach,
            "crossing": r.crossing,
            "closed": r.closed,
        }
        with atomic_path(path) as tmp, open(tmp, "wb") as f:
            np.savez(
                f,
                weights=m.weights,
                means=m.means,
                cholesky=m.cholesky,
                latents=r.latents,
                frames=r.frames,
                meta=np.array(json.dumps(meta)),
            )

    @classmethod
    def load(cls, path: str | Path) -> NamedPrior:
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as z:
                meta = json.loads(str(z["meta"]))
                mixture = LatentPrior(z["weights"], z["means"], z["cholesky"])
                ref = Reference(
                    z["latents"],
                    z["frames"],
                    float(meta.pop("reach")),
                    float(meta.pop("crossing")),
                    float(meta.pop("closed")),
                )
        except (OSError, KeyError, ValueError) as e:
            raise ModelLoadError(f"{path}: not a prior of curve-vae prior ({e})") from e
        if meta.pop("version", None) != NAMED_PRIOR_VERSION:
            raise ModelLoadError(f"{path}: a prior of another format; fit it again with curve-vae prior")
        return cls(path.stem, mixture, ref, meta.pop("model"), {k: v for k, v in meta.items() if k != "name"})


def model_identity(manifest: Manifest) -> dict[str, str]:
    """The sha256 of a model's graphs: what a prior's latents belong to."""
    return {f: manifest.files[f].sha256 for f in (manifest.graphs.encoder.file, manifest.graphs.decoder.file)}


def load_priors(directory: str | Path | None, manifest: Manifest, latent_dim: int) -> dict[str, NamedPrior]:
    """Every `<name>.npz` prior of `directory`, checked against the model; ModelLoadError naming the prior and both
    models where one was fitted to another model."""
    if not directory:
        return {}
    root = Path(directory)
    if not root.is_dir():
        raise ModelLoadError(f"CURVE_VAE_PRIORS_DIR {root} is not a directory")
    mine = model_identity(manifest)
    out = {}
    for path in sorted(root.glob("*.npz")):
        prior = NamedPrior.load(path)
        if prior.model != mine:
            raise ModelLoadError(
                f"{path}: fitted to another model ({prior.meta.get('model_name', '?')} "
                f"{prior.meta.get('model_version', '?')}, encoder sha256 {next(iter(prior.model.values()))[:12]}…) "
                f"than the one served ({manifest.name} {manifest.version}, encoder sha256 "
                f"{next(iter(mine.values()))[:12]}…): fit it again with `curve-vae prior --model-dir …`"
            )
        if prior.mixture.latent_dim != latent_dim:
            raise ModelLoadError(f"{path}: {prior.mixture.latent_dim} latent dimensions, the model {latent_dim}")
        if prior.name in ("learned", "standard"):
            raise ModelLoadError(f"{path}: {prior.name!r} names a built-in prior; rename the file")
        out[prior.name] = prior
    return out


def frames_array(frames: list[Frame | None], closed: list[bool]) -> np.ndarray:
    """(N, 7) rows of Reference.frames."""
    return np.array(
        [[*f.center, f.size, f.rotation, f.mirror, f.reverse, c] for f, c in zip(frames, closed) if f is not None],
        np.float64,
    )


def meta_of(**kw: Any) -> dict[str, Any]:
    return {k: (asdict(v) if hasattr(v, "__dataclass_fields__") else v) for k, v in kw.items()}
