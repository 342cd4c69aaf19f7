"""The listening sockets of `curve-vae serve --workers N`: one per worker, all in one SO_REUSEPORT group (Linux).

uvicorn's supervisor binds one socket and every worker accepts from it. The worker that wakes first takes every
connection then waiting, and a keep-alive client (a load balancer's pool, wrk) stays with the worker it reached:
in bench.serve's `workers` run, one of two workers did all the work (19.9 CPU-seconds against 0.1) and the second
process bought nothing. The service's default reading holds the GIL for most of a request, so a second process is
the way past one core's worth of Python; it must get its share of the connections.

So the parent keeps only a reservation, a socket bound to the address with SO_REUSEPORT but never listening (it
holds the port, and learns the one port 0 picked), and hands uvicorn's supervisor a `PerWorkerListener` in place
of a socket. Pickled into each worker it starts (and each it restarts), that becomes a socket of the worker's own,
bound to the same address in the same group, and Linux shares new connections out among the group's listening
sockets by their address hash. Elsewhere (no SO_REUSEPORT load balancing) uvicorn's shared socket stays.
"""

from __future__ import annotations

import logging
import socket
import sys
from typing import Any

log = logging.getLogger("uvicorn.error")


def balances_connections() -> bool:
    """Whether this platform shares connections out among SO_REUSEPORT listeners (Linux does; macOS and the BSDs
    bind them all but send every connection to one)."""
    return sys.platform.startswith("linux") and hasattr(socket, "SO_REUSEPORT")


def _family(host: str) -> socket.AddressFamily:
    return socket.AF_INET6 if ":" in host else socket.AF_INET


def _bound(family: socket.AddressFamily, address: tuple[Any, ...]) -> socket.socket:
    # IPPROTO_TCP, not 0: asyncio sets TCP_NODELAY only on accepted sockets that say they are TCP (uvicorn #3149)
    sock = socket.socket(family, socket.SOCK_STREAM, socket.IPPROTO_TCP)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        sock.bind(address)
    except BaseException:
        sock.close()
        raise
    return sock


class PerWorkerListener:
    """What the parent hands uvicorn's supervisor for its socket: a reservation of the address, which each worker
    unpickles into a socket of its own on that address, which uvicorn's `create_server(sock=…)` makes listen."""

    def __init__(self, host: str, port: int) -> None:
        self.family = _family(host)
        if port:  # SO_REUSEPORT would join another server's group on this port (same user): refuse, as one socket does
            with socket.socket(self.family, socket.SOCK_STREAM, socket.IPPROTO_TCP) as probe:
                probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                probe.bind((host, port))
        self.reservation = _bound(self.family, (host, port))  # bound, never listening: it takes no connections
        self.address = self.reservation.getsockname()

    @property
    def port(self) -> int:
        return int(self.address[1])

    def close(self) -> None:
        self.reservation.close()

    def __reduce__(self) -> tuple[Any, ...]:
        return _bound, (self.family, self.address)


def announce(host: str, port: int) -> None:
    """uvicorn's "running on" line, which its own socket binding would have logged."""
    shown = f"[{host}]" if ":" in host else host
    log.info("Uvicorn running on http://%s:%d (Press CTRL+C to quit)", shown, port)
    log.info("Each worker listens on its own SO_REUSEPORT socket: connections are shared out among them")
