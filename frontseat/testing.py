"""Helpers for tests that need the basic frontseat simulator (ours and other areas').

* :func:`running_simulator` starts ``frontseat-sim`` as a real subprocess on a free port (or a given one)
  and stops it on exit;
* :class:`SimClient` is a blocking line client for talking to it byte for byte;
* :func:`basic_simulator_frontseat_cfg` writes the interface's ``frontseat_cfg`` for it;
"""

from __future__ import annotations

import collections
import contextlib
import os
import shutil
import socket
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from frontseat.simulator.protocol import LineSplitter, encode_lines
from util.process import ChildProcess, ProcessError


@dataclass
class SimulatorProcess:
    """A running ``frontseat-sim`` child process and the address it listens on."""

    process: ChildProcess
    host: str
    port: int
    _own_dir: str | None = None

    def stop(self, kill: bool = False) -> None:
        """SIGTERM (or SIGKILL) it and wait; idempotent."""
        if kill:
            self.process.kill()
        self.process.stop()
        if self._own_dir is not None:
            shutil.rmtree(self._own_dir, ignore_errors=True)
            self._own_dir = None


def start_simulator(port: int = 0, verbosity: int = 0, timeout: float = 30.0,
                    log_path: str | os.PathLike[str] | None = None) -> SimulatorProcess:
    """Start ``frontseat-sim <port>`` (0: a free port) and wait until it listens; its output goes to ``log_path``
    (default: a temporary file removed when it stops)."""
    args = [sys.executable, "-m", "frontseat.apps.frontseat_sim", str(port)] + (["-" + "v" * verbosity] if verbosity else [])
    own_dir = None if log_path is not None else tempfile.mkdtemp(prefix="fsim", dir="/tmp")
    child = ChildProcess(args, log_path or Path(own_dir or ".") / "frontseat-sim.log", name="frontseat-sim").start()
    try:
        ready = child.wait_ready(r"listening on (\S+):(\d+)", timeout=timeout)
    except ProcessError:
        if own_dir is not None:
            shutil.rmtree(own_dir, ignore_errors=True)
        raise
    assert ready is not None
    return SimulatorProcess(child, ready.group(1), int(ready.group(2)), own_dir)


@contextlib.contextmanager
def running_simulator(port: int = 0, verbosity: int = 0) -> Iterator[SimulatorProcess]:
    """Context manager: a ``frontseat-sim`` subprocess on ``port`` (0: a free one), stopped on exit."""
    sim = start_simulator(port, verbosity)
    try:
        yield sim
    finally:
        sim.stop()


class SimClient:
    """A blocking client of the simulator's line protocol, for tests."""

    def __init__(self, port: int, host: str = "127.0.0.1", timeout: float = 20.0) -> None:
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._splitter = LineSplitter()
        self._lines: collections.deque[str] = collections.deque()

    def send(self, *lines: str) -> None:
        """Send each line with ``\\r\\n`` (all in one write)."""
        self.sock.sendall(encode_lines(lines))

    def send_bytes(self, data: bytes) -> None:
        self.sock.sendall(data)

    def read_line(self, timeout: float = 20.0) -> str:
        """The next line (without ``\\r\\n``); TimeoutError if none arrives in time."""
        deadline = time.monotonic() + timeout
        while not self._lines:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError("no line from the simulator")
            self.sock.settimeout(remaining)
            chunk = self.sock.recv(65536)
            if not chunk:
                raise ConnectionError("simulator closed the connection")
            self._lines.extend(self._splitter.feed(chunk))
        return self._lines.popleft()

    def read_until(self, predicate: Callable[[str], bool], timeout: float = 20.0) -> list[str]:
        """Lines up to and including the first one matching ``predicate``."""
        deadline = time.monotonic() + timeout
        lines: list[str] = []
        while True:
            lines.append(self.read_line(max(0.01, deadline - time.monotonic())))
            if predicate(lines[-1]):
                return lines

    def close(self) -> None:
        self.sock.close()

    def __enter__(self) -> SimClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def basic_simulator_frontseat_cfg(
    port: int,
    *,
    lat: float = 41.592344,
    lon: float = -70.711260,
    host: str = "127.0.0.1",
    require_helm: bool = True,
    helm_running_timeout: float = 10,
    frontseat_connected_timeout: float = 10,
    status_period: int = 5,
    data_timeout: float = 10,
    reconnect_interval: float = 1,
    vehicle_type: str = "USV",
) -> str:
    """The ``frontseat_cfg { ... }`` text block for the basic simulator driver."""
    return (
        "frontseat_cfg {\n"
        f"  require_helm: {str(require_helm).lower()}\n"
        f"  helm_running_timeout: {helm_running_timeout}\n"
        f"  frontseat_connected_timeout: {frontseat_connected_timeout}\n"
        f"  status_period: {status_period}\n"
        f"  type: {vehicle_type}\n"
        "  [goby.middleware.frontseat.protobuf.basic_simulator_config] {\n"
        f'    tcp_address: "{host}"\n'
        f"    tcp_port: {port}\n"
        f"    start {{ lat: {lat} lon: {lon} duration: 0 control_freq: 10 }}\n"
        "  }\n"
        "  [goby_moos_py.frontseat.protobuf.basic_simulator_tuning] {\n"
        f"    data_timeout: {data_timeout}\n"
        f"    reconnect_interval: {reconnect_interval}\n"
        "  }\n"
        "}\n"
    )


def start_interface_with_moos_helm(workdir: Path, env: dict[str, str], sim_port: int, moosdb_port: int, *,
                                   warp: float, helm_running_timeout: float, lat: float = 41.592344,
                                   lon: float = -70.711260) -> ChildProcess:
    """A frontseat-interface process on the basic simulator with its embedded MOOS helm translation (a
    ``moos_helm`` block naming ``moosdb_port``), warped, with ``env`` (the broker's) and its log in ``workdir``."""
    from gateway.goby.portal.testing import app_process

    cfg = workdir / "frontseat.pb.cfg"
    cfg.write_text(
        f"app {{ geodesy {{ lat_origin: {lat} lon_origin: {lon} }}\n"
        f"      simulation {{ time {{ use_sim_time: true warp_factor: {warp} }} }} }}\n"
        + basic_simulator_frontseat_cfg(sim_port, status_period=1, helm_running_timeout=helm_running_timeout)
        + f'[goby.moos.protobuf.moos_helm] {{ server: "127.0.0.1" port: {moosdb_port} }}\n'
    )
    env = {**env, "FRONTSEAT_DRIVER_LIBRARY": "basic_simulator"}
    return app_process([sys.executable, "-m", "frontseat.apps.frontseat_interface", str(cfg), "-v"], env=env,
                       log_path=workdir / "iface.log")
