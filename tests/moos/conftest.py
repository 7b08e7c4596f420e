"""Fixtures for the MOOS tests: our DB in-process, and the real C++ MOOSDB when it may run here.

The real MOOSDB listens on every address, so it is only started inside a private network namespace (one
whose only interface is loopback), e.g. under ``/opt/moos/bin/netns-run``.
"""

from __future__ import annotations

import contextlib
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from gateway.moos.server import MoosDB
from gateway.moos.testing import free_port, wait_for


def private_netns() -> bool:
    """True when this process sees no network interface but loopback."""
    try:
        lines = Path("/proc/self/net/dev").read_text().splitlines()[2:]
    except OSError:
        return False
    names = {line.split(":", 1)[0].strip() for line in lines}
    return names == {"lo"}


def real_moosdb_skip_reason() -> str | None:
    if shutil.which("MOOSDB") is None:
        return "the real MOOSDB is not on PATH"
    if not private_netns():
        return "the real MOOSDB listens on all addresses; run inside a private network namespace (netns-run)"
    return None


def _port_open(port: int) -> bool:
    import socket

    with socket.socket() as s:
        s.settimeout(0.2)
        return s.connect_ex(("127.0.0.1", port)) == 0


@contextlib.contextmanager
def real_moosdb(tmp_path: Path, community: str = "moos", warp: float = 1.0) -> Iterator[int]:
    """The C++ MOOSDB as a child process on a free port; yields the port."""
    port = free_port()
    log = open(tmp_path / f"MOOSDB-{port}.log", "wb")
    proc = subprocess.Popen(
        ["MOOSDB", f"--moos_port={port}", f"--moos_community={community}", f"--moos_time_warp={warp}",
         "--moos_suicide_disable"],
        stdout=log, stderr=subprocess.STDOUT, cwd=tmp_path,
    )
    try:
        if not wait_for(lambda: _port_open(port) or proc.poll() is not None, 10) or proc.poll() is not None:
            raise RuntimeError(f"MOOSDB did not start: {(tmp_path / f'MOOSDB-{port}.log').read_text()}")
        yield port
    finally:
        proc.terminate()
        try:
            proc.wait(5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(5)
        log.close()


@pytest.fixture
def our_db() -> Iterator[MoosDB]:
    with MoosDB(community="moos") as db:
        yield db


@pytest.fixture(params=["ours", "real"])
def db_port(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[int]:
    """The port of a running DB: ours (always) and the real MOOSDB (when it may run here)."""
    if request.param == "ours":
        with MoosDB(community="moos") as db:
            yield db.port
    else:
        reason = real_moosdb_skip_reason()
        if reason:
            pytest.skip(reason)
        with real_moosdb(tmp_path) as port:
            yield port
