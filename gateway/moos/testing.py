"""Helpers for tests in any area: a MOOSDB in-process or as a process, connected clients, mail collection.

Everything here binds 127.0.0.1 on free ports and stops what it starts.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any

from util.process import ChildProcess, free_port, wait_until

from .client import comms
from .message import MoosMessage
from .server import MoosDB


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


COURSE_IVP_RELEASE = "19.8.1"  # the MOOS-IvP release ivp-helm follows (the Goby3 course's)


def ivp_release(binary: str = "pHelmIvP") -> str | None:
    """The MOOS-IvP release a real binary reports (``Version 19.8`` -> ``"19.8"``), or None if it says none.

    Comparisons of release-specific details (flag macros, BHV_Trail's geometry) hold for ``COURSE_IVP_RELEASE``.
    """
    try:
        text = subprocess.run([binary, "--version"], capture_output=True, text=True, timeout=10).stdout
    except (OSError, subprocess.TimeoutExpired):
        return None
    match = re.search(r"Version\s+([0-9][0-9.]*[0-9])", text)
    return match.group(1) if match else None


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
    """A MOOSDB as a child process: our ``moos-db`` (``program=None``) or the real one (``program="MOOSDB"``).

    Both take the same flags. Ours picks a free port when ``port`` is 0 and reports it; the real one is given a
    free port and is ready when it listens. ``restart`` kills it (as a crash would) and starts it on the same port.
    Its output (all starts) goes to ``log_path``.
    """

    def __init__(self, workdir: str | os.PathLike[str], community: str = "moos", warp: float = 1.0,
                 port: int = 0, extra_args: Iterable[str] = (), program: str | None = None) -> None:
        self.workdir = Path(workdir)
        self.community = community
        self.warp = warp
        self.program = program
        self.port = port or (free_port() if program else 0)
        self.extra_args = list(extra_args)
        self.log_path = self.workdir / f"{program or 'moos-db'}-{self.port or 'any'}.log"
        self.child: ChildProcess | None = None

    def start(self, timeout: float = 20.0) -> MoosDBProcess:
        """Start (or restart, on the same port) and wait until it listens; ProcessError if it does not."""
        if self.child is not None and self.child.running:
            return self
        program = [self.program, "--moos_suicide_disable"] if self.program else [
            sys.executable, "-m", "gateway.apps.moos_db", "-v"]
        args = [*program, f"--moos_port={self.port}", f"--moos_community={self.community}",
                f"--moos_time_warp={self.warp}", *self.extra_args]
        if self.child is None:
            self.child = ChildProcess(args, self.log_path, name=self.program or "moos-db", cwd=self.workdir)
        self.child.args = args  # a restart keeps the port the first start reported
        self.child.start()
        if self.program:
            self.child.wait_ready(port=self.port, timeout=timeout)
        else:
            ready = self.child.wait_ready(r" listening on \S+:(\d+)", timeout=timeout)
            assert ready is not None
            self.port = int(ready.group(1))
        return self

    @property
    def pid(self) -> int:
        assert self.child is not None, "not started"
        return self.child.pid

    def kill(self) -> None:
        """SIGKILL, as a crash would; the port is free again once this returns."""
        if self.child is not None:
            self.child.kill()

    def stop(self) -> None:
        """SIGTERM (then SIGKILL after 5 s); idempotent."""
        if self.child is not None:
            self.child.stop(grace=5.0)

    def restart(self, timeout: float = 20.0) -> MoosDBProcess:
        self.kill()
        return self.start(timeout)

    def __enter__(self) -> MoosDBProcess:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


@contextlib.contextmanager
def moosdb_process(tmp_path: str | os.PathLike[str], community: str = "moos", warp: float = 1.0,
                   port: int = 0, extra_args: Iterable[str] = (), program: str | None = None
                   ) -> Iterator[MoosDBProcess]:
    """A :class:`MoosDBProcess` (``.port``) logging to ``tmp_path``, stopped on exit.

    ``program="MOOSDB"`` runs the C++ MOOSDB: check ``real_moos_skip_reason()`` first (it listens on every
    address, so only inside a private network namespace).
    """
    with MoosDBProcess(tmp_path, community, warp, port, extra_args, program) as db:
        yield db


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
            wait_until(lambda: all(client.is_registered_for(n) for n in names), timeout, f"{name}'s registrations")
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
    done: Callable[[list[MoosMessage]], bool]
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
