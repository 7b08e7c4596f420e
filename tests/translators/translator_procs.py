"""Real processes for the translator tests: a MOOSDB (ours or the C++ one), moos-gateway with named plugins,
usv-manager and usv-command, each a child process with its output in the test's temporary directory.

The real MOOSDB listens on every address, so it is used only inside a private network namespace
(``/opt/moos/bin/netns-run``); otherwise those test variants skip.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

from gateway.moos.testing import free_port, moosdb_process, port_open, wait_for

ORIGIN = (43.8253, -70.3304)  # s1_alpha (ivp_helm.md §7.3)


class ChildProcess:
    """One child process with stdout/stderr in files; ``stop`` is SIGTERM, then SIGKILL after a grace period."""

    def __init__(self, name: str, args: list[str], workdir: Path, env: dict[str, str] | None = None) -> None:
        self.name = name
        self.out_path = workdir / f"{name}.out"
        self.err_path = workdir / f"{name}.err"
        with open(self.out_path, "wb") as out, open(self.err_path, "wb") as err:
            self.proc = subprocess.Popen(args, stdout=out, stderr=err, cwd=workdir, env=env)

    def output(self) -> str:
        return self.out_path.read_text(errors="replace") + self.err_path.read_text(errors="replace")

    def alive(self) -> bool:
        return self.proc.poll() is None

    def stop(self, grace_s: float = 15.0) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(grace_s)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(10)
        return self.proc.returncode


@contextlib.contextmanager
def moosdb(kind: str, workdir: Path, community: str = "usv") -> Iterator[int]:
    """A MOOSDB child process (``kind`` "ours" = moos-db, "real" = the C++ MOOSDB); yields its port."""
    if kind == "ours":
        with moosdb_process(workdir, community=community) as db:
            yield db.port
        return
    port = free_port()
    child = ChildProcess("MOOSDB", ["MOOSDB", f"--moos_port={port}", f"--moos_community={community}",
                                    "--moos_suicide_disable"], workdir)
    try:
        if not wait_for(lambda: port_open(port) or not child.alive(), 20) or not child.alive():
            raise RuntimeError(f"MOOSDB did not start: {child.output()}")
        yield port
    finally:
        child.stop(5)


def gateway_args(moos_port: int, origin: tuple[float, float] | None = ORIGIN) -> list[str]:
    args = [sys.executable, "-m", "gateway.apps.moos_gateway", "--moos", f'server: "127.0.0.1" port: {moos_port}', "-vv"]
    if origin is not None:
        args += ["--app", f"geodesy {{ lat_origin: {origin[0]} lon_origin: {origin[1]} }}"]
    return args


@contextlib.contextmanager
def running(name: str, args: list[str], workdir: Path, env: dict[str, str]) -> Iterator[ChildProcess]:
    """A child process for the duration of the block; its output is attached to failures by the caller."""
    child = ChildProcess(name, args, workdir, env)
    try:
        yield child
    finally:
        child.stop()


def plugin_env(broker_env: dict[str, str], plugins: str) -> dict[str, str]:
    env = dict(broker_env)
    env["GOBY_MOOS_GATEWAY_PLUGINS"] = plugins
    return env


def run_cli(args: list[str], env: dict[str, str], workdir: Path, timeout_s: float = 60.0) -> subprocess.CompletedProcess:
    """``usv-command`` with ``args``, to completion."""
    return subprocess.run([sys.executable, "-m", "translators.apps.usv_command", *args], env=env, cwd=workdir,
                          capture_output=True, text=True, timeout=timeout_s)


def wait_until(predicate, timeout_s: float, what: str, *children: ChildProcess) -> None:  # noqa: ANN001
    """Poll ``predicate`` until true; on timeout fail with ``what`` and the children's output."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            logs = "\n".join(f"--- {c.name} ---\n{c.output()[-4000:]}" for c in children)
            raise AssertionError(f"timed out after {timeout_s} s waiting for {what}\n{logs}")
        time.sleep(0.05)


def environ_without_plugins() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("GOBY_MOOS_GATEWAY_PLUGINS", None)
    return env
