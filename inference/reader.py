"""Reading caller curves into the model: their frames and poses, their points at the model's count, the encoder, and
— for a model placed "closest" — the decoded spline and where each caller point sits on it.

    caller's curve (n, 2) --frame + pose (geometry.frame)--> --spacing (geometry.adapt)--> (161, 2) model plane
        --encoder--> latent --decoder--> spline --geometry.ordered_closest_params--> each caller point's parameter

A model trained in geometry.canonical_frame's pose reads each curve once: the canonical pose, the points as given.
The search (pose or spacing "search") makes several candidates per curve — six poses, the points as given and their
natural readings — encodes and decodes them all, and keeps each curve's closest reconstruction. Curves read before
with the same reading come from the encoding cache. `refine` fits each latent closer afterwards (inference.fitting).
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Sequence
from typing import Any

import numpy as np

from curve_vae.geometry import (
    Frame,
    canonical_frame,
    fit_frame,
    natural_readings_of,
    ordered_closest_params,
    pose_frames,
)
from curve_vae.geometry.adapt import COINCIDENT, coincident
from curve_vae.geometry.batch import (
    canonical_frames,
    pose_frames_of,
    shared_canonical_frames,
    shared_pose_frames,
)
from curve_vae.inference import picking
from curve_vae.inference.errors import InputError
from curve_vae.inference.fitting import Fitter
from curve_vae.inference.looking import look_again
from curve_vae.inference.model.graphs import ModelGraphs, checkpoint
from curve_vae.inference.placing import model_targets, pinned_rows, placed_again, untangle_rows
from curve_vae.inference.prepared import EncodingCache, Prepared, ReadCurve
from curve_vae.inference.ranker import RANKED_READS, Ranker
from curve_vae.inference.reading import Candidate, Reading, model_points
from curve_vae.inference.spacer import Spacer

#: A natural reading whose parameters are all within this of the points' index fractions reads the curve as given:
#: spacing "search" does not try it beside "parameter".
SAME_READING = 1e-4
#: Curves whose natural readings are fitted together (a batch's fit holds ~9 starts × points × 10 per curve).
NATURAL_BATCH = 32
#: The natural fit's (scout, total) steps for pose "learned", whose ranker keeps the closer of two candidates: the
#: family suite (200 a set) reads as close with 8 and 24 as with the fit's own 15 and 40 (0.97–1.04× per set, every
#: set within 1.17× of the search; docs/RESULTS.md) and one curve of the default request costs 20.4 ms in-process
#: against 29.5 (docs/BENCHMARKS.md, service 0.16.0). The search and spacing "natural" keep the full fit.
LEARNED_NATURAL_STEPS = (8, 24)
#: The same when the model ships a spacing guesser (inference.spacer): the fit starts from its guess and the
#: arc-length fractions alone. On the family suite (200 a set) every set reads within 1.16× of the search (the
#: paper's curves by arc length 1.05×, 1.15× from the nine starts), in 0.62× the time; 4/8 read a little farther, and
#: the reading table's superellipse and cardioid need more than 8 (docs/RESULTS.md, "The spacing guesser").
GUESSED_NATURAL_STEPS = (6, 12)
#: Which curves keep the arc-length start's fit as a second natural reading beside the guess's (natural_readings_of's
#: `arc_reading`): loops and curves with a corner. Paired against every curve (scripts/arc_reading.py, the family
#: suite, 200 a set): the paper's curves come back 1.0–1.8% closer (fewer candidates for the ranker to mistake),
#: polygons 2.7% and waves 1.4% farther, airfoils, NACA sections and closed outlines as before, no answer more
#: crossing itself; a 128-curve default request reads 13.1 candidates a curve instead of 17.7 (docs/RESULTS.md).
GUESSED_ARC_READING = "loops_and_corners"
#: Chord directions pose "search" tries (geometry.frame.POSE_CHORDS), each as drawn and reversed-and-mirrored.
POSE_CHORD_COUNT = 3
ENCODE_OVERFLOW = 'encodes to non-finite values: coordinates far outside the model\'s plane (use frame "auto")'


class Reader:
    """Brings caller curves to a model's graphs and through them (see the module docstring)."""

    def __init__(
        self,
        graphs: ModelGraphs,
        *,
        closest: bool,
        fitter: Fitter | None = None,
        cache: EncodingCache | None = None,
        ranker: Ranker | None = None,
        spacer: Spacer | None = None,
    ) -> None:
        self.graphs = graphs
        self.ranker = ranker  # pose "learned": which candidates to encode
        self.spacer = spacer  # pose "learned": where the natural fit starts
        self.closest = closest  # each caller point placed at its closest point on the decoded spline
        self.fitter = fitter
        self.cache = cache
        self.untangle = True  # answers that cross themselves where their inputs do not are untangled (untangling)
        self.keep_ends = True  # answers start and end where their inputs do (inference.placing)
        #: pose "learned": how many of each curve's candidates the ranker's order reads, the closest kept. One, then
        #: a look again, reads closer than two at the cost of two (docs/RESULTS.md, "Readings").
        self.ranked_reads = RANKED_READS

    def read(
        self, curves: Sequence[np.ndarray], reading: Reading, *, decoded: bool = True, shared: bool = False
    ) -> Prepared:
        """Each curve read as `reading` (resolved: no "auto") says, in these steps:

        1. the encoding cache: a curve read before the same way comes back as it was read (`_cached`);
        2. candidates, ranked, encoded: each new curve's poses and spacings, the ranker's first for pose "learned",
           encoded; where several remain, each decoded and the closest kept (`_fresh`);
        3. looked at again: z ← z + E(x) − E(D(z)), a step kept where it brings the answer closer (`_looked`);
        4. refined: the latents fitted closer (`_refined`, inference.fitting);
        5. decoded and placed: each caller point's parameter on its spline (`_decoded`);
        6. finished: the ends kept, and an answer that crosses itself where its input does not untangled (`_finish`);
        7. kept in the cache.

        The runtime takes the rows back to the caller's frame (inference.placing). decoded: also decode each latent
        and, for a model placed closest, place the caller's points on the spline (an encoding alone needs neither).
        shared: the curves are a set that is mixed together (interpolated, augmented), read in one pose."""
        inputs = [np.asarray(c, np.float64) for c in curves]
        shared = (
            shared
            and len(inputs) > 1
            and reading.frame != "model"
            and reading.pose in ("canonical", "search", "learned")
        )
        keys, cached = self._cached(inputs, reading, shared=shared)
        todo = [i for i, r in enumerate(cached) if r is None]
        if shared and todo:  # the set's pose is chosen for all its curves at once
            todo = list(range(len(inputs)))
        fresh = [inputs[i] for i in todo]
        new = self._fresh(fresh, todo, reading, shared=shared)
        earlier: list[list[ReadCurve]] = [[] for _ in new]  # each new row before its steps, the latest first
        new = self._looked(fresh, new, reading.looks, earlier)
        new = self._refined(fresh, new, reading.refine, earlier)
        read = list(cached)
        for i, row in zip(todo, new):
            read[i] = row
        rows: list[ReadCurve] = [r for r in read if r is not None]  # every row now: cached or read just now
        missing = [i for i, r in enumerate(rows) if not r.decoded_yet] if decoded or self.closest else []
        for i, row in zip(missing, self._decoded([inputs[i] for i in missing], [rows[i] for i in missing])[0]):
            rows[i] = row
        # rows read or decoded just now (cached rows were finished when they were read)
        self._finish(inputs, rows, sorted(set(todo) | set(missing)), dict(zip(todo, earlier)))
        if self.cache is not None:
            for k, row in zip(keys, rows):
                self.cache.put(k, row)
        return Prepared(inputs, rows, ends_kept=self.keep_ends)

    def _cached(
        self, inputs: list[np.ndarray], reading: Reading, *, shared: bool
    ) -> tuple[list[bytes], list[ReadCurve | None]]:
        """Each curve's cache key (none without a cache) and its row where the cache holds one: keyed by its bytes,
        the reading, the placement and the ends; a curve of a shared set by its set too (its pose depends on it)."""
        if self.cache is None:
            return [], [None] * len(inputs)
        key = f"{reading.key}/{'closest' if self.closest else 'index'}/{'ends' if self.keep_ends else 'decoded'}"
        if shared:
            key += "/set/" + EncodingCache.key(np.concatenate(inputs), str([len(c) for c in inputs])).hex()
        keys = [EncodingCache.key(c, key) for c in inputs]
        return keys, [self.cache.get(k) for k in keys]

    def _refined(
        self, inputs: list[np.ndarray], rows: list[ReadCurve], steps: int, earlier: list[list[ReadCurve]]
    ) -> list[ReadCurve]:
        """The rows after `steps` refine steps (inference.fitting), each row before them put first in its
        `earlier`; the rows as they are for 0 steps (cached rows were cached refined: the reading's key counts them)."""
        if steps <= 0 or not rows:
            return rows
        if self.fitter is None or not self.graphs.has_splines:
            raise InputError(("refine",), "refining needs a model with a B-spline head; this model has none")
        for before, row in zip(earlier, rows):
            before.insert(0, row)
        return self.fitter.refine(inputs, rows, steps)

    # ----------------------------------------------------------------------------------- candidates

    def _fresh(self, inputs: list[np.ndarray], index: list[int], reading: Reading, *, shared: bool) -> list[ReadCurve]:
        """Curves not in the cache: their candidates, encoded; with several per curve, decoded and the closest kept
        (shared: each curve's closest in the one pose whose candidates are closest over the whole set)."""
        stage = self._candidates(inputs, index, reading, shared=shared)
        models, fractions = model_points(
            inputs, index, stage, n_points=self.graphs.n_points, model_size=self.graphs.model_size
        )
        if reading.pose == "learned" and stage:
            if self.ranker is None:
                raise InputError(("pose",), 'pose "learned" needs a model with a reading ranker; this one has none')
            ranked = picking.ranked(self.ranker, stage, models, shared=shared, count=self.ranked_reads)
            keep = np.sort(np.concatenate(ranked))
            stage, models, fractions = [stage[k] for k in keep], models[keep], [fractions[k] for k in keep]
        if not stage:
            return []
        rows = self._encoded(stage, models, fractions, index)
        if len(stage) == len(inputs):  # one candidate each: nothing to choose
            return rows
        owners = [c.curve for c in stage]
        rows, err = self._decoded([inputs[o] for o in owners], rows)
        owner = np.asarray(owners)
        if shared:
            err = picking.in_shared_pose(inputs, stage, err)
        best = [int(np.flatnonzero(owner == i)[err[owner == i].argmin()]) for i in range(len(inputs))]
        return [rows[b] for b in best]

    def _encoded(
        self, stage: list[Candidate], models: np.ndarray, fractions: list[Any], index: list[int]
    ) -> list[ReadCurve]:
        """The candidates' rows, encoded (InputError naming the request's curve where a latent is not finite)."""
        with np.errstate(all="ignore"):
            mean, log_var = self.graphs.encode(models)
        _check_finite(mean, log_var, [index[c.curve] for c in stage])
        return [ReadCurve(c.frame, m, fr, mu, lv) for c, m, fr, mu, lv in zip(stage, models, fractions, mean, log_var)]

    def _candidates(
        self, inputs: list[np.ndarray], index: list[int], reading: Reading, *, shared: bool = False
    ) -> list[Candidate]:
        """Every curve in every pose, read as the reading says; spacing "search": its points as given and each of
        its natural readings that does not put them where they are (a curve at the paper's own spacing is read so).
        The candidate poses are found for all curves at once (geometry.batch); shared: the set's poses, the same for
        every curve (geometry.batch.shared_pose_frames)."""
        posed: list[list[Frame]] | None = None
        with contextlib.suppress(ValueError), np.errstate(all="ignore"):  # the curve whose points coincide: below
            if shared and reading.pose == "canonical":
                posed = [[f] for f in shared_canonical_frames(inputs)]
            elif shared:
                posed = shared_pose_frames(inputs, chords=POSE_CHORD_COUNT)
            elif reading.frame != "model" and reading.pose == "canonical":
                posed = [[f] for f in canonical_frames(inputs)]
            elif reading.frame != "model" and reading.pose in ("search", "learned"):
                posed = pose_frames_of(inputs, chords=POSE_CHORD_COUNT)
        natural = (
            self._natural_readings(inputs, index, self._natural_fit(reading))
            if reading.spacing in ("search", "natural")
            else None
        )
        stage: list[Candidate] = []
        with np.errstate(all="ignore"):
            for c, (i, pts) in enumerate(zip(index, inputs)):
                try:
                    if reading.frame == "model":
                        frames: list[Frame | None] = [None]
                    elif posed is not None:
                        frames = list(posed[c])
                    elif reading.pose == "canonical":
                        frames = [canonical_frame(pts)]
                    elif reading.pose in ("search", "learned"):
                        frames = list(pose_frames(pts, chords=POSE_CHORD_COUNT))
                    else:
                        frames = [fit_frame(pts)]
                    if reading.spacing == "search" and natural is not None:
                        spaced = [("parameter", None)] + [
                            ("natural", n)
                            for n in natural[c]
                            if np.abs(n - np.linspace(0.0, 1.0, len(n))).max() > SAME_READING
                        ]
                    elif reading.spacing == "natural" and natural is not None:
                        spaced = [("natural", natural[c][0])]  # it does not depend on the pose: fitted once
                    else:
                        spaced = [(reading.spacing, None)]
                except ValueError as e:  # all points coincide
                    raise InputError(("curves", i), COINCIDENT.format(n=len(pts))) from e
                stage += [Candidate(c, f, s, n, p) for p, f in enumerate(frames) for s, n in spaced]
        return stage

    def _natural_fit(self, reading: Reading) -> dict[str, Any]:
        """How the natural fit runs for `reading` (geometry.natural_readings_of's options): pose "learned" with
        spacing "search" from the spacing guesser's guesses where the model has one, in fewer steps either way;
        anything else, the fit's own."""
        if (reading.pose, reading.spacing) != ("learned", "search"):
            return {}
        if self.spacer is not None:
            scout, steps = GUESSED_NATURAL_STEPS
            return {"scout": scout, "steps": steps, "guess": self.spacer.guesses, "arc_reading": GUESSED_ARC_READING}
        scout, steps = LEARNED_NATURAL_STEPS
        return {"scout": scout, "steps": steps}

    @staticmethod
    def _natural_readings(inputs: list[np.ndarray], index: list[int], fit: dict[str, Any]) -> list[list[np.ndarray]]:
        """Each curve's natural readings (geometry.natural_readings_of, with `fit`'s options), NATURAL_BATCH
        curves fitted at once; an abandoned request stops between batches."""
        out: list[list[np.ndarray]] = []
        for start in range(0, len(inputs), NATURAL_BATCH):
            checkpoint()
            part = inputs[start : start + NATURAL_BATCH]
            try:
                out += natural_readings_of(part, **fit)
            except ValueError:  # all points of one coincide: name it
                bad = coincident(part)
                if bad.any():
                    k = int(np.argmax(bad))
                    raise InputError(("curves", index[start + k]), COINCIDENT.format(n=len(part[k]))) from None
                raise
        return out

    def _looked(
        self, inputs: list[np.ndarray], rows: list[ReadCurve], steps: int, earlier: list[list[ReadCurve]]
    ) -> list[ReadCurve]:
        """The rows after `steps` looks again (inference.looking), each row before them (decoded) put first in its
        `earlier`; the rows as they are for 0 steps."""
        if steps <= 0 or not rows:
            return rows
        todo = [i for i, r in enumerate(rows) if not r.decoded_yet or r.distance is None]
        rows = list(rows)
        for i, row in zip(todo, self._decoded([inputs[i] for i in todo], [rows[i] for i in todo])[0]):
            rows[i] = row
        for before, row in zip(earlier, rows):
            before.insert(0, row)
        err = np.array([r.distance for r in rows], np.float64)
        return look_again(self.graphs, inputs, rows, err, steps, self._decoded)[0]

    def _finish(
        self, inputs: list[np.ndarray], read: list[ReadCurve], fresh: list[int], earlier: dict[int, list[ReadCurve]]
    ) -> None:
        """`read[i]` for each i in `fresh`, in place: its ends kept (inference.placing) and untangled (inference.
        untangling). Where an answer still crosses itself, the row before its last step (refine, the looks: `earlier`,
        latest first), finished so, in its place where that one does not."""
        unfinished = {i: read[i] for i in fresh}
        rows, tangled = self._finished([inputs[i] for i in fresh], [read[i] for i in fresh])
        for i, row in zip(fresh, rows):
            read[i] = row
        for i in tangled:
            for before in earlier.get(i, []):
                if not before.decoded_yet:
                    before = self._decoded([inputs[i]], [before])[0][0]
                (row,), still = self._finished([inputs[i]], [before])
                if not still:  # repaired, and says so: another latent than the steps asked for
                    read[i] = row if row.repair is not None or row.ctrl is None else replace_repair(row)
                    break
            else:  # the last resort: the answer's ends free to move where holding them leaves it crossing
                (row,), _ = self._finished([inputs[i]], [unfinished[i]], free_ends=True)
                read[i] = row

    def _finished(
        self, inputs: list[np.ndarray], rows: list[ReadCurve], *, free_ends: bool = False
    ) -> tuple[list[ReadCurve], list[int]]:
        """The rows with their ends kept and untangled, and which of them still cross themselves; `free_ends`: the
        untangling may move the ends where holding them leaves an answer crossing."""
        size, degree = self.graphs.model_size, self.graphs.spline_degree
        if self.keep_ends:
            rows = placed_again(
                inputs, pinned_rows(inputs, rows, model_size=size, degree=degree), model_size=size, degree=degree
            )
        if not self.untangle:
            return rows, []
        return untangle_rows(inputs, rows, model_size=size, degree=degree, free_ends=free_ends or not self.keep_ends)

    # ----------------------------------------------------------------------------------- decoding, placement

    def _decoded(self, inputs: list[np.ndarray], rows: list[ReadCurve]) -> tuple[list[ReadCurve], np.ndarray]:
        """Rows with their latents decoded and, placed closest, each caller point's parameter on the spline; and each
        row's squared distance from its model-plane points (by which the search keeps the closest candidate)."""
        if not rows:
            return [], np.zeros(0)
        g = self.graphs
        with np.errstate(all="ignore"):
            decoded, ctrl, params = g.decode(np.stack([r.mean for r in rows]))
            feet: list[np.ndarray | None] = [None] * len(rows)
            if self.closest and ctrl is not None:
                targets = model_targets(inputs, [r.frame for r in rows], g.model_size)
                placed, err = ordered_closest_params(ctrl, targets, degree=g.spline_degree)
                feet = list(placed)
            else:
                model = np.stack([r.model for r in rows]).astype(np.float64)
                err = ((decoded.astype(np.float64) - model) ** 2).sum(axis=(1, 2))
        err = np.where(np.isfinite(err), err, np.inf)
        out = [
            r.with_decoding(
                decoded[i],
                None if ctrl is None else ctrl[i],
                None if params is None else params[i],
                feet[i],
                float(err[i]),
            )
            for i, r in enumerate(rows)
        ]
        return out, err


def replace_repair(row: ReadCurve) -> ReadCurve:
    """A row marked repaired (`ReadCurve.repair` set, all zeros: its control points are its decoding's)."""
    assert row.ctrl is not None
    return dataclasses.replace(row, repair=np.zeros_like(np.asarray(row.ctrl, np.float64)))


def _check_finite(mean: np.ndarray, log_var: np.ndarray, owners: list[int]) -> None:
    bad = ~(np.isfinite(mean).all(axis=1) & np.isfinite(log_var).all(axis=1))
    if bad.any():
        raise InputError(("curves", owners[int(np.argmax(bad))]), ENCODE_OVERFLOW)
