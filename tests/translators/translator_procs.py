"""Real processes for the translator tests: a MOOSDB (ours or the C++ one), moos-gateway with named plugins,
usv-manager and usv-command, each a child process with its output in the test's temporary directory.

The real MOOSDB listens on every address, so it is used only inside a private network namespace
(``/opt/moos/bin/netns-run``); otherwise those test variants skip.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

from gateway.moos.testing import moosdb_process
from util.process import ChildProcess, WaitTimeout, wait_until

ORIGIN = (43.8253, -70.3304)  # s1_alpha (ivp_helm.md §7.3)


def start_child(name: str, args: list[str], workdir: Path, env: dict[str, str] | None = None) -> ChildProcess:
    """``args`` started as a child process logging to ``workdir/<name>.log``; the caller stops it."""
    return ChildProcess(args, workdir / f"{name}.log", name=name, cwd=workdir, env=env).start()


@contextlib.contextmanager
def moosdb(kind: str, workdir: Path, community: str = "usv") -> Iterator[int]:
    """A MOOSDB child process (``kind`` "ours" = moos-db, "real" = the C++ MOOSDB); yields its port."""
    with moosdb_process(workdir, community=community, program=None if kind == "ours" else "MOOSDB") as db:
        yield db.port


def gateway_args(moos_port: int, origin: tuple[float, float] | None = ORIGIN) -> list[str]:
    args = [sys.executable, "-m", "gateway.apps.moos_gateway", "--moos", f'server: "127.0.0.1" port: {moos_port}', "-vv"]
    if origin is not None:
        args += ["--app", f"geodesy {{ lat_origin: {origin[0]} lon_origin: {origin[1]} }}"]
    return args


@contextlib.contextmanager
def running(name: str, args: list[str], workdir: Path, env: dict[str, str]) -> Iterator[ChildProcess]:
    """A child process for the duration of the block; its output is attached to failures by the caller."""
    child = start_child(name, args, workdir, env)
    try:
        yield child
    finally:
        child.stop(15)


def plugin_env(broker_env: dict[str, str], plugins: str) -> dict[str, str]:
    env = dict(broker_env)
    env["GOBY_MOOS_GATEWAY_PLUGINS"] = plugins
    return env


def run_cli(args: list[str], env: dict[str, str], workdir: Path, timeout_s: float = 60.0) -> subprocess.CompletedProcess:
    """``usv-command`` with ``args``, to completion."""
    return subprocess.run([sys.executable, "-m", "translators.apps.usv_command", *args], env=env, cwd=workdir,
                          capture_output=True, text=True, timeout=timeout_s)


def wait_showing_logs(predicate: Callable[[], object], timeout_s: float, what: str, *children: ChildProcess) -> None:
    """:func:`util.process.wait_until`, failing with the children's output attached."""
    try:
        wait_until(predicate, timeout_s, what)
    except WaitTimeout as exc:
        logs = "\n".join(f"--- {c.name} ---\n{c.output()[-4000:]}" for c in children)
        raise AssertionError(f"{exc}\n{logs}") from None


def environ_without_plugins() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("GOBY_MOOS_GATEWAY_PLUGINS", None)
    return env
