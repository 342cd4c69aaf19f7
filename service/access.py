"""Optional API keys: with CURVE_VAE_API_KEYS set, every request needs one, except liveness and readiness.

A key comes as `Authorization: Bearer <key>` or `X-API-Key: <key>` and is compared with each
configured key in constant time (hmac.compare_digest, all keys every time), so the answer's
timing tells nothing about how much of a key matched. A missing or wrong key gets a 401 that
says how to send one. The page and the API docs are the package's own static files (no data,
no model): they load without a key, and the page then sends the key the user types in.
"""

from __future__ import annotations

import hmac

from starlette.types import ASGIApp, Receive, Scope, Send

from curve_vae.service.errors import error_response

#: Paths served without a key: probes must work for orchestrators, and the page must load to ask for the key.
OPEN_PATHS = frozenset(
    {"/health", "/ready", "/v2/health/live", "/v2/health/ready", "/", "/docs", "/redoc", "/openapi.json"}
)
OPEN_PREFIXES = ("/static/", "/docs-assets/")


def key_of(headers: dict[bytes, bytes]) -> str | None:
    """The key a request carries, from Authorization: Bearer or X-API-Key; None when it carries none."""
    auth = headers.get(b"authorization", b"").decode("latin-1")
    scheme, _, token = auth.partition(" ")
    if scheme.lower() == "bearer" and token.strip():
        return token.strip()
    key = headers.get(b"x-api-key", b"").decode("latin-1").strip()
    return key or None


def accepted(key: str | None, keys: list[str]) -> bool:
    """Whether `key` is one of `keys`, in time that depends on neither (every key compared, as bytes)."""
    given = (key or "").encode()
    match = False
    for k in keys:
        match |= hmac.compare_digest(given, k.encode())
    return match and bool(key)  # an empty key never opens anything, whatever is configured


class ApiKeyMiddleware:
    def __init__(self, app: ASGIApp, *, keys: list[str]) -> None:
        self.app, self.keys = app, keys

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        path = scope.get("path", "")
        if (
            scope["type"] != "http"
            or scope["method"] == "OPTIONS"  # CORS preflights carry no credentials
            or path in OPEN_PATHS
            or path.startswith(OPEN_PREFIXES)
            or accepted(key_of(dict(scope["headers"])), self.keys)
        ):
            await self.app(scope, receive, send)
            return
        missing = key_of(dict(scope["headers"])) is None
        msg = (
            "this service needs an API key: send Authorization: Bearer <key> or X-API-Key: <key>"
            if missing
            else "the API key is not valid for this service"
        )
        response = error_response(
            401, [("headers.authorization", msg)], detail=msg, headers={"WWW-Authenticate": "Bearer"}, path=path
        )
        await response(scope, receive, send)
