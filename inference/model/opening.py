"""Opening a model directory: its manifest checked, its graphs' sessions opened, the files beside them read (the
learned prior, the reading ranker, priors fitted to users' curves), each failure a ModelLoadError that names the file
and what to fix; then, with warm-up, one default request (`warm_up_request`). `CurveRuntime.load` is the way in;
this is what it is made of."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from curve_vae.errors import InvalidInput
from curve_vae.inference.choices import Placement, Providers, choices
from curve_vae.inference.generation.named_priors import load_priors
from curve_vae.inference.generation.prior import LatentPrior
from curve_vae.inference.model.graphs import ModelGraphs
from curve_vae.inference.model.manifest import Manifest, ModelLoadError
from curve_vae.inference.model.sessions import SessionConfig
from curve_vae.inference.prepared import EncodingCache
from curve_vae.inference.ranker import Ranker
from curve_vae.inference.spacer import Spacer

if TYPE_CHECKING:  # the runtime is made of what this module opens
    from curve_vae.inference.runtime import CurveRuntime

T = TypeVar("T")
#: Points of the warm-up request's curve: not the model's count, so that it is resampled and fitted as callers' are.
WARM_UP_POINTS = 57


def open_model(
    model_dir: str | Path,
    *,
    providers: Providers,
    batch_size: int,
    warm_up: bool,
    sessions: SessionConfig,
    placement: str,
    cache_bytes: int,
    priors_dir: str | Path | None,
) -> dict[str, Any]:
    """The parts `CurveRuntime(...)` takes, by name (see `CurveRuntime.load` for the options)."""
    root = Path(model_dir)
    manifest = Manifest.read(root)
    if placement not in choices(Placement):
        raise InvalidInput(f"placement must be one of {', '.join(choices(Placement))}, got {placement!r}")
    if placement == "closest" and manifest.spline is None:
        raise ModelLoadError(f"{root}: placement closest needs a model with a B-spline head; this one has none")
    prior = _load_part(root, manifest.prior, "latent prior", LatentPrior.load)
    if prior is not None and prior.latent_dim != manifest.latent_dim:
        raise ModelLoadError(
            f"graphs do not match the manifest: the prior has {prior.latent_dim} latent dimensions, "
            f"the model {manifest.latent_dim}"
        )
    graphs = ModelGraphs.open(
        root, manifest, providers=providers, sessions=sessions, batch_size=batch_size, warm_up=warm_up
    )
    # the learned parts run where the graphs do (the providers their sessions opened on), each one session that
    # every inference thread shares
    part_sessions = replace(sessions, sessions=1)
    ranker = _load_part(
        root,
        manifest.ranker,
        "reading ranker",
        lambda p: Ranker.load(p, graphs, sessions=part_sessions),
    )
    spacer = _load_part(
        root,
        manifest.spacer,
        "spacing guesser",
        lambda p: Spacer.load(p, graphs, sessions=part_sessions),
    )
    closest = None if placement == "model" else placement == "closest"
    cache = EncodingCache(cache_bytes) if cache_bytes > 0 else None
    named = load_priors(priors_dir, manifest, manifest.latent_dim)
    return {
        "graphs": graphs,
        "prior": prior,
        "closest": closest,
        "cache": cache,
        "model_dir": root,
        "priors": named,
        "ranker": ranker,
        "spacer": spacer,
    }


def _load_part(root: Path, entry: Any, what: str, load: Callable[[Path], T]) -> T | None:
    """A model file the manifest names (None where it names none), or a ModelLoadError saying why it is unusable."""
    if entry is None:
        return None
    path = root / entry.file
    try:
        return load(path)
    except (OSError, ValueError, KeyError) as e:
        raise ModelLoadError(f"{path}: not a usable {what} ({e})") from e


def warm_up_request(runtime: CurveRuntime) -> None:
    """One default request, read as any caller's is: the compiled kernels it runs (geometry's natural fit and
    placement, numba) load here, or compile into numba's cache on a machine's first start (20–30 s; 0.5 s from
    the cache), so that no caller's first request pays for them. The encoding cache and the graphs' row counts are
    left as they were; ModelLoadError if the request fails."""
    t = np.linspace(0.2, 2.9, WARM_UP_POINTS)
    arc = np.stack([300 + 120 * np.cos(t), 200 - 80 * np.sin(t) + 10 * np.sin(3 * t)], axis=1)
    rows, cache = dict(runtime.graphs.rows), runtime.reader.cache
    runtime.reader.cache = None
    try:
        runtime.reconstruct([arc])
    except Exception as e:  # noqa: BLE001  (whatever fails, the model cannot serve: say so at start)
        raise ModelLoadError(f"warm-up request failed: {e}") from e
    finally:
        runtime.reader.cache = cache
        runtime.graphs.rows.update(rows)


#: The compiled kernels a reading calls (the rest are compiled into them): geometry.natural_kernel's fit and
#: geometry.matching_kernel's placement.
KERNELS = (("natural_kernel", "fit_start"), ("natural_kernel", "lm_steps"), ("matching_kernel", "place"))


def compiled_kernels() -> tuple[str, list[str]]:
    """Where numba caches the reading's compiled kernels (KERNELS), and which of them it holds no index for yet: what
    a first start compiles (warm_up_request)."""
    from curve_vae.geometry import matching_kernel, natural_kernel

    modules = {"natural_kernel": natural_kernel, "matching_kernel": matching_kernel}
    stats = [getattr(modules[module], name).stats for module, name in KERNELS]
    paths = sorted({s.cache_path for s in stats if s.cache_path})
    if not paths:
        return "no cache (each process compiles them)", [name for _, name in KERNELS]
    where = Path(paths[0])
    return str(where), [name for module, name in KERNELS if not any(where.glob(f"{module}.{name}-*.nbi"))]


def seed_kernel_cache(seed: Path) -> str | None:
    """Copy a numba cache compiled elsewhere (`curve-vae warm-up` at an image's build) into NUMBA_CACHE_DIR where
    that holds none of the reading's kernels yet (a new container or pod: an empty, writable directory), so that the
    start loads them instead of compiling; what was done, or None where nothing was (no NUMBA_CACHE_DIR, no seed,
    or the kernels there already)."""
    import os
    import shutil

    target = os.environ.get("NUMBA_CACHE_DIR")
    if not target or not seed.is_dir() or not compiled_kernels()[1]:
        return None
    shutil.copytree(seed, target, dirs_exist_ok=True)
    return f"copied the compiled kernels of {seed} into {target}"
