"""Issue #19 item 3: our servers listen only where told. The OS's own table of listening sockets
(``/proc/<pid>/net/tcp`` and ``tcp6``, matched to the process's socket inodes) is the judge."""

from __future__ import annotations

import ipaddress
import os
import socket
import struct
from pathlib import Path

from frontseat.testing import running_simulator
from gateway.goby.portal.testing import broker_process
from gateway.moos.testing import moosdb_process

_LISTEN = "0A"


def _address(hex_addr: str) -> str:
    """Decode /proc/net/tcp's ``0100007F:1F90`` (little-endian words) into an address text."""
    host, _ = hex_addr.split(":")
    raw = bytes.fromhex(host)
    words = b"".join(struct.pack("<I", struct.unpack(">I", raw[i:i + 4])[0]) for i in range(0, len(raw), 4))
    address = ipaddress.ip_address(words)
    mapped = getattr(address, "ipv4_mapped", None)  # a dual-stack socket bound to an IPv4 address
    return str(mapped or address)


def listening_addresses(pid: int) -> set[str]:
    """``address:port`` of every TCP socket process ``pid`` listens on, as the kernel reports them."""
    inodes = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    found = set()
    for table in ("tcp", "tcp6"):
        for line in Path(f"/proc/{pid}/net/{table}").read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] == _LISTEN and fields[9] in inodes:
                found.add(f"{_address(fields[1])}:{int(fields[1].rsplit(':', 1)[1], 16)}")
    return found


def wildcard(addresses: set[str]) -> set[str]:
    return {a for a in addresses if ipaddress.ip_address(a.rsplit(":", 1)[0]).is_unspecified}


def test_moos_db_binds_loopback_unless_asked(tmp_path: Path) -> None:
    with moosdb_process(tmp_path) as db:
        got = listening_addresses(db.pid)
        assert got == {f"127.0.0.1:{db.port}"}
    with moosdb_process(tmp_path, extra_args=["--moos_address=0.0.0.0"]) as db:
        assert wildcard(listening_addresses(db.pid)) == {f"0.0.0.0:{db.port}"}


def test_tcp_broker_binds_its_configured_address(tmp_path: Path) -> None:
    with broker_process(tmp_path, tcp=True) as broker:
        got = listening_addresses(broker.process.pid)  # type: ignore[union-attr]
        assert len(got) == 3 and not wildcard(got), got  # manager, XPUB, XSUB
        assert all(a.startswith("127.0.0.1:") for a in got), got


def test_ipc_broker_listens_on_no_tcp_port(tmp_path: Path) -> None:
    with broker_process(tmp_path) as broker:
        assert listening_addresses(broker.process.pid) == set()  # type: ignore[union-attr]


def test_simulator_binds_loopback() -> None:
    with running_simulator() as sim:
        got = listening_addresses(sim.process.pid)
        assert got == {f"127.0.0.1:{sim.port}"}, got


def test_reader_sees_a_wildcard_listener() -> None:
    """The check itself can fail: a socket on every interface is reported as such."""
    with socket.socket() as sock:
        sock.bind(("0.0.0.0", 0))
        sock.listen(1)
        assert f"0.0.0.0:{sock.getsockname()[1]}" in wildcard(listening_addresses(os.getpid()))
