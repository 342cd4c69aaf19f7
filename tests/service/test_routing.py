"""service.routing.model_route: one way to build a route — the handler sees a request already validated and within
every limit (JSON or, with npy, a .npy body), and the OpenAPI operation documents the bodies it takes. Tested on a
small app of its own, so that what the handler receives is observed directly."""

from __future__ import annotations

import io

import numpy as np
import pytest
from fastapi import APIRouter, FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from fastapi.testclient import TestClient

from curve_vae.inference.errors import InputError
from curve_vae.service import schemas as s
from curve_vae.service.errors import on_input_error, on_validation_error
from curve_vae.service.routing import FastJSONRoute, model_route
from curve_vae.service.settings import Settings

CURVE = [[0.0, 0.0], [1.0, 2.0], [2.0, 1.0], [3.0, 0.0]]
NPY_HEADER = {"Content-Type": "application/x-npy"}


@pytest.fixture
def probe():
    """An app with a curve route (JSON or .npy) and a model route (JSON only), recording what each handler got."""
    seen: list[tuple[str, object, list[np.ndarray]]] = []
    router = APIRouter(route_class=FastJSONRoute)

    @model_route(router, "/curves", s.ReconstructRequest, npy=True, examples={"one": {"value": {"curves": [CURVE]}}})
    async def curves(request: Request, req: s.ReconstructRequest, got: list[np.ndarray]) -> Response:
        seen.append(("curves", req, got))
        return JSONResponse({"n": len(got)})

    @model_route(router, "/sample", s.SampleRequest)
    async def sample(request: Request, req: s.SampleRequest, got: list[np.ndarray]) -> Response:
        seen.append(("sample", req, got))
        return JSONResponse({"count": req.count})

    app = FastAPI()
    app.state.settings = Settings(max_curves=2, max_points=50, max_refine_work=1_000)
    app.include_router(router)
    app.add_exception_handler(RequestValidationError, on_validation_error)
    app.add_exception_handler(InputError, on_input_error)
    return TestClient(app), seen


def _npy(a: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, a)
    return buf.getvalue()


def test_the_handler_gets_the_validated_request_and_its_curves_as_arrays(probe):
    client, seen = probe
    r = client.post("/curves", json={"curves": [CURVE, CURVE[::-1]], "pose": "as_is"})
    assert r.status_code == 200 and r.json() == {"n": 2}
    (name, req, got) = seen[-1]
    assert name == "curves" and req.reading().pose == "as_is"
    assert [g.dtype for g in got] == [np.float64, np.float64]
    np.testing.assert_array_equal(got[1], np.asarray(CURVE[::-1]))


def test_a_npy_body_reaches_the_same_handler_with_the_query_fields(probe):
    client, seen = probe
    r = client.post("/curves?pose=as_is", content=_npy(np.asarray([CURVE], np.float32)), headers=NPY_HEADER)
    assert r.status_code == 200 and r.json() == {"n": 1}
    np.testing.assert_array_equal(seen[-1][2][0], np.asarray(CURVE))
    assert seen[-1][1].reading().pose == "as_is"


@pytest.mark.parametrize(
    ("body", "field"),
    [
        pytest.param({"curves": [CURVE] * 3}, "curves", id="too-many-curves"),
        pytest.param({"curves": [CURVE * 13]}, "curves", id="too-many-points"),
        pytest.param({"curves": [CURVE], "refine": 30}, "refine", id="refine-work"),
        pytest.param({"curves": [CURVE], "pose": "sideways"}, "pose", id="schema"),
    ],
)
def test_a_request_beyond_a_limit_never_reaches_the_handler(probe, body, field):
    client, seen = probe
    r = client.post("/curves", json=body)
    assert r.status_code == 422 and field in r.text
    assert seen == []


def test_the_npy_body_is_held_to_the_same_limits(probe):
    client, seen = probe
    three = np.asarray([CURVE] * 3)
    r = client.post("/curves", content=_npy(three), headers=NPY_HEADER)
    assert r.status_code == 422 and "at most 2 curves per request, got 3" in r.text
    r = client.post("/curves?refine=30", content=_npy(three[:1]), headers=NPY_HEADER)
    assert r.status_code == 422 and "CURVE_VAE_MAX_REFINE_WORK" in r.text
    assert seen == []


def test_a_route_without_curves_gets_none_and_its_own_bounds(probe):
    client, seen = probe
    assert client.post("/sample", json={"count": 2}).json() == {"count": 2}
    assert seen[-1][0] == "sample" and seen[-1][2] == []
    r = client.post("/sample", json={"count": 3})
    assert r.status_code == 422 and "count" in r.text and len(seen) == 1


def test_the_operation_documents_the_bodies_each_route_takes(probe):
    client, _ = probe
    paths = client.get("/openapi.json").json()["paths"]
    both = paths["/curves"]["post"]["requestBody"]["content"]
    assert set(both) == {"application/json", "application/x-npy"}
    assert both["application/json"]["examples"] == {"one": {"value": {"curves": [CURVE]}}}
    assert set(paths["/sample"]["post"]["requestBody"]["content"]) == {"application/json"}
