"""Calls from pages on other origins (CORS): starlette's CORSMiddleware for the origins the settings allow, and for
any other origin's preflight a 403 whose body says how to allow it (a preflight the service cannot answer would
otherwise meet a bare 405 from the routes, or starlette's plain-text 400)."""

from __future__ import annotations

from fastapi import FastAPI
from fastapi.middleware.cors import CORSMiddleware
from starlette.types import ASGIApp, Receive, Scope, Send

from curve_vae.service.errors import error_response
from curve_vae.service.settings import Settings

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
