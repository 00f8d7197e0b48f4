"""Dask for a campaign: a loopback-only local cluster, or a checked connection to a trusted one.

Trust model (``docs/campaign.md``, "Running on a cluster")
------------------------------------------------------------
A Dask scheduler and its workers run code in the ``tyredamp campaign``
process: Dask's wire protocol unpickles the objects it marks as pickled
whatever the client allows, so a hostile scheduler or worker can execute
code here. ``--scheduler`` must therefore name a cluster you trust as you
trust your own account. What this module does about the rest:

* the local cluster (``--dask``) listens on 127.0.0.1 only (scheduler,
  workers, nannies) and starts no dashboard;
* ``--scheduler`` accepts ``tcp://`` and ``tls://`` addresses only, parsed
  and refused in one line before any connection; a ``tls://`` scheduler is
  reached with the CA, certificate and key given (mutual TLS through
  :class:`distributed.security.Security`): only a party holding a
  certificate of that CA can then be the scheduler, and the traffic
  (test file paths, settings, results) is encrypted;
* before the Dask client connects, a probe reads the scheduler's greeting
  under a time limit and checks its size and form with plain msgpack (never
  pickle): a port that refuses, a listener that stays silent, an HTTP server
  or any server that is not a Dask scheduler ends in a one-line error instead
  of a hang or a huge read;
* the client decodes task results with msgpack only
  (``deserializers=["msgpack"]``), and every task returns its result as JSON
  bytes that :mod:`.runner` decodes and checks with :mod:`json`: a worker
  cannot return a Python object through the ordinary result path.

What is not protected: over ``tcp://`` anybody on the network path can read
and change the traffic; a worker or scheduler of the cluster (or whoever
controls one) can still run code here through Dask's own messages, read
every test file the workers can read, and send back wrong results.
"""

from __future__ import annotations

import ipaddress
import re
import socket
import ssl
import struct
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..exceptions import InputError

__all__ = [
    "SCHEDULER_SCHEMES",
    "SchedulerAddress",
    "connect_scheduler",
    "local_dask_cluster",
    "parse_scheduler",
    "probe_scheduler",
    "scheduler_security",
]

#: The address schemes ``--scheduler`` accepts.
SCHEDULER_SCHEMES = ("tcp", "tls")
#: The largest greeting a Dask scheduler sends (its handshake is about 100 bytes).
_MAX_GREETING = 1 << 16
_EXAMPLE = "tcp://host:8786 or tls://host:8786"
_HOST = re.compile(r"^[A-Za-z0-9]([A-Za-z0-9-]{0,62})(\.[A-Za-z0-9]([A-Za-z0-9-]{0,62}))*\.?$")


@dataclass(frozen=True)
class SchedulerAddress:
    """A checked scheduler address: ``scheme`` (tcp or tls), ``host`` and ``port``."""

    scheme: str
    host: str
    port: int

    @property
    def url(self) -> str:
        """The address as Dask takes it (IPv6 hosts in brackets)."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{self.scheme}://{host}:{self.port}"


def parse_scheduler(text: str) -> SchedulerAddress:
    """Check a ``--scheduler`` address; only ``tcp://host:port`` and ``tls://host:port``.

    Raises
    ------
    InputError
        Empty, no scheme, another scheme (``ucx://``, ``inproc://`` ...), no
        host, a host that is neither a name nor an IP address, or a port that
        is missing or not in 1-65535; the message says what was expected.
    """
    given = text.strip()
    if not given:
        raise InputError(f"--scheduler: empty address; expected {_EXAMPLE}")
    if any(ord(c) < 33 or ord(c) == 127 for c in given):
        raise InputError(f"--scheduler: {text!r} holds spaces or control characters")
    scheme, sep, rest = given.partition("://")
    if not sep:
        raise InputError(f"--scheduler: {given} has no scheme; expected {_EXAMPLE}")
    if scheme.lower() not in SCHEDULER_SCHEMES:
        raise InputError(
            f"--scheduler: {given}: the scheme {scheme}:// is not supported; expected {_EXAMPLE}"
        )
    m = re.fullmatch(r"\[([0-9A-Fa-f:.]+)\]:(\d{1,5})|([^\[\]:/@?#]+):(\d{1,5})", rest)
    if m is None:
        raise InputError(f"--scheduler: {given}: expected a host and a port, as in {_EXAMPLE}")
    host, port_text = (m.group(1), m.group(2)) if m.group(1) else (m.group(3), m.group(4))
    try:
        ipaddress.ip_address(host)
    except ValueError:
        if not _HOST.match(host) or host.replace(".", "").isdigit():
            raise InputError(
                f"--scheduler: {given}: {host!r} is neither a host name nor an IP address"
            ) from None
    port = int(port_text)
    if not 1 <= port <= 65535:
        raise InputError(f"--scheduler: {given}: port {port} is not in 1-65535")
    return SchedulerAddress(scheme.lower(), host, port)


def _readable(path: str | Path, what: str) -> str:
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{what}: {p} does not exist or is not a file")
    try:
        with open(p, "rb") as fh:
            fh.read(1)
    except OSError as exc:
        raise InputError(f"{what}: cannot read {p} ({exc.strerror})") from None
    return str(p)


def scheduler_security(
    address: SchedulerAddress,
    ca: str | Path | None = None,
    cert: str | Path | None = None,
    key: str | Path | None = None,
) -> Any:
    """The :class:`distributed.security.Security` of a ``tls://`` scheduler (None for tcp).

    ``ca`` is the CA certificate that signed the scheduler's certificate;
    ``cert`` and ``key`` (PEM) are this client's, signed by a CA the cluster
    trusts (the key may be appended to ``cert``). Encryption is required.

    Raises
    ------
    InputError
        TLS files given for a ``tcp://`` address, a ``tls://`` address without
        the CA or the certificate, a file that cannot be read, or files that
        do not form a certificate and its key.
    """
    given = [x for x in (ca, cert, key) if x is not None]
    if address.scheme == "tcp":
        if given:
            raise InputError(
                f"--scheduler: {address.url} is not encrypted but TLS files were given; "
                f"use tls://{address.url.split('://', 1)[1]}"
            )
        return None
    if ca is None or cert is None:
        missing = "--tls-ca" if ca is None else "--tls-cert"
        raise InputError(
            f"--scheduler: {address.url} needs {missing} (the CA that signed the scheduler's "
            "certificate, and this client's certificate and key)"
        )
    from distributed.security import Security

    sec = Security(
        require_encryption=True,
        tls_ca_file=_readable(ca, "--tls-ca"),
        tls_client_cert=_readable(cert, "--tls-cert"),
        tls_client_key=None if key is None else _readable(key, "--tls-key"),
    )
    try:
        sec.get_connection_args("client")
    except (ssl.SSLError, ValueError, OSError) as exc:
        raise InputError(
            f"--tls-cert/--tls-key/--tls-ca: not a usable certificate, key and CA ({exc})"
        ) from None
    return sec


def _open(address: SchedulerAddress, security: Any, timeout: float) -> socket.socket:
    try:
        sock = socket.create_connection((address.host, address.port), timeout=timeout)
    except socket.gaierror as exc:
        raise InputError(
            f"--scheduler: cannot find the host {address.host} ({exc.strerror})"
        ) from None
    except ConnectionRefusedError:
        raise InputError(
            f"--scheduler: {address.url} refused the connection (no scheduler listens there)"
        ) from None
    except TimeoutError:
        raise InputError(
            f"--scheduler: {address.url} did not accept a connection within {timeout:g} s"
        ) from None
    except OSError as exc:
        raise InputError(f"--scheduler: cannot connect to {address.url} ({exc.strerror})") from None
    if security is None:
        return sock
    context = security.get_connection_args("client")["ssl_context"]
    try:
        return context.wrap_socket(sock, server_hostname=address.host)
    except (ssl.SSLError, OSError) as exc:
        sock.close()
        raise InputError(
            f"--scheduler: the TLS handshake with {address.url} failed "
            f"({' '.join(str(exc).split())})"
        ) from None


def _read_exactly(sock: socket.socket, n: int, deadline: float, address: SchedulerAddress) -> bytes:
    buf = b""
    while len(buf) < n:
        left = deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError
        sock.settimeout(left)
        chunk = sock.recv(n - len(buf))
        if not chunk:
            raise InputError(
                f"--scheduler: {address.url} closed the connection without the greeting "
                "of a Dask scheduler"
            )
        buf += chunk
    return buf


def probe_scheduler(address: SchedulerAddress, security: Any = None, timeout: float = 10.0) -> None:
    """Check that a Dask scheduler answers at ``address``, before the Dask client connects.

    A Dask server sends its greeting (the handshake: one msgpack map of a few
    hundred bytes, framed by 8-byte little-endian lengths) as soon as it
    accepts a connection. The probe reads it with a deadline of ``timeout``
    seconds, refuses a frame larger than 64 KiB and decodes it with plain
    msgpack (no extension types, no pickle), then closes the connection.

    Raises
    ------
    InputError
        Unknown host, refused connection, TLS failure, no greeting within
        ``timeout`` (a silent listener, an HTTP server), or a reply that is
        not a Dask greeting.
    """
    import msgpack

    not_dask = f"--scheduler: {address.url} is not a Dask scheduler"
    deadline = time.monotonic() + timeout
    sock = _open(address, security, timeout)
    try:
        (total,) = struct.unpack("<Q", _read_exactly(sock, 8, deadline, address))
        if not 16 <= total <= _MAX_GREETING:
            raise InputError(f"{not_dask} (its first message announces {total} bytes)")
        body = _read_exactly(sock, total, deadline, address)
        (n_frames,) = struct.unpack_from("<Q", body)
        if not 1 <= n_frames <= 64 or 8 * (n_frames + 1) > total:
            raise InputError(f"{not_dask} (its first message is not in Dask's framing)")
        lengths = struct.unpack_from(f"<{n_frames}Q", body, 8)
        start = 8 * (n_frames + 1)
        if sum(lengths) != total - start:
            raise InputError(f"{not_dask} (its first message is not in Dask's framing)")
        greeting = msgpack.unpackb(body[start : start + lengths[0]], raw=False, strict_map_key=True)
        if not isinstance(greeting, dict) or "pickle-protocol" not in greeting:
            raise InputError(f"{not_dask} (its greeting is not Dask's handshake)")
    except TimeoutError:
        raise InputError(
            f"--scheduler: {address.url} sent no Dask greeting within {timeout:g} s "
            "(is it a Dask scheduler? see --connect-timeout)"
        ) from None
    except (ValueError, struct.error, msgpack.UnpackException):
        raise InputError(f"{not_dask} (its greeting cannot be decoded)") from None
    except OSError as exc:
        raise InputError(
            f"--scheduler: the connection to {address.url} failed ({exc.strerror or exc})"
        ) from None
    finally:
        sock.close()


def connect_scheduler(
    address: SchedulerAddress,
    security: Any = None,
    connect_timeout: float = 10.0,
    worker_timeout: float = 60.0,
) -> Any:
    """A ``distributed.Client`` of the trusted cluster at ``address``, with a worker.

    Probes the address first (:func:`probe_scheduler`), connects with
    ``connect_timeout`` seconds, decodes results with msgpack only, and waits
    up to ``worker_timeout`` seconds for at least one worker.

    Raises
    ------
    InputError
        Every failure to reach a working cluster, in one line.
    """
    from distributed import Client

    probe_scheduler(address, security, connect_timeout)
    try:
        client = Client(
            address.url,
            timeout=f"{connect_timeout}s",
            security=security,
            deserializers=["msgpack"],
            set_as_default=False,
        )
    except Exception as exc:  # any failure of the handshake is a failure to connect
        reason = " ".join(str(exc).split())[:300] or type(exc).__name__
        raise InputError(f"--scheduler: cannot connect to {address.url} ({reason})") from None
    try:
        client.wait_for_workers(1, timeout=worker_timeout)
    except Exception:  # TimeoutError, or the scheduler went away while we waited
        client.close()
        raise InputError(
            f"--scheduler: the cluster at {address.url} has no worker after {worker_timeout:g} s "
            "(start workers, or see --worker-timeout)"
        ) from None
    return client


def local_dask_cluster(workers: int) -> tuple[Any, Any]:
    """A new ``LocalCluster`` on 127.0.0.1 only, without dashboard, and its client.

    ``workers`` processes with one thread each. The scheduler, the workers,
    their nannies and the HTTP servers Dask always starts listen on 127.0.0.1
    only, and those HTTP servers answer nothing but their health check (no
    dashboard, no worker list). The workers' statistical profiler is off (it
    samples every thread every 10 ms and costs the tasks CPU on busy cores).
    """
    import logging

    import dask
    from distributed import Client, LocalCluster

    quiet = {
        "distributed.worker.profile.enabled": False,
        # the HTTP servers Dask always starts serve nothing but their health check
        "distributed.scheduler.http.routes": ["distributed.http.health"],
        "distributed.worker.http.routes": ["distributed.http.health"],
    }
    with dask.config.set(quiet):
        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            worker_dashboard_address=None,
            scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
            silence_logs=logging.ERROR,
        )
    return Client(cluster, set_as_default=False), cluster
