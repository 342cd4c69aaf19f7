"""curve_vae.client.errors: an answer that is not a success, whatever its body, becomes one ApiError with the
service's status, the field it names, what it said there and every problem it listed."""

from __future__ import annotations

import json

import pytest

from curve_vae.client.errors import ApiError, RetriesExhausted
from curve_vae.errors import ClientError

BODY = {
    "detail": "curves[0][1][1]: not a finite number",
    "errors": [
        {"loc": "curves[0][1][1]", "msg": "not a finite number"},
        {"loc": "curves[2]", "msg": "a curve needs at least 4 points, got 3"},
    ],
}


def test_the_services_error_body_gives_status_field_message_and_all_problems():
    e = ApiError.from_response(422, json.dumps(BODY).encode())
    assert (e.status, e.loc, e.msg, e.detail) == (422, "curves[0][1][1]", "not a finite number", BODY["detail"])
    assert e.errors == BODY["errors"] and str(e) == "422: curves[0][1][1]: not a finite number"


@pytest.mark.parametrize(
    ("status", "body", "detail"),
    [
        pytest.param(401, b'{"detail": "missing API key"}', "missing API key", id="detail-alone"),
        pytest.param(400, b'{"error": "unknown model curve_vae_x"}', "unknown model curve_vae_x", id="oip-error"),
        pytest.param(502, b"<html>Bad Gateway</html>", "<html>Bad Gateway</html>", id="a-proxys-page"),
        pytest.param(504, b"", "HTTP 504", id="empty"),
        pytest.param(500, b"[1, 2]", "HTTP 500", id="json-not-an-object"),
        pytest.param(404, b'{"detail": ""}', "HTTP 404", id="empty-detail"),
    ],
)
def test_any_other_body_is_one_line_naming_what_it_can(status, body, detail):
    e = ApiError.from_response(status, body)
    assert (e.status, e.detail, e.loc, e.msg, e.errors) == (status, detail, "", detail, [])
    assert str(e) == f"{status}: {detail}"


def test_a_long_page_is_cut_to_500_characters():
    e = ApiError.from_response(502, b"x" * 2000)
    assert e.detail == "x" * 500


def test_both_are_client_errors_and_runtime_errors():
    assert issubclass(RetriesExhausted, ApiError) and issubclass(ApiError, ClientError)
    with pytest.raises(RuntimeError, match="503: busy"):
        raise RetriesExhausted(503, "busy")
