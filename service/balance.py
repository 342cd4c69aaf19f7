"""Connections kept shared out evenly among `--workers` processes, however few clients there are.

Linux hands each new connection to one of the workers' SO_REUSEPORT sockets by a hash of its addresses
(service.listeners), and a keep-alive client stays where it landed. With many connections that evens out; with few
it often does not: two clients posting 128-curve batches land on one worker half the time, and that worker then
serves both while the other idles (bench.serve's run A: 145 curves/s against 186 when they are apart). So each
worker publishes how many connections it holds (a small file per worker in a directory the server makes: the count
and the worker's start time, so that a dead worker's pid used again by another process is not taken for it), and a
worker holding at least REBALANCE_MARGIN more than the least-loaded other one answers with `Connection: close`:
the client connects again, and the kernel deals the new connection afresh. Nothing is refused and no request is
lost; a client pays one reconnect (loopback: well under a millisecond) each time it is moved, and the moves stop
once no worker holds two more than another.
"""

from __future__ import annotations

import atexit
import contextlib
import mmap
import os
import socket
import struct
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from starlette.types import ASGIApp, Message, Receive, Scope, Send

#: The environment variable naming the workers' directory (made by service.server for its workers; internal).
BALANCE_DIR = "CURVE_VAE_BALANCE_DIR"
#: A worker moves a connection when it holds at least this many more than the least-loaded other worker.
REBALANCE_MARGIN = 2
#: How often a worker looks for workers started or gone since (seconds); their counts it reads on every response.
RESCAN_S = 1.0
#: How often a worker counts the connections it holds from its sockets (seconds): a connection its client closed
#: leaves the count within this (one it opens is counted at its first request, one it is asked to close at once).
RECOUNT_S = 0.25
_SLOT = struct.Struct("<qq")  # the worker's open connections, and its start time (/proc/PID/stat, clock ticks)
_SUFFIX = ".connections"


class Peers:
    """This worker's published connection count, and the other workers' as they publish theirs."""

    def __init__(self, directory: str | Path, *, pid: int | None = None) -> None:
        self.dir = Path(directory)
        self.pid = os.getpid() if pid is None else pid
        self.path = self.dir / f"{self.pid}{_SUFFIX}"
        fd, tmp = tempfile.mkstemp(dir=self.dir, prefix=".new-")  # whole before it appears under its name
        try:
            os.write(fd, _SLOT.pack(0, _start_time(self.pid) or 0))
            self._map = mmap.mmap(fd, _SLOT.size)
            os.replace(tmp, self.path)
        finally:
            os.close(fd)
        self.mine = 0
        self._others: dict[int, mmap.mmap] = {}
        self._scanned = -float("inf")
        self.on_count: Callable[[int], None] | None = None  # told each new count (the /metrics gauge)

    def publish(self, count: int) -> None:
        self.mine = count
        struct.pack_into("<q", self._map, 0, count)
        if self.on_count is not None:
            self.on_count(count)

    def others(self) -> dict[int, int]:
        """The other live workers' connection counts, by pid."""
        now = time.monotonic()
        if now - self._scanned > RESCAN_S:
            self._rescan()
            self._scanned = now
        return {pid: _SLOT.unpack_from(m, 0)[0] for pid, m in self._others.items()}

    def crowded(self) -> bool:
        """Whether this worker holds REBALANCE_MARGIN or more connections beyond the least-loaded other worker."""
        if self.mine < REBALANCE_MARGIN:
            return False
        counts = self.others()
        return bool(counts) and self.mine >= min(counts.values()) + REBALANCE_MARGIN

    def _rescan(self) -> None:
        seen: dict[int, mmap.mmap] = {}
        with os.scandir(self.dir) as entries:
            for entry in entries:
                stem = entry.name.removesuffix(_SUFFIX)
                if stem == entry.name or not stem.isdigit() or int(stem) == self.pid:
                    continue
                pid = int(stem)
                slot = self._others.pop(pid, None)
                if slot is None:
                    with contextlib.suppress(OSError, ValueError), open(entry.path, "rb") as fh:
                        slot = mmap.mmap(fh.fileno(), _SLOT.size, access=mmap.ACCESS_READ)
                if slot is None:
                    continue
                if _start_time(pid) != _SLOT.unpack_from(slot, 0)[1]:  # killed outright, its pid gone or another's
                    slot.close()
                    with contextlib.suppress(OSError):
                        os.unlink(entry.path)  # nobody else removes its file
                    continue
                seen[pid] = slot
        for gone in self._others.values():
            gone.close()
        self._others = seen

    def close(self) -> None:
        """This worker stopping: its file goes, so that the others stop counting it."""
        with contextlib.suppress(OSError):
            os.unlink(self.path)
        for m in self._others.values():
            m.close()
        self._others = {}


def _start_time(pid: int) -> int | None:
    """When process `pid` started (clock ticks since boot, /proc/PID/stat's 22nd field), or None where there is no such
    process or it has exited (a zombie): a pid used again by a later process has another start time."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return None
    return None if fields[0] in ("Z", "X") else int(fields[19])


#: This worker's Peers (`join`), which its connections report to.
_peers: Peers | None = None


def join() -> Peers | None:
    """This worker's Peers in the directory BALANCE_DIR names (None where it is unset: one process, or a platform
    where the workers share one socket)."""
    global _peers
    directory = os.environ.get(BALANCE_DIR)
    if directory and _peers is None:
        _peers = Peers(directory)
    return _peers


def leave() -> None:
    global _peers
    if _peers is not None:
        _peers.close()
        _peers = None


Client = tuple[str, int]


class Connections:
    """The connections this worker holds, as the clients' addresses, told to `peers` as they change: a client is
    counted at its first request and uncounted once asked to reconnect; every RECOUNT_S the worker's own sockets
    say which connections are still open (`held`), so that one its client closed is uncounted too. The count comes
    from the operating system and the ASGI scope only, whatever server runs the app."""

    def __init__(self, peers: Peers) -> None:
        self.peers, self.port = peers, 0
        self.clients: set[Client] = set()
        self.leaving: set[Client] = set()  # asked to reconnect, perhaps not yet gone
        self._lock = threading.Lock()

    def seen(self, scope: Scope) -> None:
        client, server = scope.get("client"), scope.get("server")
        if client is None or server is None:
            return
        self.port = server[1]
        key = (client[0], client[1])
        if key not in self.clients:
            with self._lock:
                self.clients.add(key)
                self.peers.publish(len(self.clients))

    def closing(self, scope: Scope) -> None:
        client = scope.get("client")
        if client is None:
            return
        with self._lock:
            self.clients.discard((client[0], client[1]))
            self.leaving.add((client[0], client[1]))
            self.peers.publish(len(self.clients))

    def recount(self) -> None:
        """Keep the clients whose connection is still open (and any the sockets show that sent nothing yet)."""
        if not self.port:
            return
        open_now = held(self.port)
        with self._lock:
            self.leaving &= open_now
            self.clients = open_now - self.leaving
            self.peers.publish(len(self.clients))

    def watch(self) -> None:
        """Recount every RECOUNT_S, on a daemon thread, for the worker's life."""

        def loop() -> None:
            while True:
                time.sleep(RECOUNT_S)
                with contextlib.suppress(Exception):  # a count missed is taken again next time
                    self.recount()

        threading.Thread(target=loop, name="connection-count", daemon=True).start()


def held(port: int) -> set[Client]:
    """The peers of this process's connected TCP sockets on local port `port` (its accepted connections), from its
    open file descriptors: about 25 µs a socket."""
    peers: set[Client] = set()
    for name in os.listdir("/proc/self/fd"):
        try:
            if not os.readlink(f"/proc/self/fd/{name}").startswith("socket:"):
                continue
            with socket.socket(fileno=os.dup(int(name))) as sock:
                if sock.type != socket.SOCK_STREAM or sock.family not in (socket.AF_INET, socket.AF_INET6):
                    continue
                if sock.getsockname()[1] != port or sock.getsockopt(socket.SOL_SOCKET, socket.SO_ACCEPTCONN):
                    continue
                peer = sock.getpeername()
        except OSError:  # closed meanwhile, not connected, not ours to read
            continue
        peers.add((peer[0], peer[1]))
    return peers


class Rebalance:
    """Pure ASGI: a response from a crowded worker (Peers.crowded) says `Connection: close`, so that its client
    connects again and the kernel deals the connection afresh; `on_move` is told each time. With `connections`,
    each request's client is counted, and a client asked to reconnect uncounted."""

    def __init__(
        self,
        app: ASGIApp,
        peers: Peers,
        on_move: Callable[[], None] | None = None,
        connections: Connections | None = None,
    ) -> None:
        self.app, self.peers, self.on_move, self.connections = app, peers, on_move, connections

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        if self.connections is not None:
            self.connections.seen(scope)

        async def sending(message: Message) -> None:
            if message["type"] == "http.response.start" and self._crowded():
                headers = list(message.get("headers", []))
                if not any(name.lower() == b"connection" for name, _ in headers):
                    message = {**message, "headers": [*headers, (b"connection", b"close")]}
                    if self.connections is not None:
                        self.connections.closing(scope)
                    if self.on_move is not None:
                        self.on_move()
            await send(message)

        await self.app(scope, receive, sending)

    def _crowded(self) -> bool:
        """Peers.crowded, by this worker's count as its sockets tell it now, where that count could move a client."""
        if not self.peers.crowded():
            return False
        if self.connections is not None:
            self.connections.recount()  # a client that closed its connection since the last recount is gone
        return self.peers.crowded()


def balanced(app: Any, metrics: Any) -> Any:
    """A worker's app (service.server.supervised_app): wrapped in Rebalance where the server keeps counts, its
    counts and moves in `metrics` (curve_vae_open_connections, curve_vae_connections_moved); as it is elsewhere."""
    peers = join()
    if peers is None:
        return app
    atexit.register(leave)
    peers.on_count = metrics.open_connections.set
    connections = Connections(peers)
    connections.watch()
    return Rebalance(app, peers, metrics.connections_moved.inc, connections)
