"""inference.reader: how caller curves are read into the model, through the real ONNX graphs.

- spacing "natural" and "search": a curve read at even steps of the parameters of the cubic B-spline that fits it
  (`geometry.natural_params`), and the readings tried with the reconstruction closest to the input kept;
- a model that reads curves in the canonical pose (its manifest's reading): one encoding and one decoding per curve,
  and the same answer for a curve, its reversal, its mirror image and its rotations;
- pose "auto" and "learned" on the shipped model: a curve, its reversal, mirror image and rotations come back as the
  same curve, moved alike;
- sweeps between curves read as one set (the shared pose): the README's pair turns as its curves do, and a set
  moved moves its sweep.
"""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from curve_vae.geometry import evaluate_bspline, natural_params, natural_readings, resample, sample_bspline
from curve_vae.geometry.morph import end_drift, turn_excess
from curve_vae.inference import reader as reader_module
from curve_vae.inference.errors import InputError
from curve_vae.inference.reading import Reading
from curve_vae.inference.results import Reconstruction
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.schemas import ReconstructRequest
from tests.helpers import bspline_curves, natural_fits_asked

# ------------------------------------------------------------------ spacing: natural readings and the search


def _drawn_by_arc_length(count: int, seed: int) -> list[np.ndarray]:
    return [resample(3.0 * c + [40.0, -900.0], 161) for c in bspline_curves(count, seed=seed)]


def _rel(curves: list[np.ndarray], out: list[np.ndarray]) -> np.ndarray:
    return np.array(
        [np.sqrt(((a - b) ** 2).sum(-1).mean()) / np.hypot(*np.ptp(a, axis=0)) for a, b in zip(curves, out)]
    )


def _each_reading(runtime, curves, monkeypatch, **options) -> dict[str, Reconstruction]:
    """What /reconstruct gives each reading spacing "auto" tries alone: the points as given, the closest natural
    fit's reading, and the reading of the fit from the arc-length fractions (where it ends elsewhere)."""
    out = {sp: runtime.reconstruct(curves, Reading(spacing=sp, **options)) for sp in ("parameter", "natural")}
    with monkeypatch.context() as m:
        m.setattr(reader_module, "natural_readings_of", lambda many: [natural_readings(pts)[-1:] for pts in many])
        out["natural, from arc length"] = runtime.reconstruct(curves, Reading(spacing="natural", **options))
    return out


def test_auto_keeps_the_closest_reading_and_brings_curves_drawn_by_arc_length_closer(shipped_runtime, monkeypatch):
    curves = _drawn_by_arc_length(10, seed=31)
    # pose "search" (the learned reading encodes only two of these candidates: tests/inference/test_ranker.py)
    each = _each_reading(shipped_runtime, curves, monkeypatch, pose="search")
    errors = {sp: _rel(curves, out.curves) for sp, out in each.items()}
    auto = _rel(curves, shipped_runtime.reconstruct(curves, Reading(pose="search", spacing="search")).curves)
    picked = np.any([np.isclose(auto, e, rtol=1e-9) for e in errors.values()], axis=0)
    assert picked.all(), (auto, errors)  # each curve's answer is one of the readings'
    assert (auto <= np.max(list(errors.values()), axis=0) * (1 + 1e-9)).all()
    assert auto.mean() < 0.8 * errors["parameter"].mean(), (auto.mean(), errors["parameter"].mean())


def test_auto_answers_a_curve_reversed_or_mirrored_alike(shipped_runtime):
    # (a turned curve's bounding box, and so its scale in the model plane, changes with the angle: within a few
    # percent, with every spacing)
    curves = _drawn_by_arc_length(3, seed=32)
    want = _rel(curves, shipped_runtime.reconstruct(curves, Reading(spacing="search")).curves)
    for move in (lambda c: c[::-1], lambda c: c * [-1.0, 1.0], lambda c: c[::-1] * [-1.0, 1.0]):
        moved = [move(c) for c in curves]
        np.testing.assert_allclose(
            _rel(moved, shipped_runtime.reconstruct(moved, Reading(spacing="search")).curves), want, rtol=1e-9
        )


def test_without_pose_candidates_the_readings_still_compete(runtime, monkeypatch):
    curves = [c for c in bspline_curves(3, seed=33)] + [resample(c, 90) for c in bspline_curves(2, seed=34)]
    for frame, pose in (("model", "search"), ("auto", "as_is")):
        res = runtime.reconstruct(curves, Reading(frame=frame, pose=pose, spacing="search"))
        out, mse = res.curves, res.mse
        one = _each_reading(runtime, curves, monkeypatch, frame=frame, pose=pose)
        assert [len(o) for o in out] == [len(c) for c in curves]
        assert np.any([np.isclose(mse, rec.mse) for rec in one.values()], axis=0).all()


def test_the_natural_reading_puts_the_callers_points_at_their_natural_parameters(runtime):
    c = resample(bspline_curves(1, seed=35)[0], 120)
    splines = runtime.reconstruct([c], Reading(spacing="natural", pose="as_is")).splines
    np.testing.assert_allclose(splines[0].params, natural_params(c), atol=1e-9)  # index placement: at their params


def test_http_takes_both_readings_and_names_a_bad_one(client):
    c = resample(bspline_curves(1, seed=36)[0], 100).tolist()
    for sp in ("natural", "search"):
        r = client.post("/reconstruct", json={"curves": [c], "spacing": sp, "n_points": 50})
        assert r.status_code == 200, r.text
        assert np.array(r.json()["curves"][0]).shape == (50, 2)
    r = client.post("/reconstruct", json={"curves": [c], "spacing": "natrual"})
    assert r.status_code == 422 and "spacing" in r.text
    with pytest.raises(ValueError):
        ReconstructRequest(curves=[c], spacing="natrual")


def test_a_natural_reading_that_puts_the_points_where_they_are_is_not_tried_again(runtime, monkeypatch):
    """A curve at the paper's own spacing: its closest natural fit gives its points their index fractions
    (reader.SAME_READING), so "search" does not try that reading beside "parameter"; a curve drawn by arc length gets
    every natural reading in every pose."""
    even = bspline_curves(1, seed=37)[0]
    drawn = resample(even, len(even))
    assert np.abs(natural_params(even) - np.linspace(0, 1, len(even))).max() <= reader_module.SAME_READING
    rows: list[int] = []
    encode = runtime.graphs.encode
    monkeypatch.setattr(runtime.graphs, "encode", lambda x: rows.append(len(x)) or encode(x))
    runtime.reconstruct([even], Reading(spacing="search", looks=0))
    runtime.reconstruct([drawn], Reading(spacing="search", looks=0))
    poses = 2 * reader_module.POSE_CHORD_COUNT
    assert rows[0] == poses * len(natural_readings(even))  # "parameter", and the readings but the closest
    assert rows[1] == poses * (1 + len(natural_readings(drawn)))


# ------------------------------------------------------------------ a model read in the canonical pose

#: How close the answers for moved copies of a curve come back, relative to its size: float rounding of the moves.
TOLERANCE = 1e-6


@pytest.fixture(scope="module")
def canonical(model_dir, tmp_path_factory) -> CurveRuntime:
    out = tmp_path_factory.mktemp("canonical")
    shutil.copytree(model_dir, out, dirs_exist_ok=True)
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["reading"] = {"pose": "canonical", "spacing": "parameter"}
    manifest["spline"]["placement"] = "closest"
    (out / "manifest.json").write_text(json.dumps(manifest))
    return CurveRuntime.load(out, providers="cpu", intra_op_threads=1, cache_bytes=0)


def _moves_of(c: np.ndarray) -> dict[str, tuple]:
    a = np.radians(130)
    turn = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
    return {
        "reversed": (c[::-1], lambda x: x[::-1]),
        "mirrored": (c * [-1.0, 1.0], lambda x: x * [-1.0, 1.0]),
        "rotated": (c @ turn * 2.5 + 40, lambda x: x @ turn * 2.5 + 40),
        "all of them": ((c * [-1.0, 1.0])[::-1] @ turn, lambda x: (x * [-1.0, 1.0])[::-1] @ turn),
    }


def _graph_rows(rt: CurveRuntime, curves: list[np.ndarray], reading: Reading | None = None) -> dict[str, int]:
    """The encoder and decoder rows one reconstruction runs."""
    rows: dict[str, list[int]] = {"encoder": [], "decoder": []}
    run = rt.graphs._run_graph
    rt.graphs._run_graph = lambda s, graph, x, o: rows[graph].append(len(x)) or run(s, graph, x, o)
    try:
        rt.reconstruct(curves, reading)
    finally:
        rt.graphs._run_graph = run
    return {k: sum(v) for k, v in rows.items()}


def test_the_default_reading_is_one_encoding_and_one_look(canonical):
    """Ten curves: one encoder and one decoder batch to read them, one of each to look again (inference.looking);
    without the look, one of each."""
    assert canonical.reading() == Reading(pose="canonical", spacing="parameter", looks=1)
    curves = list(bspline_curves(10, 90, seed=3) * 0.3 - 5)
    assert _graph_rows(canonical, curves) == {"encoder": 20, "decoder": 20}
    assert _graph_rows(canonical, curves, Reading(looks=0)) == {"encoder": 10, "decoder": 10}


@pytest.mark.parametrize("move", ["reversed", "mirrored", "rotated", "all of them"])
def test_a_moved_curve_comes_back_as_the_curve_moved(canonical, move):
    for c in [
        *bspline_curves(4, 120, seed=8) * 0.05,
        np.stack([np.linspace(0, 3, 80), np.sin(np.linspace(0, 4, 80))], 1),
    ]:
        moved, how = _moves_of(c)[move]
        (own,), (back,) = canonical.reconstruct([c]).curves, canonical.reconstruct([moved]).curves
        size = np.ptp(how(c), axis=0).max()
        np.testing.assert_allclose(back, how(own), atol=TOLERANCE * size)


# ------------------------------------------------------------------ pose "auto" and "learned": moves do not matter


def _rot(a: float) -> np.ndarray:
    return np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])


def _stroke() -> np.ndarray:
    """An S-shaped stroke from corner to corner, drawn left to right: nothing like the paper's curves' pose."""
    ctrl = np.array([[0.0, 0.0], [40.0, 5.0], [10.0, 50.0], [60.0, 60.0], [90.0, 40.0], [100.0, 90.0]])
    return sample_bspline(ctrl[None], 120)[0]


MOVES = {
    "reversed": (lambda c: c[::-1], lambda c: c[::-1]),
    "mirrored": (lambda c: c * [-1.0, 1.0], lambda c: c * [-1.0, 1.0]),
    "rotated 130°": (lambda c: c @ _rot(np.radians(130)), lambda c: c @ _rot(np.radians(130)).T),
}


@pytest.mark.parametrize("move", MOVES)
def test_reconstruction_does_not_care_about_the_move(shipped_runtime, move):
    c = _stroke()
    there, back = MOVES[move]
    (own,) = shipped_runtime.reconstruct([c]).curves
    (moved,) = shipped_runtime.reconstruct([there(c)]).curves
    np.testing.assert_allclose(back(moved), own, atol=1e-3 * np.ptp(c))


@pytest.mark.parametrize("move", MOVES)
def test_the_learned_reading_does_not_care_about_the_move(shipped_runtime, move):
    """Pose "learned": the ranker scores the search's candidates from their model-plane points, which a curve and
    its reversal, mirror image or rotation share to rounding, so each comes back as the same curve, moved, within
    1e-3 of its size; curves of several kinds, as drawn and by arc length. A symmetric curve (half an ellipse, the
    mirror image of its own reversal) has pairs of readings the ranker scores alike, and a move may tip it to the
    other of two equally close answers: within a few tenths of a percent of its size, its error within 10%."""
    t = np.linspace(0.0, 1.0, 90)
    curves = [_stroke(), *bspline_curves(2, seed=41), resample(bspline_curves(1, seed=42)[0], 70)]
    symmetric = np.c_[np.cos(np.pi * t), 0.6 * np.sin(np.pi * t)]
    there, back = MOVES[move]
    learned = Reading(pose="learned", spacing="search")
    own = shipped_runtime.reconstruct([*curves, symmetric], learned)
    moved = shipped_runtime.reconstruct([there(c) for c in [*curves, symmetric]], learned)
    for c, a, b in zip(curves, own.curves, moved.curves):
        np.testing.assert_allclose(back(b), a, atol=1e-3 * np.ptp(c))
    np.testing.assert_allclose(back(moved.curves[-1]), own.curves[-1], atol=3e-3 * np.ptp(symmetric))
    assert moved.mse[-1] == pytest.approx(own.mse[-1], rel=0.1)


def test_pose_auto_beats_as_is_on_a_stroke_unlike_the_papers_curves(shipped_runtime):
    c = _stroke()
    diag = np.hypot(*np.ptp(c, axis=0))
    auto = shipped_runtime.reconstruct([c]).mse
    as_is = shipped_runtime.reconstruct([c], Reading(pose="as_is")).mse
    assert np.sqrt(2 * auto[0]) / diag < 0.02  # within 2% of the diagonal (eq. 4 MSE averages both coordinates)
    assert auto[0] < as_is[0] / 4


def test_interpolating_a_curve_with_its_reversal_gives_the_curve(shipped_runtime):
    c = _stroke()
    (own,) = shipped_runtime.reconstruct([c]).curves  # at its own points, as a sweep between inputs of its length
    w = np.array([[1.0, 0.0], [0.7, 0.3], [0.5, 0.5], [0.2, 0.8]])
    res = shipped_runtime.interpolate([c, c[::-1]], w)
    out, frames = res.curves, res.frames
    mine = shipped_runtime.encode([c]).frames[0]
    for curve, frame in zip(out, frames):  # in the order of the heavier source
        np.testing.assert_allclose(curve if frame.reverse == mine.reverse else curve[::-1], own, atol=1e-6 * np.ptp(c))


def test_spline_output_matches_the_points_in_a_reversed_pose(shipped_runtime):
    c = _stroke()[::-1] * [1.0, -1.0]
    rec = shipped_runtime.reconstruct([c])
    (pts,), (s,) = rec.curves, rec.splines
    np.testing.assert_allclose(evaluate_bspline(s.control_points, s.params, s.degree), pts, atol=1e-9)


# ------------------------------------------------------------------ sweeps of a set read in one pose

README_PAIR = [
    np.array([[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]], float),
    np.array([[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]], float),
]
STEPS = np.array([[1 - t, t] for t in np.linspace(0, 1, 5)])


def test_the_readme_pair_turns_from_one_chord_to_the_other(shipped_runtime):
    sweep = np.stack(shipped_runtime.interpolate(README_PAIR, STEPS).curves)
    chords = np.degrees(np.arctan2(*(sweep[:, -1] - sweep[:, 0]).T[::-1]))
    assert np.all(np.diff(chords) > 0), chords  # 0° -> 47°, every step further round
    assert turn_excess(sweep) <= 10.0
    assert end_drift(sweep) <= 0.1


def test_a_sweep_moves_with_its_pair(shipped_runtime):
    turn = np.array([[0.6, 0.8], [-0.8, 0.6]])
    moved = [c @ turn * 30 + [500, -20] for c in README_PAIR]
    sweep = np.stack(shipped_runtime.interpolate(README_PAIR, STEPS).curves)
    swept = np.stack(shipped_runtime.interpolate(moved, STEPS).curves)
    np.testing.assert_allclose(swept, sweep @ turn * 30 + [500, -20], atol=1e-6 * 30 * 8)


# ------------------------------------------------------------------ curves the reader cannot take, named

#: every way a curve is read: each has its own place that finds coincident points (the frame, the batch's canonical
#: poses, the pose candidates, the natural fit), and each must name the curve, not fail on it
READINGS = {
    "as given": Reading(pose="as_is", spacing="parameter"),
    "by arc length": Reading(pose="as_is", spacing="arc_length"),
    "canonical": Reading(pose="canonical", spacing="parameter"),
    "pose search": Reading(pose="search", spacing="parameter"),
    "natural": Reading(pose="as_is", spacing="natural"),
    "the search": Reading(pose="search", spacing="search"),
}


@pytest.mark.parametrize("reading", READINGS.values(), ids=READINGS.keys())
def test_a_curve_whose_points_coincide_is_named_in_every_reading(runtime, reading):
    good = list(bspline_curves(2, 60, seed=50))
    with pytest.raises(InputError, match=r"^curves\[2\]: all 60 points coincide: a curve needs at least 2") as caught:
        runtime.reconstruct([*good, np.full((60, 2), 7.0)], reading)
    assert caught.value.loc == ("curves", 2)


def test_a_set_read_in_one_pose_names_its_coincident_curve(runtime):
    with pytest.raises(InputError, match="coincide") as caught:
        runtime.interpolate([bspline_curves(1, seed=51)[0], np.ones((161, 2))], STEPS)
    assert caught.value.loc == ("curves", 1)


def test_points_beyond_float32_in_the_models_plane_are_named(runtime):
    # frame "model" takes the points as they are: the encoder runs in float32, so 1e300 cannot be read
    huge = bspline_curves(2, seed=52)
    huge[1] *= 1e300
    with pytest.raises(InputError, match=r'curves\[1\]: coordinates beyond float32 range; use frame "auto"'):
        runtime.reconstruct(list(huge), Reading(frame="model"))


def test_without_a_spacing_guesser_the_learned_reading_fits_in_fewer_steps_and_the_search_in_the_full_fit(
    shipped_runtime, monkeypatch
):
    """For a model with a ranker and no spacing guesser, pose "learned" with spacing "search" reads each curve's
    natural spacings with LEARNED_NATURAL_STEPS (its ranker keeps the closer of two candidates, and the suite reads as
    close); the search and spacing "natural" keep the fit's own steps (with a guesser: tests/inference/test_spacer)."""
    monkeypatch.setattr(shipped_runtime.reader, "spacer", None)
    scout, steps = reader_module.LEARNED_NATURAL_STEPS
    expected = {
        Reading(pose="learned", spacing="search"): {"scout": scout, "steps": steps},
        Reading(pose="search", spacing="search"): {},
        Reading(pose="learned", spacing="natural"): {},
        Reading(pose="canonical", spacing="natural"): {},
    }
    asked = natural_fits_asked(shipped_runtime, monkeypatch, list(expected))
    assert asked == [[fit] for fit in expected.values()]
