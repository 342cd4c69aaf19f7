"""POST /sample and /augment (service.routes.generate, issue 5): seeded, paged and streamed batches; weights in the
simplex; metrics; a stream that fails midway is visibly short."""

from __future__ import annotations

import io
import threading
import time

import httpx
import numpy as np
import pytest
import uvicorn

from curve_vae.geometry import (
    Frame,
    curve_length,
    self_intersects,
    smoothness,
)
from curve_vae.inference.results import curve_metrics
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings

CURVE = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]


def _seeds(curves, count: int = 6) -> list[list]:
    """Seed curves in frames of their own (different places and sizes)."""
    return [(c * (0.5 + i) + 40 * i).tolist() for i, c in enumerate(curves(count, 161))]


# ----------------------------------------------------------------------------- sample


def test_sample_same_seed_same_batch_and_seed_reported(client):
    a = client.post("/sample", json={"count": 4, "seed": 11}).json()
    assert a == client.post("/sample", json={"count": 4, "seed": 11}).json() and a["seed"] == 11
    fresh = client.post("/sample", json={"count": 2}).json()
    again = client.post("/sample", json={"count": 2, "seed": fresh["seed"]}).json()
    assert again == fresh  # the reported seed repeats an unseeded request
    first = client.post("/sample", json={"count": 2, "seed": 11}).json()
    assert first["latents"] == a["latents"][:2]  # a larger count extends a smaller one


def test_standard_prior_latents_follow_the_temperature(client):
    body = {"count": 256, "seed": 0, "temperature": 0.5, "prior": "standard", "valid": False}
    r = client.post("/sample", json=body).json()
    z = np.array(r["latents"])
    assert r["prior"] == "standard" and r["rejected"] == 0
    assert z.shape == (256, 32) and abs(z.std() - 0.5) < 0.02 and abs(z.mean()) < 0.02


def test_sample_into_a_frame(client, runtime):
    body = {"count": 2, "seed": 4, "n_points": 30}
    plane = np.array(client.post("/sample", json=body).json()["curves"])
    framed = np.array(client.post("/sample", json={**body, "frame": {"center": [5, -3], "size": 0.5}}).json()["curves"])
    expected = [Frame(center=(5.0, -3.0), size=0.5).from_model(c, runtime.model_size) for c in plane]
    np.testing.assert_allclose(framed, expected, rtol=1e-12, atol=1e-12)


# ----------------------------------------------------------------------------- augment


@pytest.mark.parametrize("mode,k", [pytest.param("pair", 2, id="pair"), pytest.param("triplet", 3, id="triplet")])
def test_augment_weights_lie_in_the_simplex_and_are_reported(client, curves, runtime, mode, k):
    seeds = _seeds(curves)
    out = client.post("/augment", json={"curves": seeds, "count": 40, "mode": mode, "seed": 2}).json()
    sources, weights = np.array(out["sources"]), np.array(out["weights"])
    assert sources.shape == weights.shape == (40, k)
    assert all(len(set(row)) == k for row in sources.tolist()) and 0 <= sources.min() and sources.max() < len(seeds)
    assert (weights >= 0).all() and (weights <= 1).all()
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, rtol=0, atol=1e-12)
    assert len({tuple(r) for r in weights.round(6).tolist()}) == 40  # drawn, not a grid
    assert len(set(sources[:, 0].tolist())) > 1  # anchors vary
    full = np.zeros((40, len(seeds)))
    np.put_along_axis(full, sources, weights, axis=1)
    expected = runtime.interpolate([np.array(c) for c in seeds], full).curves
    np.testing.assert_allclose(out["curves"], expected, rtol=1e-9, atol=1e-9)  # each curve is its reported mix


def test_augment_same_seed_same_batch(client, curves):
    body = {"curves": _seeds(curves), "count": 8, "mode": "triplet", "seed": 2**53 - 1}
    a = client.post("/augment", json=body).json()
    assert a == client.post("/augment", json=body).json() and a["seed"] == 2**53 - 1
    other = client.post("/augment", json={**body, "seed": 5}).json()
    assert other["sources"] != a["sources"]
    fresh = client.post("/augment", json={**body, "seed": None}).json()
    assert client.post("/augment", json={**body, "seed": fresh["seed"]}).json() == fresh


@pytest.mark.parametrize("page", [1, 3, 4, 12])
def test_pages_are_the_same_whatever_the_page_size(client, curves, page):
    body = {"curves": _seeds(curves), "count": 12, "seed": 9, "n_points": 20}
    whole = client.post("/augment", json=body).json()
    pages = [client.post("/augment", json={**body, "count": page, "offset": o}).json() for o in range(0, 12, page)]
    assert [p["offset"] for p in pages] == list(range(0, 12, page))
    for key in ("sources", "weights", "curves", "frames"):
        assert sum((p[key] for p in pages), []) == whole[key], key


def test_neighbours_restricts_partners_to_the_nearest_in_latent_space(client, curves, runtime):
    seeds = _seeds(curves, 8)
    mean = runtime.encode([np.array(c) for c in seeds], together=True).mean  # seeds are read as one set
    d = np.linalg.norm(mean[:, None] - mean[None], axis=-1)
    np.fill_diagonal(d, np.inf)
    for mode, k in (("pair", 1), ("triplet", 2), ("triplet", 3)):
        out = client.post("/augment", json={"curves": seeds, "count": 60, "mode": mode, "neighbours": k, "seed": 1})
        nearest = np.argsort(d, axis=1)[:, :k]
        for anchor, *partners in out.json()["sources"]:
            assert set(partners) <= set(nearest[anchor].tolist()), (mode, k, anchor, partners)
    wide = client.post("/augment", json={"curves": seeds, "count": 5, "neighbours": 7, "seed": 1}).json()
    assert wide == client.post("/augment", json={"curves": seeds, "count": 5, "seed": 1}).json()  # all = no limit
    too_many = client.post("/augment", json={"curves": seeds, "count": 5, "neighbours": 8, "seed": 1})
    assert too_many.status_code == 422 and too_many.json()["detail"].startswith("neighbours: at most 7")


def test_npy_output_loads_with_numpy_and_equals_the_json_pages(make_client, curves):
    client = make_client(max_curves=8, batch_size=5)  # many chunks; more curves than a JSON response may hold
    body = {"curves": _seeds(curves, 4), "count": 23, "seed": 3, "n_points": 40, "mode": "triplet"}
    r = client.post("/augment", json={**body, "format": "npy"})
    assert r.status_code == 200 and r.headers["content-type"] == "application/octet-stream"
    assert r.headers["content-disposition"] == 'attachment; filename="augment.npy"'
    assert r.headers["x-augment-seed"] == "3" and int(r.headers["content-length"]) == len(r.content)
    batch = np.load(io.BytesIO(r.content), allow_pickle=False)
    assert batch.shape == (23, 40, 2) and batch.dtype == np.float32
    pages = [client.post("/augment", json={**body, "count": min(8, 23 - o), "offset": o}).json() for o in (0, 8, 16)]
    np.testing.assert_array_equal(batch, np.array(sum((p["curves"] for p in pages), []), dtype=np.float32))


def test_npy_length_follows_the_inputs(client):
    r = client.post("/augment", json={"curves": [CURVE, CURVE[::-1]], "count": 3, "seed": 0, "format": "npy"})
    assert np.load(io.BytesIO(r.content)).shape == (3, 7, 2)  # the inputs' common length
    mixed = [CURVE, CURVE[:5]]
    r = client.post("/augment", json={"curves": mixed, "count": 3, "seed": 0, "format": "npy"})
    assert np.load(io.BytesIO(r.content)).shape == (3, 161, 2)  # no common length: the model's


def test_count_limits_per_format(make_client):
    client = make_client(max_curves=4, max_stream_curves=10)
    body = {"curves": [CURVE, CURVE[::-1]], "seed": 0}
    r = client.post("/augment", json={**body, "count": 5})
    assert r.status_code == 422
    assert r.json()["detail"].startswith("count: at most 4, got 5 (format json, CURVE_VAE_MAX_CURVES)")
    assert "offset" in r.json()["detail"]
    assert client.post("/augment", json={**body, "count": 10, "format": "npy"}).status_code == 200
    r = client.post("/augment", json={**body, "count": 11, "format": "npy"})
    assert r.status_code == 422 and "CURVE_VAE_MAX_STREAM_CURVES" in r.json()["detail"]


def test_the_stream_holds_one_chunk_at_a_time(make_client, runtime, monkeypatch):
    """Decoding is asked for batch_size rows at a time, never the whole count."""
    client = make_client(max_stream_curves=10_000)
    seen: list[int] = []
    decode = runtime.graphs.decode
    monkeypatch.setattr(runtime.graphs, "decode", lambda z: seen.append(len(z)) or decode(z))
    r = client.post(
        "/augment",
        # one reading of each seed in one pose: no decoding before the stream's (spacing "auto" decodes to choose)
        json={
            "curves": [CURVE, CURVE[::-1]],
            "count": 1000,
            "format": "npy",
            "seed": 1,
            "pose": "as_is",
            "spacing": "parameter",
            "looks": 0,  # a look decodes the seeds too
        },
    )
    assert r.status_code == 200 and len(r.content) == 128 + 1000 * 7 * 2 * 4
    # a chunk's first decoding is batch_size rows; its mixes that cross themselves are drawn again, fewer at a time
    assert max(seen) == runtime.graphs.batch_size and sum(seen) >= 1000
    assert seen[:1] == [runtime.graphs.batch_size]


# ----------------------------------------------------------------------------- metrics on request


def _expected_metrics(curves) -> list[dict]:
    out = []
    for c in curves:
        c = np.asarray(c)
        sm = smoothness(c)
        out.append(
            {
                "smoothness": {k: float(v) for k, v in sm.items()},
                "self_intersects": bool(self_intersects(c)),
                "length": float(curve_length(c)),
            }
        )
    return out


@pytest.mark.parametrize(
    "path,body",
    [
        pytest.param("/decode", {"latents": [[0.0] * 32, [0.5] * 32]}, id="decode"),
        pytest.param("/reconstruct", {"curves": [CURVE, CURVE[:5]]}, id="reconstruct"),
        pytest.param("/interpolate", {"curves": [CURVE, CURVE[::-1]], "steps": 3}, id="interpolate"),
        pytest.param("/sample", {"count": 3, "seed": 1}, id="sample"),
        pytest.param("/augment", {"curves": [CURVE, CURVE[::-1]], "count": 3, "seed": 1}, id="augment"),
    ],
)
def test_metrics_on_request(client, path, body):
    plain = client.post(path, json=body).json()
    assert "metrics" not in plain
    r = client.post(path, json={**body, "metrics": True})
    assert r.status_code == 200, r.text
    out = r.json()
    assert out["curves"] == plain["curves"]
    expected = _expected_metrics(out["curves"])
    assert len(out["metrics"]) == len(expected) == len(out["curves"])
    for got, want in zip(out["metrics"], expected, strict=True):
        assert got["self_intersects"] is want["self_intersects"]
        assert got["length"] == pytest.approx(want["length"], rel=1e-12)
        assert got["smoothness"] == pytest.approx(want["smoothness"], rel=1e-12)


def test_metrics_measure_what_they_say():
    t = np.linspace(0, np.pi, 50)
    arc = np.stack([np.cos(t), np.sin(t)], axis=1)
    loop = np.array([[0, 0], [2, 0], [2, 2], [1, -1]], float)
    m_arc, m_loop = curve_metrics([arc, loop])
    assert m_arc["smoothness"]["mean_turn"] == pytest.approx(180 / 49, rel=1e-9)
    assert m_arc["smoothness"]["roughness"] < 1e-9 and m_arc["self_intersects"] is False
    assert m_arc["length"] == pytest.approx(np.pi, rel=1e-3)
    assert m_loop["self_intersects"] is True and m_loop["smoothness"]["max_turn"] == pytest.approx(
        180 - np.degrees(np.arctan(1 / 3))
    )


def test_metrics_need_json(client):
    r = client.post("/augment", json={"curves": [CURVE, CURVE], "count": 2, "format": "npy", "metrics": True})
    assert r.status_code == 422 and r.json()["detail"].startswith("metrics: only with format json")


def test_a_stream_that_fails_midway_is_visibly_short(model_dir, monkeypatch):
    """The .npy answer carries its Content-Length: a failure after the first chunk ends the connection early, and
    the client sees an incomplete body, never a silently short file."""
    runtime = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1)
    real, calls = runtime.augment, []

    def failing(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise RuntimeError("the decoder broke down")
        return real(*args, **kwargs)

    monkeypatch.setattr(runtime, "augment", failing)
    config = uvicorn.Config(create_app(Settings(model_dir=model_dir), runtime=runtime), port=0, log_level="critical")
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    try:
        deadline = time.monotonic() + 30
        while not server.started:
            assert time.monotonic() < deadline
            time.sleep(0.05)
        port = server.servers[0].sockets[0].getsockname()[1]
        body = {"curves": [CURVE, CURVE[::-1]], "count": 1000, "format": "npy", "seed": 1}
        with pytest.raises(httpx.RemoteProtocolError, match="incomplete|closed"):
            with httpx.stream("POST", f"http://127.0.0.1:{port}/augment", json=body, timeout=30) as r:
                assert r.status_code == 200 and int(r.headers["content-length"]) == 128 + 1000 * 7 * 2 * 4
                r.read()
    finally:
        server.should_exit = True
        thread.join(timeout=30)
    assert len(calls) == 3


def test_sample_is_reproducible_with_a_seed(client, runtime):
    a = client.post("/sample", json={"count": 3, "seed": 5, "n_points": 50}).json()
    b = client.post("/sample", json={"count": 3, "seed": 5, "n_points": 50}).json()
    c = client.post("/sample", json={"count": 3, "seed": 6, "n_points": 50}).json()
    assert a == b and a["latents"] != c["latents"]
    assert np.shape(a["latents"]) == (3, 32) and np.shape(a["curves"]) == (3, 50, 2)
    np.testing.assert_allclose(a["curves"], runtime.decode(np.array(a["latents"]), n_points=50).curves, rtol=1e-9)
    cold = client.post("/sample", json={"count": 2, "temperature": 0, "prior": "standard", "valid": False}).json()
    assert np.all(np.array(cold["latents"]) == 0)
    cold = client.post("/sample", json={"count": 4, "temperature": 0, "valid": False}).json()  # the learned prior
    for z in cold["latents"]:  # each a component's mean
        assert np.abs(runtime.prior.means - np.array(z)).max(axis=1).min() < 1e-12


@pytest.mark.parametrize("mode,k", [("pair", 2), ("triplet", 3)])
def test_augment(client, curves, runtime, mode, k):
    c = [x * (i + 1) + 10 * i for i, x in enumerate(curves(4, 161))]
    body = {"curves": [x.tolist() for x in c], "count": 6, "mode": mode, "seed": 3}
    out = client.post("/augment", json=body).json()
    assert out == client.post("/augment", json=body).json()  # same seed, same answer
    sources, weights = np.array(out["sources"]), np.array(out["weights"])
    assert sources.shape == weights.shape == (6, k)
    assert all(len(set(row)) == k for row in sources.tolist()) and sources.min() >= 0 and sources.max() < 4
    np.testing.assert_allclose(weights.sum(axis=1), 1.0)
    assert (weights >= 0).all()
    full = np.zeros((6, 4))
    np.put_along_axis(full, sources, weights, axis=1)
    expected = runtime.interpolate(c, full).curves
    np.testing.assert_allclose(out["curves"], expected, rtol=1e-9, atol=1e-9)


C1 = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]


C2 = [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]]


def test_npy_augment_is_points_only(client):
    body = {"curves": [C1, C2], "count": 3, "format": "npy", "output": "both"}
    r = client.post("/augment", json=body)
    assert r.status_code == 422 and r.json()["detail"].startswith('output: only "points" with format npy')
