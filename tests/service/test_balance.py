"""service.balance: workers publish their open connections, and one holding two or more beyond another asks a client
to connect again (`Connection: close`), so that few keep-alive clients end up shared out evenly."""

from __future__ import annotations

import http.client
import os
import re
import socket
import struct
import subprocess
import sys
import time

import pytest
from starlette.applications import Starlette
from starlette.responses import PlainTextResponse
from starlette.routing import Route
from starlette.testclient import TestClient

from curve_vae.service import balance
from curve_vae.service.balance import REBALANCE_MARGIN, RECOUNT_S, Peers, Rebalance


def _finished_pid() -> int:
    """The pid of a process that has exited (and been reaped)."""
    proc = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(proc.stdout)


def test_workers_read_each_others_counts(tmp_path):
    mine, other = Peers(tmp_path), Peers(tmp_path, pid=os.getppid())  # another live process's slot
    mine.publish(1)
    other.publish(1 + REBALANCE_MARGIN)
    assert mine.others() == {os.getppid(): 1 + REBALANCE_MARGIN}
    assert other.others() == {os.getpid(): 1}
    assert other.crowded() and not mine.crowded()
    other.publish(REBALANCE_MARGIN)  # one more than the other: moving one would only swap them
    assert not other.crowded()
    mine.publish(REBALANCE_MARGIN + 1)  # counts are read afresh on every look, not only at a rescan
    assert not mine.crowded()  # 3 against 2
    mine.publish(2 * REBALANCE_MARGIN)
    assert mine.crowded()  # 4 against 2


def test_a_lone_worker_is_never_crowded(tmp_path):
    alone = Peers(tmp_path)
    alone.publish(50)
    assert alone.others() == {} and not alone.crowded()


def test_a_worker_killed_outright_is_not_counted_and_its_file_goes(tmp_path, monkeypatch):
    monkeypatch.setattr(balance, "RESCAN_S", 0.0)
    dead = Peers(tmp_path, pid=_finished_pid())  # as a worker SIGKILLed would leave it: its file, no process
    dead.publish(0)
    mine = Peers(tmp_path)
    mine.publish(10)
    assert mine.others() == {} and not mine.crowded()
    assert not dead.path.exists()


def test_a_dead_workers_pid_used_again_by_another_process_is_not_taken_for_it(tmp_path, monkeypatch):
    """The file names a pid that is alive, but the process there started at another time than the worker that wrote
    it (its start time is in the file): not a worker, not counted, its file removed."""
    monkeypatch.setattr(balance, "RESCAN_S", 0.0)
    other = Peers(tmp_path, pid=os.getppid())
    other.publish(0)
    mine = Peers(tmp_path)
    mine.publish(10)
    assert mine.others() == {os.getppid(): 0}  # the real start time: a worker
    struct.pack_into("<q", other._map, 8, balance._start_time(os.getppid()) - 1)  # as an earlier process's
    other._map.flush()
    assert mine.others() == {} and not mine.crowded()
    assert not other.path.exists()


def test_workers_started_later_are_found_and_stopped_ones_forgotten(tmp_path, monkeypatch):
    monkeypatch.setattr(balance, "RESCAN_S", 0.0)
    mine = Peers(tmp_path)
    assert mine.others() == {}
    later = Peers(tmp_path, pid=os.getppid())
    later.publish(4)
    assert mine.others() == {os.getppid(): 4}
    later.close()
    assert not later.path.exists() and mine.others() == {}
    assert sorted(p.name for p in tmp_path.iterdir()) == [mine.path.name]  # no temporary files left behind


class _Crowded:
    def __init__(self, crowded: bool) -> None:
        self.value = crowded

    def crowded(self) -> bool:
        return self.value


def _app(headers: dict[str, str] | None = None) -> Starlette:
    return Starlette(routes=[Route("/", lambda _: PlainTextResponse("ok", headers=headers))])


@pytest.mark.parametrize("crowded", [False, True])
def test_a_crowded_worker_asks_its_client_to_connect_again(crowded):
    moves: list[int] = []
    app = Rebalance(_app(), _Crowded(crowded), lambda: moves.append(1))  # type: ignore[arg-type]
    r = TestClient(app).get("/")
    assert r.status_code == 200 and r.text == "ok"  # the answer itself is untouched
    assert (r.headers.get("connection") == "close") is crowded
    assert moves == ([1] if crowded else [])


def test_a_response_that_names_its_connection_keeps_its_header():
    moves: list[int] = []
    app = Rebalance(_app({"Connection": "keep-alive"}), _Crowded(True), lambda: moves.append(1))  # type: ignore[arg-type]
    r = TestClient(app).get("/")
    assert r.headers.get_list("connection") == ["keep-alive"] and moves == []


def _per_worker(metrics: str) -> dict[str, float]:
    return {
        pid: float(v) for pid, v in re.findall(r'^curve_vae_open_connections\{pid="(\d+)"\} ([\d.]+)$', metrics, re.M)
    }


def test_few_keep_alive_clients_end_up_shared_out_evenly(server_factory, model_dir):
    """Eight keep-alive connections to two workers, in two waves: the kernel's hash alone leaves them four and four
    27% of the time; with the moves, every wave ends four and four (a client reconnects when it is told to)."""
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--workers", "2")
    server.wait_ready(listeners=2)
    time.sleep(2 * RECOUNT_S)  # wait_ready's connections, closed, leave the counts (and /metrics) within RECOUNT_S
    moved = 0
    for wave in range(2):
        conns = [http.client.HTTPConnection("127.0.0.1", server.port, timeout=30) for _ in range(8)]
        for c in conns:
            c.connect()
        settled = 0
        for _ in range(100):  # rounds of one request a connection, until two rounds move nobody
            moves = 0
            for k, c in enumerate(conns):
                c.request("GET", "/health")
                r = c.getresponse()
                assert r.status == 200 and r.read() == b'{"status":"ok"}'
                if r.getheader("connection") == "close":
                    c.close()
                    conns[k] = http.client.HTTPConnection("127.0.0.1", server.port, timeout=30)
                    conns[k].connect()
                    moves += 1
            moved += moves
            settled = settled + 1 if moves == 0 else 0
            if settled == 2:
                break
        conns[0].request("GET", "/metrics")
        r = conns[0].getresponse()
        counts = _per_worker(r.read().decode())
        assert sorted(counts.values()) == [4.0, 4.0], (wave, counts)
        for c in conns:
            c.close()
        time.sleep(2 * RECOUNT_S)  # a connection its client closed leaves the count within RECOUNT_S
    conns = [http.client.HTTPConnection("127.0.0.1", server.port, timeout=30)]
    conns[0].request("GET", "/metrics")
    total = re.search(r"^curve_vae_connections_moved_total ([\d.]+)$", conns[0].getresponse().read().decode(), re.M)
    assert total is not None and float(total.group(1)) == moved
    assert server.stop() == 0


def test_a_worker_counts_the_connections_its_sockets_hold(tmp_path):
    """balance.held reads the process's own accepted sockets on the port; Connections counts a client at its first
    request, uncounts one asked to reconnect at once, and one whose connection is gone at the next recount."""
    with socket.create_server(("127.0.0.1", 0)) as listening:
        port = listening.getsockname()[1]
        clients = [socket.create_connection(("127.0.0.1", port)) for _ in range(3)]
        accepted = [listening.accept()[0] for _ in clients]
        try:
            assert balance.held(port) == {c.getsockname() for c in clients}
            peers = Peers(tmp_path)
            connections = balance.Connections(peers)
            scopes = [{"client": c.getsockname(), "server": ("127.0.0.1", port)} for c in clients]
            for scope in scopes + scopes:  # a second request on a connection counts it once
                connections.seen(scope)
            assert peers.mine == 3
            connections.closing(scopes[0])
            assert peers.mine == 2
            connections.recount()  # still open: asked to leave, it is not counted again
            assert peers.mine == 2
            accepted[1].close()  # the server side of a connection its client closed
            connections.recount()
            assert peers.mine == 1 and connections.clients == {clients[2].getsockname()}
        finally:
            for s in clients + accepted:
                s.close()
