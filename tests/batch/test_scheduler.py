"""``--scheduler``: an address where no Dask scheduler answers is one line naming the option, within seconds.

Fake servers on loopback, each in a thread: one that writes a banner first (as SSH does), an
HTTP server, one that accepts and says nothing, one that sends a frame length and hangs up, and a
closed port.  A real scheduler passes the probe.
"""
from __future__ import annotations

import socket
import struct
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import pytest

from auvtrack.batch.scheduler import SCHEDULER_TIMEOUT_S, SchedulerError, connect_scheduler, probe_scheduler
from auvtrack.cli import main

BOUND_S = 2 * SCHEDULER_TIMEOUT_S + 2  # a connect and a handshake read, each bounded


class _Server:
    """A TCP server on loopback that answers each connection with ``reply(conn)`` in a thread."""

    def __init__(self, reply) -> None:
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.reply, self.conns = reply, []
        self.address = f"tcp://127.0.0.1:{self.sock.getsockname()[1]}"
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.conns.append(conn)
            self.reply(conn)

    def close(self) -> None:
        self.sock.close()
        for c in self.conns:
            c.close()


def _banner(conn):
    conn.sendall(b"SSH-2.0-OpenSSH_9.6p1 Ubuntu-3ubuntu13\r\n")  # its first 8 bytes as a length: ~3 EiB


def _silent(conn):
    pass


def _hang_up(conn):
    conn.sendall(struct.pack("Q", 200) + b"x" * 10)  # a plausible length, then the connection ends
    conn.close()


class _Hello(BaseHTTPRequestHandler):
    def do_GET(self):  # noqa: N802
        self.send_response(200)
        self.end_headers()
        self.wfile.write(b"dashboard")

    def log_message(self, *args):
        pass


@pytest.fixture(params=["banner", "silent", "hang_up", "http", "closed"])
def not_dask(request):
    if request.param == "http":
        http = ThreadingHTTPServer(("127.0.0.1", 0), _Hello)
        threading.Thread(target=http.serve_forever, daemon=True).start()
        yield request.param, f"tcp://127.0.0.1:{http.server_address[1]}"
        http.shutdown()
        http.server_close()
        return
    if request.param == "closed":
        s = socket.socket()
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        s.close()
        yield request.param, f"tcp://127.0.0.1:{port}"
        return
    server = _Server({"banner": _banner, "silent": _silent, "hang_up": _hang_up}[request.param])
    yield request.param, server.address
    server.close()


EXPECT = {"banner": "is not a Dask scheduler", "silent": "sends no Dask handshake", "hang_up": "not a Dask scheduler",
          "http": "sends no Dask handshake", "closed": "cannot connect"}


def test_the_probe_refuses_what_is_not_a_dask_scheduler_within_its_bound(not_dask):
    kind, address = not_dask
    t0 = time.monotonic()
    with pytest.raises(SchedulerError) as info:
        connect_scheduler(address)
    took = time.monotonic() - t0
    msg = str(info.value)
    assert msg.startswith(f"--scheduler: {address}: ") and EXPECT[kind] in msg and "\n" not in msg, msg
    assert took < BOUND_S, took


@pytest.mark.parametrize("address, expect", [("tcp://127.0.0.1", "must be an address such as"),
                                             ("tcp://127.0.0.1:99999", "must be an address such as"),
                                             ("tcp://no-such-host.invalid:8786", "unknown host")])
def test_a_malformed_address_or_unknown_host_is_one_line(address, expect):
    with pytest.raises(SchedulerError, match=expect):
        probe_scheduler(address)


def test_a_real_scheduler_passes():
    from distributed import LocalCluster

    with LocalCluster(n_workers=0, processes=False, protocol="tcp://", dashboard_address=":0") as cluster:
        assert cluster.scheduler_address.startswith("tcp://")
        probe_scheduler(cluster.scheduler_address)
        client = connect_scheduler(cluster.scheduler_address)
        try:
            assert client.scheduler_info()["address"] == cluster.scheduler_address
        finally:
            client.close()


@pytest.mark.parametrize("command", ["sweep", "compare"])
def test_the_commands_exit_2_with_one_line_naming_the_option(command, tmp_path, capsys):
    server = _Server(_banner)
    try:
        if command == "sweep":
            study = tmp_path / "s.toml"
            study.write_text('name = "s"\nset = ["sim.duration=0.2"]\nsamples = 2\n')
            args = ["sweep", str(study)]
        else:
            args = ["compare", "--quick", "--controllers", "ftsmc"]
        t0 = time.monotonic()
        code = main([*args, "--scheduler", server.address, "--out", str(tmp_path / "o"), "--quiet"])
        took = time.monotonic() - t0
    finally:
        server.close()
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"auvtrack: error: --scheduler: {server.address}: what answers there is not a Dask "), err
    assert not (tmp_path / "o").exists()  # nothing written
    print(f"{command}: refused in {took:.1f} s (loading the study or suite included)")
