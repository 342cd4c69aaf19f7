"""inference/reading.py: each candidate reading's points in the model's plane, all of a request's candidates at
once — exactly what geometry.to_model_plane gives each alone."""

from __future__ import annotations

import numpy as np

from curve_vae.geometry import resample, to_model_plane
from curve_vae.inference.reading import Reading, model_points
from tests.helpers import bspline_curves


def _drawn_by_arc_length(count: int, seed: int) -> list[np.ndarray]:
    return [resample(3.0 * c + [40.0, -900.0], 161) for c in bspline_curves(count, seed=seed)]


def test_the_candidates_model_points_are_to_model_planes_all_at_once(runtime):
    """The search's candidates (six poses, the points as given and their natural readings) are brought to the model's
    plane together: exactly what `to_model_plane` gives each alone, where the caller's points sit along them too —
    for curves of several lengths, repeated points and a natural reading that stands still at an end."""
    curves = _drawn_by_arc_length(3, seed=61) + [resample(c, 90) for c in bspline_curves(2, seed=62)]
    curves[1] = np.concatenate([curves[1][:1], curves[1][:1], curves[1]])  # its first point three times
    reader = runtime.reader
    stage = reader._candidates(curves, list(range(len(curves))), Reading(pose="search", spacing="search"))
    assert {c.spacing for c in stage} == {"parameter", "natural"} and any(c.frame.reverse for c in stage)
    g = runtime.graphs
    models, fractions = model_points(
        curves, list(range(len(curves))), stage, n_points=g.n_points, model_size=g.model_size
    )
    for c, m, fr in zip(stage, models, fractions):
        one, where = to_model_plane(
            curves[c.curve], c.frame, model_size=g.model_size, n_points=g.n_points, spacing=c.spacing, natural=c.natural
        )
        np.testing.assert_array_equal(m, one.astype(np.float32))
        assert (fr is None) == (where is None) and (fr is None or np.array_equal(fr, where))
