"""Labels for the reading ranker: curves like users send, each read every way the search reads it, with each reading's
error through the frozen model.

For each curve, the search's candidates (inference.reader: six poses, the points as given and their natural
readings) are mapped to the model plane, encoded, decoded and placed closest, exactly as the service does; a
candidate's label is its relative RMSE (RMSE at the curve's own points ÷ its bounding-box diagonal). The ranker
(training/ranker.py) learns to tell, from a candidate's model-plane points alone, which readings come back closest.

Labels are written in chunks, `labels-<seed>-<chunk>.npz`, each atomically and named by its seed: a run that stops
loses at most the chunk it was on, and `label_curves` skips the chunks already written (resuming).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from curve_vae.files import atomic_path
from curve_vae.geometry.frame import resample, resample_index
from curve_vae.geometry.metrics import diagonal
from curve_vae.inference.placing import model_targets
from curve_vae.inference.reading import Reading, model_points
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.training.families import RANKER_FAMILIES, TRAIN_FAMILIES, draw_family
from curve_vae.training.suite import AIRFOIL_WHEEL, random_moves

#: Point counts the labelled curves come at (users send anything from a few dozen points to a few hundred).
POINT_COUNTS = (40, 64, 100, 161, 240)
#: Airfoils the evaluation tables draw (training/suite.py: 200 with seed 2024; scripts/reading_table.py: 20 with
#: seed 5): never labelled, so the tables measure airfoils the ranker has not seen.
HELD_AIRFOILS = ((200, 2024), (20, 5))
SEARCH = Reading(pose="search", spacing="search")


def user_curves(count: int, seed: int, families: Sequence[str] = tuple(TRAIN_FAMILIES)) -> list[np.ndarray]:
    """`count` curves of `families` (RANKER_FAMILIES' names; by default the training families, the paper's among
    them) and real airfoils, at random point counts and spacings (as drawn, by arc length, warped), turned, mirrored
    and reversed at random."""
    rng = np.random.default_rng(seed)
    airfoils = _TRAINING_AIRFOILS or _training_airfoils()
    chosen = [RANKER_FAMILIES[name] for name in families]
    out: list[np.ndarray] = []
    while len(out) < count:
        n = int(rng.choice(POINT_COUNTS))
        if airfoils and rng.random() < 0.15:
            c = airfoils[int(rng.integers(len(airfoils)))]
            c = resample(c, n) if rng.random() < 0.5 else c
        else:
            family = chosen[int(rng.integers(len(chosen)))]
            c = draw_family(family, 1, rng, n_points=n, model_size=None, chunk=8)[0].astype(np.float64)
            if rng.random() < 0.2:  # also the model's own count at the paper's spacing, read by index
                c = resample_index(c[None], 161)[0]
        out.append(c)
    return random_moves(out, rng)


_TRAINING_AIRFOILS: list[np.ndarray] = []


def _training_airfoils() -> list[np.ndarray]:
    if not AIRFOIL_WHEEL.exists():
        return []
    from curve_vae.training.airfoils import load_airfoils

    held = {c.tobytes() for n, s in HELD_AIRFOILS for c in load_airfoils(AIRFOIL_WHEEL, n, seed=s)}
    _TRAINING_AIRFOILS[:] = [c for c in load_airfoils(AIRFOIL_WHEEL, 10**6) if c.tobytes() not in held]
    return _TRAINING_AIRFOILS


def label(runtime: CurveRuntime, curves: list[np.ndarray]) -> dict[str, np.ndarray]:
    """Every search candidate of every curve: its model-plane points (k, n_points, 2) float32, its curve (k,), its
    pose (k,) and spacing (k,: 0 as given, 1 natural) and its relative RMSE (k,) through the frozen model."""
    reader = runtime.reader
    inputs = [np.asarray(c, np.float64) for c in curves]
    index = list(range(len(inputs)))
    stage = reader._candidates(inputs, index, SEARCH)
    g = runtime.graphs
    models, fractions = model_points(inputs, index, stage, n_points=g.n_points, model_size=g.model_size)
    mean, log_var = runtime.graphs.encode(models)
    from curve_vae.inference.prepared import ReadCurve

    rows = [ReadCurve(c.frame, m, fr, mu, lv) for c, m, fr, mu, lv in zip(stage, models, fractions, mean, log_var)]
    owner = np.array([c.curve for c in stage], np.int32)
    _, err = reader._decoded([inputs[o] for o in owner], rows)
    targets = model_targets([inputs[o] for o in owner], [c.frame for c in stage], reader.graphs.model_size)
    diag = np.array([diagonal(t) for t in targets])  # in the model plane, where err is
    rel = np.sqrt(err / np.array([len(t) for t in targets])) / diag  # frames are similarities: the caller's ratio
    return {
        "points": models.astype(np.float32),
        "curve": owner,
        "pose": np.array([c.pose for c in stage], np.int16),
        "spacing": np.array([c.spacing == "natural" for c in stage], np.int8),
        "error": rel.astype(np.float32),
    }


def label_curves(
    model_dir: str | Path,
    out_dir: str | Path,
    *,
    curves: int,
    seed: int,
    chunk: int = 500,
    time_budget: float = 0.0,
    families: Sequence[str] = tuple(TRAIN_FAMILIES),
    say: Callable[[str], None] = print,
) -> list[Path]:
    """Label `curves` user curves of `families` (seed `seed`: give each set of families its own) against the model
    in `model_dir`, `chunk` curves a file, skipping chunks already written; stop after `time_budget` seconds (0: no
    limit) at a chunk's end. Returns the files."""
    out = Path(out_dir)
    runtime = CurveRuntime.load(model_dir, intra_op_threads=1, cache_bytes=0)
    files, start, total = [], time.monotonic(), (curves + chunk - 1) // chunk
    for k in range(total):
        path = out / f"labels-{seed}-{k:04d}.npz"
        files.append(path)
        if path.exists():
            continue
        if time_budget and time.monotonic() - start > time_budget:
            say(f"time budget spent: {k} of {total} chunks; run again to carry on")
            return [f for f in files if f.exists()]
        t0 = time.monotonic()
        drawn = user_curves(min(chunk, curves - k * chunk), seed * 100_003 + k, families)
        labels = label(runtime, drawn)
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as fh:
                # the ignore: numpy's stub, mypy checks **arrays against allow_pickle: bool too
                np.savez(fh, seed=seed, chunk=k, **labels)  # type: ignore[arg-type]
        say(
            f"chunk {k + 1}/{total}: {len(drawn)} curves, {len(labels['error'])} readings "
            f"in {time.monotonic() - t0:.0f} s"
        )
    return files
