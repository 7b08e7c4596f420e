"""Helpers for tests in any area: a MOOSDB in-process or as a process, connected clients, mail collection.

Everything here binds 127.0.0.1 on free ports and stops what it starts.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any

from .client import comms
from .message import MoosMessage
from .server import MoosDB


def free_port() -> int:
    """A TCP port that was free a moment ago on 127.0.0.1."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def port_open(port: int, host: str = "127.0.0.1") -> bool:
    """True when something accepts TCP connections on ``host:port`` (a server has finished starting)."""
    with socket.socket() as s:
        s.settimeout(0.2)
        return s.connect_ex((host, port)) == 0


def private_netns() -> bool:
    """True when this process sees no network interface but loopback (a private network namespace)."""
    try:
        lines = Path("/proc/self/net/dev").read_text().splitlines()[2:]
    except OSError:
        return False
    return {line.split(":", 1)[0].strip() for line in lines} == {"lo"}


def real_moos_skip_reason(*binaries: str) -> str | None:
    """Why tests cannot use the real MOOS-IvP ``binaries`` here, or None when they can.

    The C++ MOOSDB listens on every address, so the real programs are used only on PATH *and* inside a private
    network namespace (e.g. ``/opt/moos/bin/netns-run``); a developer's machine with MOOS-IvP installed does not
    expose test servers to its network by accident.
    """
    for binary in binaries or ("MOOSDB",):
        if shutil.which(binary) is None:
            return f"the real {binary} is not on PATH"
    if not private_netns():
        return "the real MOOSDB listens on all addresses; run inside a private network namespace (netns-run)"
    return None


def stop_process(proc: subprocess.Popen, timeout: float = 5.0) -> int | None:
    """SIGTERM ``proc``, then SIGKILL if it has not ended within ``timeout``; returns its exit status."""
    if proc.poll() is None:
        proc.terminate()
        try:
            return proc.wait(timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
    return proc.wait(timeout)


@contextlib.contextmanager
def real_moosdb(workdir: str | os.PathLike[str], port: int | None = None, community: str = "moos",
                warp: float = 1.0) -> Iterator[tuple[int, subprocess.Popen]]:
    """The C++ MOOSDB as a child process, listening before this yields ``(port, process)``; stopped on exit.

    Check ``real_moos_skip_reason()`` first: the C++ MOOSDB listens on every address, so only run it inside a
    private network namespace. Its output goes to ``workdir/MOOSDB-<port>.log``.
    """
    port = port or free_port()
    log_path = Path(workdir) / f"MOOSDB-{port}.log"
    with open(log_path, "wb") as log:
        proc = subprocess.Popen(
            ["MOOSDB", f"--moos_port={port}", f"--moos_community={community}", f"--moos_time_warp={warp}",
             "--moos_suicide_disable"],
            stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, cwd=workdir,
        )
        try:
            if not wait_for(lambda: port_open(port) or proc.poll() is not None, 10) or proc.poll() is not None:
                raise RuntimeError(f"MOOSDB did not start on port {port}: {log_path.read_text()}")
            yield port, proc
        finally:
            stop_process(proc)


def wait_for(predicate: Callable[[], Any], timeout: float = 10.0, interval: float = 0.01) -> Any:
    """Poll ``predicate`` until it returns something truthy (returned) or ``timeout`` passes (returns it falsy)."""
    deadline = time.monotonic() + timeout
    while True:
        result = predicate()
        if result or time.monotonic() >= deadline:
            return result
        time.sleep(interval)


@contextlib.contextmanager
def running_moosdb(community: str = "moos", warp: float = 1.0, **kwargs: Any) -> Iterator[MoosDB]:
    """An in-process :class:`MoosDB` on a free loopback port (``db.port``), stopped on exit."""
    db = MoosDB("127.0.0.1", 0, community, time_warp=warp, **kwargs)
    db.start()
    try:
        yield db
    finally:
        db.stop()


class MoosDBProcess:
    """The ``moos-db`` console script as a child process; knows its port and can be restarted on it."""

    def __init__(self, workdir: str | os.PathLike[str], community: str = "moos", warp: float = 1.0,
                 port: int = 0, extra_args: Iterable[str] = ()) -> None:
        self.workdir = Path(workdir)
        self.community = community
        self.warp = warp
        self.port = port
        self.extra_args = list(extra_args)
        self.proc: subprocess.Popen[bytes] | None = None
        self._starts = 0

    @property
    def log_path(self) -> Path:
        return self.workdir / f"moosdb-{self._starts}.log"

    def start(self, timeout: float = 20.0) -> MoosDBProcess:
        """Start (or restart, on the same port) and wait until it listens."""
        if self.proc is not None and self.proc.poll() is None:
            return self
        self._starts += 1
        out_path = self.workdir / f"moosdb-{self._starts}.out"
        cmd = [sys.executable, "-m", "gateway.apps.moos_db", f"--moos_port={self.port}",
               f"--moos_community={self.community}", f"--moos_time_warp={self.warp}", "-v", *self.extra_args]
        with open(out_path, "wb") as out, open(self.log_path, "wb") as err:
            self.proc = subprocess.Popen(cmd, stdout=out, stderr=err, cwd=self.workdir)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            text = out_path.read_text(errors="replace")
            if " listening on " in text:
                self.port = int(text.split(" listening on ", 1)[1].split()[0].rsplit(":", 1)[1])
                return self
            if self.proc.poll() is not None:
                raise RuntimeError(f"moos-db exited with {self.proc.returncode}: {self.log_path.read_text()}")
            time.sleep(0.02)
        self.stop()
        raise RuntimeError(f"moos-db did not start within {timeout} s: {self.log_path.read_text()}")

    def kill(self) -> None:
        """SIGKILL, as a crash would; the port is free again once this returns."""
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(10)

    def stop(self) -> None:
        """SIGTERM (then SIGKILL after 5 s); idempotent."""
        if self.proc is None:
            return
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)

    def restart(self, timeout: float = 20.0) -> MoosDBProcess:
        self.kill()
        return self.start(timeout)

    def __enter__(self) -> MoosDBProcess:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


@contextlib.contextmanager
def moosdb_process(tmp_path: str | os.PathLike[str], community: str = "moos", warp: float = 1.0,
                   port: int = 0, extra_args: Iterable[str] = ()) -> Iterator[MoosDBProcess]:
    """``moos-db`` as a subprocess on a free port (``.port``), logging to ``tmp_path``; stopped on exit."""
    proc = MoosDBProcess(tmp_path, community, warp, port, extra_args)
    proc.start()
    try:
        yield proc
    finally:
        proc.stop()


@contextlib.contextmanager
def connected_comms(port: int, name: str, register: Iterable[str] = (), host: str = "127.0.0.1",
                    asynchronous: bool = True, timeout: float = 10.0) -> Iterator[comms]:
    """A :class:`comms` connected to ``host:port`` that (re)registers ``register`` on every connection.

    When it yields, the DB has processed the registrations (a server-request round trip confirms it), so
    a test may publish at once without racing them.
    """
    client = comms(asynchronous=asynchronous)
    names = list(register)
    client.set_on_connect_callback(lambda: [client.register(n, 0) for n in names])
    client.run(host, port, name)
    try:
        if not client.wait_until_connected(timeout * 1000):
            raise TimeoutError(f"{name} did not connect to {host}:{port} within {timeout} s")
        if names:
            wait_for(lambda: all(client.is_registered_for(n) for n in names), timeout)
            if not client.server_request("VAR_SUMMARY", timeout):
                raise TimeoutError(f"{name}: the DB did not answer a server request within {timeout} s")
        yield client
    finally:
        client.close(True)


def collect_mail(
    client: Any,
    names: Iterable[str] | None = None,
    until: Callable[[list[MoosMessage]], bool] | int | None = None,
    timeout: float = 10.0,
) -> list[MoosMessage]:
    """Fetch repeatedly, keeping messages named in ``names`` (all if None), until ``until`` holds.

    ``until`` may be a predicate over the collected list, a count, or None (= every name seen once). Returns
    what was collected when the condition held or the timeout passed; the caller asserts on it.
    Works with our ``comms`` and the real pymoos (do not also fetch from an on-mail callback).
    """
    wanted = set(names) if names is not None else None
    if until is None:
        def done(got: list[MoosMessage]) -> bool:
            return wanted is None or wanted <= {m.key() for m in got}
    elif isinstance(until, int):
        count = until

        def done(got: list[MoosMessage]) -> bool:
            return len(got) >= count
    else:
        done = until
    got: list[MoosMessage] = []
    deadline = time.monotonic() + timeout
    while True:
        for msg in client.fetch():
            if wanted is None or msg.key() in wanted:
                got.append(msg)
        if done(got) or time.monotonic() >= deadline:
            return got
        time.sleep(0.005)
