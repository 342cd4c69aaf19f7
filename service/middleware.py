"""The request body limit: 413 before a byte too many is kept."""

from __future__ import annotations

from fastapi.responses import JSONResponse
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from curve_vae.service.errors import error_response

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
