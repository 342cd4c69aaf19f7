"""curve_vae.client against a live server, what its answers are: one curve (an (n, 2) array or a list of [x, y]
pairs) answered as a batch of one by reconstruct, encode and fit, and refused by interpolate and augment before
anything is sent; curves one type whatever their lengths; /fit's and /revolve's answers typed; and the figures of
how close each answer came (closeness, repaired, valid, ends, redrawn) parsed from what the server sends and true
of the curves it returned."""

from __future__ import annotations

import asyncio

import httpx
import numpy as np
import pytest
import shapely

from curve_vae.client import AsyncClient, Client, Closeness
from curve_vae.errors import InvalidInput
from tests.curve_vae.client.test_client import C1, C2, C3, PROFILE, raw


def _curve() -> np.ndarray:
    """One curve as a numpy user holds it: x and y columns."""
    t = np.linspace(0, 1, 12)
    return np.c_[8 * t, 3 * np.sin(np.pi * t) + t]


# ------------------------------------------------------------------ one curve


def test_one_curve_is_reconstructed_as_a_batch_of_one(live_server):
    curve = _curve()
    with Client(live_server.url) as c:
        one = c.reconstruct(curve, pose="as_is")
        pairs = c.reconstruct(curve.tolist(), pose="as_is")
        batch = c.reconstruct([curve], pose="as_is")
    for got in (one, pairs):
        assert len(got.curves) == 1 and got.curve.shape == curve.shape and got.mse.shape == (1,)
        np.testing.assert_array_equal(got.curve, batch.curves[0])
        np.testing.assert_array_equal(got.mse, batch.mse)


def test_one_curve_is_encoded_and_fitted_as_a_batch_of_one(live_server):
    curve = _curve()
    with Client(live_server.url) as c:
        enc, enc_batch = c.encode(curve), c.encode([curve])
        fit, fit_batch = c.fit(curve, n_ctrl=5, n_points=9), c.fit([curve], n_ctrl=5, n_points=9)
    assert enc.mean.shape == enc_batch.mean.shape == (1, 32) and len(enc.frames) == 1
    np.testing.assert_array_equal(enc.mean, enc_batch.mean)
    np.testing.assert_array_equal(enc.log_var, enc_batch.log_var)
    assert len(fit.fits) == 1 and fit.spline.n_ctrl == 5 and fit.json() == fit_batch.json()


def test_the_async_client_answers_one_curve_as_one(live_server):
    async def run():
        async with AsyncClient(live_server.url) as c:
            return await c.reconstruct(_curve(), pose="as_is")

    got = asyncio.run(run())
    with Client(live_server.url) as c:
        np.testing.assert_array_equal(got.curve, c.reconstruct([_curve()], pose="as_is").curves[0])


def test_one_curve_to_interpolate_or_augment_is_refused_before_sending(live_server):
    sent: list[str] = []
    with Client(live_server.url) as c:
        c.model()
        c._http.event_hooks["request"] = [lambda r: sent.append(r.url.path)]
        with pytest.raises(InvalidInput, match="interpolate needs at least 2 curves, got one curve"):
            c.interpolate(_curve(), steps=3)
        with pytest.raises(InvalidInput, match="augment needs at least 2 curves, got one curve"):
            c.augment(_curve(), 4, seed=1)
        with pytest.raises(InvalidInput, match="augment_chunks needs at least 2 curves, got one curve"):
            c.augment_chunks(_curve(), 4, seed=1)  # at the call, not at the first chunk
    assert sent == []


# ------------------------------------------------------------------ one type of curves


def test_curves_are_a_list_of_arrays_whatever_their_lengths(live_server):
    with Client(live_server.url) as c:
        same = c.reconstruct([C1, C2])
        ragged = c.reconstruct([C1, C2[:5]])
        results = [
            same,
            ragged,
            c.interpolate([C1, C2], steps=3),
            c.sample(2, seed=1, n_points=20),
            c.augment([C1, C2, C3], 3, seed=1),
            c.decode(c.encode([C1]).mean, n_points=10),
            next(iter(c.augment_chunks([C1, C2, C3], 3, seed=1))),
        ]
    for got in results:
        assert type(got.curves) is list and all(x.ndim == 2 and x.shape[1] == 2 for x in got.curves), type(got)
    assert same.stacked().shape == (2, 7, 2) and [len(x) for x in ragged.curves] == [7, 5]
    with pytest.raises(ValueError, match="curves of 5, 7 points do not stack"):
        ragged.stacked()


# ------------------------------------------------------------------ /fit and /revolve


def test_a_fit_is_typed_arrays_that_draw_the_fitted_curve(live_server):
    with Client(live_server.url) as c:
        got = c.fit([C1, C2], n_ctrl=6, n_points=15)
    want = raw(live_server.url, "/fit", {"curves": [C1, C2], "n_ctrl": 6, "n_points": 15})
    assert len(got.fits) == 2 and got.json() == want
    for fit in got.fits:
        assert fit.control_points.shape == (6, 2) and fit.knots.shape == (6 + fit.degree + 1,)
        assert fit.curve is not None and fit.curve.shape == (15, 2)
        # a clamped spline starts at its first control point and ends at its last
        np.testing.assert_allclose(fit.curve[[0, -1]], fit.control_points[[0, -1]], atol=1e-9)
        assert 0 <= fit.rms_error <= fit.max_error


@pytest.mark.parametrize("fmt", ["obj", "stl"])
def test_a_revolved_mesh_is_its_file_its_counts_and_its_arrays(live_server, tmp_path, fmt):
    with Client(live_server.url) as c:
        got = c.revolve(PROFILE, segments=16, format=fmt)
    want = httpx.post(live_server.url + "/revolve", json={"curve": PROFILE, "segments": 16, "format": fmt})
    assert got.data == want.content and got.format == fmt and got.media_type == f"model/{fmt}"
    vertices, faces = got.mesh()
    assert (len(vertices), len(faces)) == (got.n_vertices, got.n_faces) and vertices.shape[1] == faces.shape[1] == 3
    assert got.closed is True  # the profile's ends lie on the axis: a closed, watertight surface
    path = got.save(tmp_path / f"vase.{fmt}")
    assert path.read_bytes() == got.data
    with pytest.raises(FileExistsError):
        got.save(path)


# ------------------------------------------------------------------ how close each answer came


def _closeness(inputs: list, outputs: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """RMS and largest point distance ÷ the input's bounding-box diagonal, and each point's distance ÷ it."""
    rms, worst, distances = [], [], []
    for a, b in zip(inputs, outputs, strict=True):
        a = np.asarray(a, np.float64)
        diag = np.hypot(*(a.max(0) - a.min(0)))
        d = np.hypot(*(a - np.asarray(b)).T) / diag
        rms.append(np.sqrt(np.mean(d**2)))
        worst.append(d.max())
        distances.append(d)
    return np.array(rms), np.array(worst), distances


def _well_formed(got: Closeness, lengths: list[int]) -> None:
    assert len(got) == len(lengths) and got.max_at.dtype == np.int64
    assert np.all(np.isfinite(got.rms)) and np.all(got.rms >= 0) and np.all(got.max >= got.rms - 1e-12)
    assert all(0 <= i < n for i, n in zip(got.max_at, lengths))


def test_a_reconstruction_says_how_close_each_curve_came_and_which_were_repaired(live_server):
    """Needs a server that sends `closeness` and `repaired` on /reconstruct."""
    inputs = [C1, C2[:5], _curve().tolist()]
    with Client(live_server.url) as c:
        got = c.reconstruct(inputs)
    want = raw(live_server.url, "/reconstruct", {"curves": inputs})
    assert got.closeness is not None, "the server sent no closeness"
    assert got.closeness.json() == want["closeness"]
    _well_formed(got.closeness, [len(x) for x in inputs])
    # the curves come back at their inputs' points (no n_points): the figures are those of the returned curves
    rms, worst, distances = _closeness(inputs, got.curves)
    np.testing.assert_allclose(got.closeness.rms, rms, rtol=1e-6)
    np.testing.assert_allclose(got.closeness.max, worst, rtol=1e-6)
    np.testing.assert_allclose([d[i] for d, i in zip(distances, got.closeness.max_at)], worst, rtol=1e-6)
    assert got.repaired is not None and got.repaired.dtype == bool and got.repaired.tolist() == want["repaired"]
    assert len(got.repaired) == len(inputs)


def test_one_curve_s_closeness_is_that_curve_s(live_server):
    """Needs a server that sends `closeness` on /reconstruct."""
    with Client(live_server.url) as c:
        one, batch = c.reconstruct(_curve(), pose="as_is"), c.reconstruct([_curve(), C1], pose="as_is")
    assert one.closeness is not None and batch.closeness is not None, "the server sent no closeness"
    assert len(one.closeness) == 1  # the batch's first curve, read beside another: the same to float rounding
    np.testing.assert_allclose(one.closeness.rms, batch.closeness.rms[:1], rtol=1e-5)
    np.testing.assert_allclose(one.closeness.max, batch.closeness.max[:1], rtol=1e-5)


def test_an_encoding_s_closeness_is_what_the_server_sent_or_none(live_server):
    """/encode's closeness may be absent: None then, and well formed where it is sent."""
    with Client(live_server.url) as c:
        got = c.encode([C1, C2[:5]])
    want = raw(live_server.url, "/encode", {"curves": [C1, C2[:5]]})
    if want.get("closeness") is None:
        assert got.closeness is None
    else:
        assert got.closeness is not None and got.closeness.json() == want["closeness"]
        _well_formed(got.closeness, [7, 5])


def test_an_interpolation_says_which_curves_are_valid_and_how_close_its_ends_came(live_server):
    """Needs a server that sends `valid`, `repaired` and `ends` on /interpolate; this model decodes the ends (a model
    that decodes only the mixes sends `ends` empty)."""
    with Client(live_server.url) as c:
        got = c.interpolate([C1, C2], steps=5)
    want = raw(live_server.url, "/interpolate", {"curves": [C1, C2], "steps": 5})
    assert got.valid is not None and got.ends is not None, "the server sent no valid or no ends"
    assert got.valid.dtype == bool and got.valid.tolist() == want["valid"] and got.ends.json() == want["ends"]
    assert got.repaired is not None and got.repaired.tolist() == want["repaired"] and len(got.repaired) == 5
    # valid: free of self-crossings (the inputs are open curves)
    assert got.valid.tolist() == [shapely.LineString(x).is_simple for x in got.curves]
    _well_formed(got.ends, [len(C1), len(C2)])  # one per input curve, not per returned one


def test_an_augment_page_says_how_many_mixes_were_drawn_again(live_server):
    """Needs a server that sends `redrawn` and `invalid` on /augment's JSON pages."""
    body = {"curves": [C1, C2, C3], "count": 6, "seed": 4, "mode": "triplet"}
    with Client(live_server.url) as c:
        got = c.augment([C1, C2, C3], 6, seed=4, mode="triplet")
        chunk = next(iter(c.augment_chunks([C1, C2, C3], 6, seed=4, mode="triplet")))
    want = raw(live_server.url, "/augment", body)
    assert got.redrawn is not None, "the server sent no redrawn"
    assert isinstance(got.redrawn, int) and got.redrawn == want["redrawn"] >= 0
    assert isinstance(got.invalid, int) and got.invalid == want["invalid"] >= 0
    assert chunk.redrawn is None and chunk.invalid is None  # a .npy chunk carries the curves alone
