"""The one error a client call raises when the service says no: its status, the field it names, and what it said."""

from __future__ import annotations

from typing import Any

from curve_vae.errors import ClientError


class ApiError(ClientError):
    """An answer that is not a success: `status` (HTTP), `loc` (the field, curve and point, e.g. `curves[2][17][1]`;
    "" where the service named none), `msg` (what is wrong there), `detail` (the service's one line) and `errors`
    (every problem it found). A 4xx is never retried: the same request gets the same answer."""

    def __init__(self, status: int, detail: str, errors: list[dict[str, Any]] | None = None) -> None:
        self.status = status
        self.detail = detail
        self.errors = errors or []
        first = self.errors[0] if self.errors else {}
        self.loc = str(first.get("loc", ""))
        self.msg = str(first.get("msg", detail))
        super().__init__(f"{status}: {detail}")

    @classmethod
    def from_response(cls, status: int, body: bytes) -> ApiError:
        import json

        try:
            data = json.loads(body)
        except ValueError:
            return cls(status, body.decode(errors="replace")[:500] or f"HTTP {status}")
        if isinstance(data, dict):
            detail = data.get("detail", data.get("error", ""))
            return cls(status, str(detail) if detail else f"HTTP {status}", data.get("errors"))
        return cls(status, f"HTTP {status}")


class RetriesExhausted(ApiError):
    """A call that kept failing in a retryable way (a dropped connection, 503, 429) until the client gave up."""
