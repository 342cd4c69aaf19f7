"""What a request passes on its way to a route, each an ASGI middleware the app adds (service.app): the body limit
(413 before a byte too many is kept), calls from other origins (CORS), and API keys. One section each, below."""

from __future__ import annotations

import hmac

from fastapi import FastAPI
from fastapi.middleware.cors import CORSMiddleware
from fastapi.responses import JSONResponse
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from curve_vae.service.errors import error_response
from curve_vae.service.settings import Settings

#: How much of an oversized body is read and thrown away before the 413 goes out, as a multiple of the limit (and
#: at least DRAIN_MIN bytes). Clients that send the whole body before reading the answer (Python's urllib, most
#: scripts) would otherwise meet a reset connection instead of the 413; a body beyond this is cut off.
DRAIN_FACTOR, DRAIN_MIN = 8, 64 << 20


class BodyLimitMiddleware:
    """413 for bodies over the limit: by Content-Length, or once a streamed body passes it. Nothing of it is kept;
    the rest of it is read and dropped (up to a bound) so the client is listening when the answer comes, except
    where the client waits for `100 Continue` before sending (curl), which then never sends it."""

    def __init__(self, app: ASGIApp, *, max_body_bytes: int) -> None:
        self.app, self.limit = app, max_body_bytes
        self.drain = max(DRAIN_FACTOR * max_body_bytes, DRAIN_MIN)

    async def _refuse(self, size: str, scope: Scope, receive: Receive, send: Send, *, drain: bool) -> None:
        read, more = 0, drain
        while more and read <= self.drain:
            message = await receive()
            if message["type"] != "http.request":
                return  # the client went away: nobody to answer
            read += len(message.get("body", b""))
            more = message.get("more_body", False)
        await self._too_large(size, scope.get("path", ""))(scope, receive, send)

    def _too_large(self, size: str, path: str) -> JSONResponse:
        return error_response(
            413, [("body", f"{size} exceeds the limit of {self.limit} bytes (CURVE_VAE_MAX_BODY_BYTES)")], path=path
        )

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = dict(scope["headers"])
        declared = headers.get(b"content-length", b"")
        if declared.isdigit() and int(declared) > self.limit:  # refuse before keeping a byte of it
            waits = headers.get(b"expect", b"").lower() == b"100-continue"
            await self._refuse(f"a body of {int(declared)} bytes", scope, receive, send, drain=not waits)
            return
        # Read the whole body (it is small: bounded by the limit) and replay it to the app.
        chunks, size, more = [], 0, True
        while more:
            message = await receive()
            if message["type"] != "http.request":  # client went away
                await self.app(scope, _replay([message], receive), send)
                return
            chunks.append(message.get("body", b""))
            size += len(chunks[-1])
            more = message.get("more_body", False)
            if size > self.limit:
                chunks.clear()
                await self._refuse(f"a streamed body of at least {size} bytes", scope, receive, send, drain=more)
                return
        await self.app(
            scope, _replay([{"type": "http.request", "body": b"".join(chunks), "more_body": False}], receive), send
        )


def _replay(messages: list[Message], receive: Receive) -> Receive:
    async def replayed() -> Message:
        return messages.pop(0) if messages else await receive()

    return replayed


# Calls from pages on other origins (CORS): starlette's CORSMiddleware for the origins the settings allow, and for
# any other origin's preflight a 403 whose body says how to allow it (a preflight the service cannot answer would
# otherwise meet a bare 405 from the routes, or starlette's plain-text 400).

#: What a page on another origin needs to read (the .npy seed, the mesh counts, download names).
EXPOSED = ["X-Augment-Seed", "X-Mesh-Vertices", "X-Mesh-Faces", "X-Mesh-Closed", "Content-Disposition"]


class CorsRefusalMiddleware:
    """403 for the preflight (OPTIONS with Origin and Access-Control-Request-Method) of an origin not allowed."""

    def __init__(self, app: ASGIApp, *, origins: list[str]) -> None:
        self.app, self.origins = app, origins

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] == "http" and scope["method"] == "OPTIONS":
            headers = dict(scope["headers"])
            origin = headers.get(b"origin", b"").decode("latin-1")
            if origin and b"access-control-request-method" in headers and not self.allows(origin):
                await self.refusal(origin, scope.get("path", ""))(scope, receive, send)
                return
        await self.app(scope, receive, send)

    def allows(self, origin: str) -> bool:
        return "*" in self.origins or origin in self.origins

    def refusal(self, origin: str, path: str):
        now = f"the server allows {', '.join(self.origins)}" if self.origins else "the server allows no other origin"
        wanted = ",".join([*self.origins, origin])
        msg = (
            f"calls from {origin} are not allowed ({now}): start it with --cors-origins {wanted} "
            f"or CURVE_VAE_CORS_ORIGINS={wanted}"
        )
        return error_response(403, [("origin", msg)], path=path)


def add_cors(app: FastAPI, settings: Settings) -> None:
    """CORS headers for the settings' origins; a preflight from any other origin gets the 403 that says how."""
    if settings.cors_origins:
        app.add_middleware(
            CORSMiddleware,
            allow_origins=settings.cors_origins,
            allow_methods=["GET", "POST"],
            allow_headers=["Content-Type", "Authorization", "X-API-Key"],
            expose_headers=EXPOSED,
            max_age=600,
        )
    app.add_middleware(CorsRefusalMiddleware, origins=settings.cors_origins)  # outside: refused before CORS


# Optional API keys: with CURVE_VAE_API_KEYS set, every request needs one, except liveness and readiness.
#
# A key comes as `Authorization: Bearer <key>` or `X-API-Key: <key>` and is compared with each
# configured key in constant time (hmac.compare_digest, all keys every time), so the answer's
# timing tells nothing about how much of a key matched. A missing or wrong key gets a 401 that
# says how to send one. The page and the API docs are the package's own static files (no data,
# no model): they load without a key, and the page then sends the key the user types in.
#

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
