"""inference.results: the JSON bodies the REST routes and the offline CLI both answer with — frames as the API reports
them, quality metrics and spline output added where asked, /fit's least-squares splines (exact on a spline's own
samples) and the errors naming the curve it cannot fit, and the mesh files of /revolve."""

import json

import numpy as np
import pytest

from curve_vae.geometry import Frame, clamped_uniform_knots, random_control_points, revolve, sample_bspline
from curve_vae.inference import results
from curve_vae.inference.answers import CurvesResponse
from curve_vae.inference.errors import InputError
from curve_vae.inference.results import (
    Augmented,
    Closeness,
    Curves,
    Encoding,
    Interpolation,
    Reconstruction,
    Sampled,
    Spline,
)

FRAME = Frame((1.0, -2.0), 3.5, rotation=0.25, mirror=True, reverse=False)
#: straight, 15 long; four points, the fewest a request may send (curve_metrics warns on fewer: nothing to average)
LINE = np.array([[0.0, 0.0], [3.0, 4.0], [6.0, 8.0], [9.0, 12.0]])


def _spline(n: int = 3) -> Spline:
    return Spline(np.zeros((5, 2)), clamped_uniform_knots(5), 3, np.linspace(0, 1, n))


def test_frames_as_the_api_reports_them_and_none_in_the_models_plane():
    assert results.frames_json([FRAME]) == [
        {"center": (1.0, -2.0), "size": 3.5, "rotation": 0.25, "mirror": True, "reverse": False}
    ]
    assert results.frames_json([None, None]) is None and results.frames_json([]) is None


def test_metrics_of_a_straight_line_and_a_curve_that_retraces_itself():
    (line,) = results.curve_metrics([LINE])
    assert line == {
        "smoothness": {"mean_turn": 0.0, "max_turn": 0.0, "roughness": 0.0},
        "self_intersects": False,
        "length": 15.0,
    }
    (back,) = results.curve_metrics([np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [0.5, 0.0]])])
    assert back["self_intersects"] is True and back["smoothness"]["max_turn"] == pytest.approx(180.0)
    json.dumps([line, back])  # plain Python values


def test_a_length_beyond_float64_is_null_not_infinity():
    huge = np.array([[-1e308, 0.0], [1e308, 0.0], [1e308, 1.0], [1e308, 2.0]])  # 2e308 overflows
    (m,) = results.curve_metrics([huge])
    assert m["length"] is None
    json.dumps(m, allow_nan=False)  # strict JSON: no Infinity


def test_metrics_and_output_are_added_only_where_asked():
    def body():
        return CurvesResponse(curves=[LINE.tolist()])

    assert results.with_curves(body(), [LINE], None) == body()
    assert results.with_curves(body(), [LINE], None, metrics=True)["metrics"] == results.curve_metrics([LINE])
    splines = [_spline()]
    assert results.with_curves(body(), [LINE], splines) == body()
    assert results.with_curves(body(), [LINE], None, output="bspline") == body()  # no head: points whatever was asked
    assert results.with_curves(body(), [LINE], splines, output="bspline") == {"splines": [splines[0].json()]}
    assert results.with_curves(body(), [LINE], splines, output="both") == {**body(), "splines": [splines[0].json()]}


def test_result_bodies_carry_their_parts():
    enc = results.encode_body(Encoding(np.ones((2, 3), np.float32) / 3, np.zeros((2, 3), np.float32), [FRAME, FRAME]))
    assert enc["mean"].dtype == np.float64 and enc["frames"] == results.frames_json([FRAME]) * 2
    rec = Reconstruction(
        [LINE, LINE[::-1]], np.array([0.5, 0.25]), np.zeros((2, 3)), [None, None], [_spline(4), _spline(4)]
    )
    body = results.reconstruct_body(rec, metrics=True, output="both")
    assert [len(c) for c in body["curves"]] == [4, 4] and body["mse"].tolist() == [0.5, 0.25]
    assert body["closeness"] == [] and body["repaired"] == []  # a hand-made result: none measured
    assert len(body["metrics"]) == len(body["splines"]) == 2
    mix = Interpolation(
        np.stack([LINE, LINE]),
        [FRAME, FRAME],
        None,
        weights=np.array([[1.0, 0.0], [0.5, 0.5]]),
        valid=np.array([True, False]),
        repaired=np.array([False, True]),
        ends=Closeness(np.array([1e-3, 2e-3]), np.array([4e-3, np.inf]), np.array([3, 0])),
    )
    body = results.interpolate_body(mix, output="bspline")  # no splines: the points stay
    assert (
        set(body) == {"weights", "curves", "frames", "valid", "repaired", "ends"} and body["frames"][1]["size"] == 3.5
    )
    assert body["valid"] == [True, False] and body["repaired"] == [False, True]
    assert body["ends"] == [{"rms": 1e-3, "max": 4e-3, "max_at": 3}, {"rms": 2e-3, "max": None, "max_at": 0}]
    json.dumps(body["ends"], allow_nan=False)  # strict JSON: an overflow is null, never Infinity
    made = results.decode_body(Curves(np.stack([LINE]), [None], [_spline()]), output="bspline")
    assert set(made) == {"splines"}


def test_sample_bodies_name_the_frames_of_a_users_prior_only():
    made = Sampled(np.stack([LINE]), [FRAME], latents=np.zeros((1, 4)), prior="learned", seed=9, rejected=2)
    body = results.sample_body(made)
    assert "frames" not in body and (body["seed"], body["rejected"], body["prior"]) == (9, 2, "learned")
    mine = results.sample_body(Sampled(np.stack([LINE]), [FRAME], latents=np.zeros((1, 4)), prior="vases"))
    assert mine["frames"] == results.frames_json([FRAME])
    json.dumps(body) and json.dumps(mine)


def test_augment_bodies():
    made = Augmented(
        np.stack([LINE]), [FRAME], sources=np.array([[2, 0]]), weights=np.array([[0.3, 0.7]]), seed=4, offset=10
    )
    body = results.augment_body(made, metrics=True)
    assert body["sources"] == [[2, 0]] and body["weights"] == [[0.3, 0.7]] and body["offset"] == 10
    assert body["frames"] == results.frames_json([FRAME]) and len(body["metrics"]) == 1


def test_fit_recovers_a_splines_control_points_from_its_own_samples():
    ctrl = random_control_points(np.random.default_rng(3), 1)[0]
    (fit,) = results.fit_body([sample_bspline(ctrl, 161)], 10, param="uniform", n_points=25)["fits"]
    np.testing.assert_allclose(fit["control_points"], ctrl, atol=1e-6)
    np.testing.assert_allclose(fit["curve"], sample_bspline(ctrl, 25), atol=1e-6)
    assert fit["n_ctrl"] == 10 and fit["degree"] == 3 and fit["rms_error"] < 1e-9
    np.testing.assert_allclose(fit["knots"], clamped_uniform_knots(10))


def test_fit_without_a_count_takes_the_fewest_control_points():
    line = np.stack([np.linspace(0, 9, 40), np.linspace(0, 3, 40)], axis=1)
    (fit,) = results.fit_body([line])["fits"]
    assert fit["n_ctrl"] == 4 and "curve" not in fit


BAD_FITS = {
    "fewer points than control points": (
        [LINE, LINE[:2].repeat(3, axis=0)],
        10,
        "n_ctrl=10 control points need at least as many points, got 6; omit n_ctrl to have it chosen",
    ),
    "points bunched in a knot span": (
        [LINE, np.concatenate([np.stack([np.linspace(0, 0.01, 10), np.zeros(10)], 1), [[10, 0], [20, 5]]])],
        10,
        "no unique least-squares spline with 10 control points",
    ),
}


@pytest.mark.parametrize("curves, n_ctrl, message", BAD_FITS.values(), ids=BAD_FITS.keys())
def test_a_curve_that_cannot_be_fitted_is_named(curves, n_ctrl, message):
    curves = [np.stack([np.linspace(0, 9, 40), np.sin(np.linspace(0, 3, 40))], 1), curves[1]]
    with pytest.raises(InputError, match=message) as caught:
        results.fit_body(curves, n_ctrl)
    assert caught.value.loc == ("curves", 1)


def test_mesh_files_say_what_they_are():
    mesh = revolve(np.array([[1.0, 0.0], [2.0, 1.0], [1.0, 2.0]]), segments=8)
    obj = results.mesh_file(mesh, points=3, segments=8, axis="y", fmt="obj").decode()
    assert obj.startswith("# curve-vae surface of revolution: 3-point profile, 8 segments about the y axis\n")
    assert obj == mesh.to_obj(comment=obj.splitlines()[0][2:])
    stl = results.mesh_file(mesh, points=3, segments=8, axis="y", fmt="stl")
    assert int.from_bytes(stl[80:84], "little") == len(mesh.faces) and len(stl) == 84 + 50 * len(mesh.faces)
