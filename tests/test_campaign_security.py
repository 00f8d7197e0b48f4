"""What a campaign exposes on the network, and a campaign over TLS.

* The local process pool (the default) opens no port; a local Dask cluster
  (``--dask``) listens on loopback addresses only and starts no dashboard.
* A campaign runs on a scheduler secured with mutual TLS (a CA and a
  certificate made here with ``cryptography``) and gives the serial results;
  a client with the wrong CA, or a ``tcp://`` address for the TLS port, ends
  in one line; so does a scheduler without workers.
"""

from __future__ import annotations

import datetime
import ipaddress
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import psutil
import pytest

from tyredamp.campaign import load_campaign
from tyredamp.campaign.outputs import write_outputs
from tyredamp.campaign.runner import TestRun, run_tests
from tyredamp.cli import main

# the hostile tests' own temporary directory serves these tests too (autouse fixture)
from .test_campaign_hostile import (  # noqa: F401
    _check_one_line_exit_2,
    _own_temporary_directory,
    tree,
    write_tiny_campaign,
)

pytestmark = pytest.mark.slow


def _http_status(port: int, path: str) -> int:
    import urllib.error
    import urllib.request

    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{port}{path}", timeout=5) as r:
            return int(r.status)
    except urllib.error.HTTPError as exc:
        return int(exc.code)


def _listening(children_only: bool = False) -> list[Any]:
    """Listening sockets of this process and its children (only the children's)."""
    me = psutil.Process()
    out = []
    for p in [*([] if children_only else [me]), *me.children(recursive=True)]:
        try:
            out += [c for c in p.net_connections(kind="inet") if c.status == psutil.CONN_LISTEN]
        except psutil.Error:
            continue
    return out


@pytest.fixture(scope="module")
def tiny(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_tiny_campaign(tmp_path_factory.mktemp("tiny") / "data")


@pytest.fixture(scope="module")
def reference(tiny: Path, tmp_path_factory: pytest.TempPathFactory) -> bytes:
    out = tmp_path_factory.mktemp("ref") / "out"
    main(["campaign", str(tiny), "--out", str(out), "--serial", "--no-report"])
    return (out / "modes.csv").read_bytes()


def test_the_local_pool_opens_no_port(tiny: Path, reference: bytes, tmp_path: Path) -> None:
    # the pool's workers are child processes: none of them listens (sockets this test
    # process may hold for other tests that ran in it before are not the pool's)
    before = {(c.laddr.ip, c.laddr.port) for c in _listening(children_only=True)}
    seen: list[set[tuple[str, int]]] = []

    def look(run: TestRun, done: int, failed: int, total: int) -> None:
        seen.append({(c.laddr.ip, c.laddr.port) for c in _listening(children_only=True)})

    runs = run_tests(
        load_campaign(tiny), tmp_path / "out", mode="local", workers=2, on_outcome=look
    )
    assert all(r.ok for r in runs)
    assert len(seen) == 2
    assert all(s <= before for s in seen)  # no new listening socket while the pool ran
    # and the pool gives the serial results, bit for bit
    write_outputs(load_campaign(tiny), runs, tmp_path / "out", report=False)
    assert (tmp_path / "out" / "modes.csv").read_bytes() == reference


def test_a_local_dask_cluster_listens_on_loopback_only() -> None:
    from tyredamp.campaign.cluster import local_dask_cluster

    before = {(c.laddr.ip, c.laddr.port) for c in _listening()}
    client, cluster = local_dask_cluster(1)
    try:
        new = [c for c in _listening() if (c.laddr.ip, c.laddr.port) not in before]
        assert new  # the scheduler, the worker and its nanny
        assert all(ipaddress.ip_address(c.laddr.ip).is_loopback for c in new), new
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        # the HTTP server Dask always starts answers its health check and nothing else
        port = next(iter(cluster.scheduler.http_server._sockets.values())).getsockname()[1]
        assert _http_status(port, "/health") == 200
        for path in ("/status", "/info/main/workers.html", "/json/identity.json", "/metrics"):
            assert _http_status(port, path) == 404, path
        assert client._deserializers is None or "pickle" not in client._deserializers
    finally:
        client.close()
        cluster.close()


# ----------------------------------------------------------------------------- TLS
def _key() -> Any:
    from cryptography.hazmat.primitives.asymmetric import ec

    return ec.generate_private_key(ec.SECP256R1())


def _cert(subject: str, key: Any, issuer: tuple[str, Any] | None, ca: bool) -> Any:
    from cryptography import x509
    from cryptography.hazmat.primitives import hashes
    from cryptography.x509.oid import NameOID

    name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, subject)])
    iss_name, iss_key = (
        (name, key)
        if issuer is None
        else (
            x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, issuer[0])]),
            issuer[1],
        )
    )
    now = datetime.datetime.now(datetime.UTC)
    b = (
        x509.CertificateBuilder()
        .subject_name(name)
        .issuer_name(iss_name)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=1))
        .add_extension(x509.BasicConstraints(ca=ca, path_length=None), critical=True)
    )
    if not ca:
        b = b.add_extension(
            x509.SubjectAlternativeName([x509.IPAddress(ipaddress.ip_address("127.0.0.1"))]),
            critical=False,
        )
    return b.sign(iss_key, hashes.SHA256())


@pytest.fixture(scope="module")
def pki(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """A CA with one certificate for scheduler, worker and client; and a stranger CA."""
    from cryptography.hazmat.primitives import serialization

    root = tmp_path_factory.mktemp("pki")
    files: dict[str, str] = {}

    def pem(name: str, data: bytes) -> None:
        (root / name).write_bytes(data)
        files[name] = str(root / name)

    for ca_name in ("ca", "stranger"):
        ca_key = _key()
        ca = _cert(ca_name, ca_key, None, True)
        node_key = _key()
        node = _cert(f"{ca_name}-node", node_key, (ca_name, ca_key), False)
        pem(f"{ca_name}.pem", ca.public_bytes(serialization.Encoding.PEM))
        pem(f"{ca_name}-node.pem", node.public_bytes(serialization.Encoding.PEM))
        pem(
            f"{ca_name}-node.key",
            node_key.private_bytes(
                serialization.Encoding.PEM,
                serialization.PrivateFormat.PKCS8,
                serialization.NoEncryption(),
            ),
        )
    return files


@pytest.fixture(scope="module")
def tls_cluster(pki: dict[str, str]) -> Iterator[Any]:
    from distributed import LocalCluster
    from distributed.security import Security

    cert, key = pki["ca-node.pem"], pki["ca-node.key"]
    sec = Security(
        tls_ca_file=pki["ca.pem"],
        tls_scheduler_cert=cert,
        tls_scheduler_key=key,
        tls_worker_cert=cert,
        tls_worker_key=key,
        tls_client_cert=cert,
        tls_client_key=key,
        require_encryption=True,
    )
    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        protocol="tls",
        host="127.0.0.1",
        security=sec,
        dashboard_address=None,
        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
    ) as c:
        yield c


def test_a_campaign_runs_on_a_tls_scheduler(
    tiny: Path, reference: bytes, pki: dict[str, str], tls_cluster: Any, tmp_path: Path
) -> None:
    address = tls_cluster.scheduler_address
    assert address.startswith("tls://127.0.0.1:")
    out = tmp_path / "out"
    tls = ["--tls-ca", pki["ca.pem"], "--tls-cert", pki["ca-node.pem"]]
    tls += ["--tls-key", pki["ca-node.key"]]
    main(["campaign", str(tiny), "--out", str(out), "--scheduler", address, *tls])
    assert (out / "modes.csv").read_bytes() == reference  # the serial results, bit for bit
    assert (out / "report.html").is_file()


@pytest.mark.parametrize(
    ("case", "want"),
    [
        ("stranger-ca", "TLS handshake"),
        ("stranger-client", "connection to"),
        ("plain-tcp", "no Dask greeting"),
    ],
)
def test_a_tls_scheduler_refuses_strangers_in_one_line(
    case: str,
    want: str,
    tiny: Path,
    pki: dict[str, str],
    tls_cluster: Any,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    address = tls_cluster.scheduler_address
    tls = {
        "stranger-ca": [
            "--tls-ca",
            pki["stranger.pem"],
            "--tls-cert",
            pki["ca-node.pem"],
            "--tls-key",
            pki["ca-node.key"],
        ],
        "stranger-client": [
            "--tls-ca",
            pki["ca.pem"],
            "--tls-cert",
            pki["stranger-node.pem"],
            "--tls-key",
            pki["stranger-node.key"],
        ],
        "plain-tcp": [],
    }[case]
    if case == "plain-tcp":
        address = address.replace("tls://", "tcp://")
    before = tree(tiny.parent)
    args = ["campaign", str(tiny), "--out", str(tmp_path / "out"), "--scheduler", address]
    line = _check_one_line_exit_2(lambda: main([*args, *tls, "--connect-timeout", "1"]), capsys)
    assert want in line
    assert tree(tiny.parent) == before
    assert not (tmp_path / "out").exists()


def test_a_scheduler_without_workers_ends_in_one_line(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=0,
        processes=False,
        protocol="tcp",
        host="127.0.0.1",
        dashboard_address=None,
        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
    ) as c:
        args = ["campaign", str(tiny), "--out", str(tmp_path / "out")]
        args += ["--scheduler", c.scheduler_address, "--worker-timeout", "0.5"]
        line = _check_one_line_exit_2(lambda: main(args), capsys)
    assert "has no worker after 0.5 s" in line
    assert not (tmp_path / "out").exists()
    assert os.path.isfile(tiny)
