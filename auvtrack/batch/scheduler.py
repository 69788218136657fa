"""Connecting to a Dask scheduler given with ``--scheduler``: bounded in time, one line when it fails.

``distributed.Client(address)`` trusts what answers at the address: a closed port is retried for
the configured connect timeout (30 s), an HTTP server (a dashboard address, say) never sends
Dask's handshake and the client waits for minutes, and a service that writes something else
first (an SSH banner) has its first 8 bytes read as a frame length, which NumPy then tries to
allocate (exabytes).  :func:`connect_scheduler` first opens a plain socket with a timeout and
reads the scheduler's handshake header itself: a Dask scheduler writes its handshake as soon
as a connection is accepted (``distributed.comm.core.Listener.on_connection``), framed as an
8-byte length (native byte order) followed by that many bytes (``distributed.comm.tcp.TCP.read``),
a few hundred bytes.  Only then does it open the real client, with a bounded timeout.  Every
failure is a :class:`SchedulerError`: one line naming ``--scheduler``.
"""
from __future__ import annotations

import socket
import struct
from typing import Any

__all__ = ["SchedulerError", "connect_scheduler", "probe_scheduler", "SCHEDULER_TIMEOUT_S", "MAX_HANDSHAKE_BYTES"]

SCHEDULER_TIMEOUT_S = 5.0
"""Seconds allowed for each step of connecting to a scheduler (TCP connect, handshake, client start)."""
MAX_HANDSHAKE_BYTES = 1 << 20
"""Largest handshake frame accepted from a scheduler (Dask's is a few hundred bytes)."""


class SchedulerError(ValueError):
    """The ``--scheduler`` address does not lead to a Dask scheduler: ``str(err)`` is one line naming the option."""


def _host_port(address: str) -> tuple[str, str, int]:
    """(scheme, host, port) of ``tcp://host:port`` (the scheme defaults to tcp)."""
    scheme, _, rest = address.rpartition("://")
    scheme = scheme or "tcp"
    host, sep, port = rest.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise SchedulerError(f"--scheduler: must be an address such as tcp://host:8786 (got {address!r})")
    return scheme, host.strip("[]"), int(port)


def _read_exactly(sock: socket.socket, n: int) -> bytes:
    data = b""
    while len(data) < n:
        part = sock.recv(n - len(data))
        if not part:
            break
        data += part
    return data


def probe_scheduler(address: str, timeout: float = SCHEDULER_TIMEOUT_S) -> None:
    """Check that a Dask scheduler answers at ``address``, within ``timeout`` seconds per step.

    Parameters
    ----------
    address : str
        ``tcp://host:port``, ``tls://host:port`` or ``host:port``.  For a TLS address only the
        TCP connection is checked (the handshake is encrypted); other schemes are not probed.
    timeout : float, optional
        Seconds for the connection and for the handshake each.

    Raises
    ------
    SchedulerError
        Nothing listens there, nothing answers, or what answers is not a Dask scheduler.
    """
    if address.partition("://")[0] not in ("tcp", "tls") and "://" in address:
        return  # inproc://, ucx://, ws://...: left to the client's own bounded timeout
    scheme, host, port = _host_port(address)
    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except socket.gaierror as exc:
        raise SchedulerError(f"--scheduler: {address}: unknown host {host!r} ({exc.strerror})") from None
    except (socket.timeout, TimeoutError):
        raise SchedulerError(f"--scheduler: {address}: no answer within {timeout:g} s "
                             "(is the scheduler running and reachable?)") from None
    except OSError as exc:
        raise SchedulerError(f"--scheduler: {address}: cannot connect ({exc.strerror or exc}); "
                             "is the scheduler running?") from None
    with sock:
        if scheme == "tls":
            return
        sock.settimeout(timeout)
        try:
            head = _read_exactly(sock, 8)
            n = struct.unpack("Q", head)[0] if len(head) == 8 else None
            if n is not None and 0 < n <= MAX_HANDSHAKE_BYTES:
                body = _read_exactly(sock, n)
                if len(body) == n:
                    return
        except (socket.timeout, TimeoutError):
            raise SchedulerError(f"--scheduler: {address}: something answers there but sends no Dask handshake "
                                 f"within {timeout:g} s (an HTTP server or dashboard? the scheduler's address is "
                                 "the one it prints as 'Scheduler at: tcp://...')") from None
        except OSError as exc:
            raise SchedulerError(f"--scheduler: {address}: the connection failed during the handshake "
                                 f"({exc.strerror or exc})") from None
    raise SchedulerError(f"--scheduler: {address}: what answers there is not a Dask scheduler "
                         "(it did not send a Dask handshake)")


def connect_scheduler(address: str, timeout: float = SCHEDULER_TIMEOUT_S) -> Any:
    """A ``distributed.Client`` of the scheduler at ``address``, or one line saying why not.

    Parameters
    ----------
    address : str
        The scheduler's address, as given with ``--scheduler``.
    timeout : float, optional
        Seconds allowed for each step (probe, handshake, client start).

    Returns
    -------
    distributed.Client
        Connected; the caller closes it.

    Raises
    ------
    SchedulerError
        One line naming ``--scheduler``, within a few times ``timeout`` seconds.
    """
    from distributed import Client

    probe_scheduler(address, timeout)
    try:
        return Client(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SchedulerError(f"--scheduler: {address}: could not start a Dask client within {timeout:g} s "
                             f"({' '.join(str(exc).split())[:160]})") from None
