"""Helpers for tests in every area: a broker subprocess on a private IPC path, the config apps need to join it,
and a small portal client driven from the test's own thread.

    with broker_process(tmp_path, platform="t1") as broker:
        env = {**os.environ, "GOBY_INTERPROCESS": broker.interprocess_text()}
        with PortalClient(broker.interprocess_config()) as client:
            got = client.collect("nav", NodeStatus)
            client.wait_subscribed()
            ...
            client.poll_until(lambda: len(got) == 3)
"""

from __future__ import annotations

import json
import os
import re
import shutil
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from google.protobuf import text_format

from gateway.goby.portal.broker import READY_PREFIX
from gateway.goby.portal.config import app_name_of, interprocess_config_of
from gateway.goby.portal.context import ProcessContext, use_context
from gateway.goby.portal.errors import PortalError
from gateway.goby.portal.group import GroupLike
from gateway.goby.portal.interprocess import InterProcessPortal
from gateway.goby.portal.timeutil import SystemClock
from gateway.goby.portal.transports import ThreadTransports
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from util.process import ChildProcess, ProcessError

#: Unix socket paths are limited to 107 bytes; longer temp dirs fall back to a short one under /tmp.
_MAX_IPC_BASE = 90


class BrokerProcess:
    """A ``goby-broker`` subprocess; ``start``/``stop``/``kill``/``restart`` may be called repeatedly."""

    def __init__(self, directory: Path, platform: str = "test", tcp: bool = False, extra_args: list[str] | None = None,
                 startup_timeout: float = 30.0, log_path: str | os.PathLike[str] | None = None,
                 address: str = "") -> None:
        self.platform = platform
        self.tcp = tcp
        self.address = address  # TCP: the ``ip_address`` to bind and connect (empty: ipv4_address, 127.0.0.1)
        self._own_dir: str | None = None
        base = Path(directory) / f"goby_{platform}"
        if len(str(base)) > _MAX_IPC_BASE:
            self._own_dir = tempfile.mkdtemp(prefix="gb", dir="/tmp")
            base = Path(self._own_dir) / f"goby_{platform}"
        self.socket_base = str(base)
        self.extra_args = list(extra_args or [])
        self.startup_timeout = startup_timeout
        self.process: ChildProcess | None = None  # while running
        self._child: ChildProcess | None = None  # kept across restarts: one log
        self.log_path = Path(log_path) if log_path is not None else None
        self._out_path = Path(self._own_dir or directory) / f"goby-broker-{platform}.out"
        self.endpoints: dict[str, Any] = {}
        self.manager_port = 0

    def _config(self) -> InterProcessPortalConfig:
        cfg = InterProcessPortalConfig(platform=self.platform)
        if self.tcp:
            cfg.transport = InterProcessPortalConfig.TCP
            cfg.tcp_port = self.manager_port
            if self.address:
                cfg.ip_address = self.address
        else:
            cfg.socket_name = self.socket_base
        return cfg

    def interprocess_config(self) -> InterProcessPortalConfig:
        """The ``interprocess`` block an app needs to join this broker."""
        return self._config()

    def interprocess_text(self) -> str:
        """The same block in one-line text format: the value for ``GOBY_INTERPROCESS`` or ``--interprocess``."""
        return text_format.MessageToString(self._config(), as_one_line=True)

    def env(self, base: dict[str, str] | None = None) -> dict[str, str]:
        """An environment for app subprocesses with ``GOBY_INTERPROCESS`` pointing here."""
        env = dict(os.environ if base is None else base)
        env["GOBY_INTERPROCESS"] = self.interprocess_text()
        return env

    def start(self) -> BrokerProcess:
        """Start the broker and wait for its ready line; raises ``PortalError`` if it does not come up."""
        if self.process is not None and self.process.running:
            return self
        cfg = self._config()
        if self.tcp and not self.manager_port:
            cfg.tcp_port = 0
        args = [sys.executable, "-m", "gateway.apps.goby_broker",
                "--interprocess", text_format.MessageToString(cfg, as_one_line=True), *self.extra_args]
        if self._child is None:
            self._child = ChildProcess(args, self._out_path, name=f"goby-broker ({self.platform})",
                                       stderr_path=self.log_path)
        self._child.args = args
        self.process = self._child
        try:
            ready = self.process.start().wait_ready(re.escape(READY_PREFIX) + "(.*)", timeout=self.startup_timeout)
        except ProcessError as exc:
            self.process = None
            raise PortalError(f"goby-broker for platform {self.platform!r} did not become ready: {exc}") from None
        assert ready is not None
        self.endpoints = json.loads(ready.group(1))
        if self.tcp and not self.manager_port:
            self.manager_port = int(self.endpoints["manager"].rsplit(":", 1)[1])
        return self

    def stop(self, timeout: float = 10.0) -> int | None:
        """SIGTERM, wait, SIGKILL if needed; returns the exit code (idempotent)."""
        proc, self.process = self.process, None
        return proc.stop(grace=timeout) if proc is not None else None

    def kill(self) -> None:
        """SIGKILL (a crash); the IPC files stay behind, as after a real crash."""
        proc, self.process = self.process, None
        if proc is not None:
            proc.kill()

    def stderr_text(self) -> str:
        """The broker's log so far (only with ``log_path``)."""
        return self.log_path.read_text() if self.log_path is not None and self.log_path.exists() else ""

    def restart(self) -> BrokerProcess:
        self.stop()
        return self.start()

    def close(self) -> None:
        self.stop()
        if self._own_dir is not None:
            shutil.rmtree(self._own_dir, ignore_errors=True)
            self._own_dir = None

    def __enter__(self) -> BrokerProcess:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()


@contextmanager
def broker_process(tmp_path: Path, platform: str = "test", tcp: bool = False,
                   extra_args: list[str] | None = None, log_path: str | os.PathLike[str] | None = None,
                   address: str = "") -> Iterator[BrokerProcess]:
    """Start ``goby-broker`` on an IPC path in ``tmp_path`` (or TCP on 127.0.0.1), yield it, stop it.

    The broker's log goes to ``log_path`` if given (read it with ``stderr_text()``), else to this process's stderr.
    """
    broker = BrokerProcess(tmp_path, platform, tcp, extra_args, log_path=log_path, address=address)
    with broker:
        yield broker


@contextmanager
def running_app(app_class: Callable[[Any], Any], cfg: Any, *, hold_settle_s: float = 0.2,
                clock: SystemClock | None = None, timeout_s: float = 30.0) -> Iterator[Any]:
    """Construct ``app_class(cfg)`` and run it on a new thread of this process (with its own ``ProcessContext``);
    yield the application; on exit ``quit()`` it, join, close.  A constructor error is raised here."""
    context = ProcessContext(interprocess_config_of(cfg), application=app_name_of(cfg, "test_app"),
                             hold_settle_s=hold_settle_s, clock=clock)
    box: dict[str, Any] = {}
    constructed = threading.Event()

    def target() -> None:
        with use_context(context):
            try:
                box["app"] = app = app_class(cfg)
            except BaseException as exc:  # noqa: BLE001 - re-raised in the test thread
                box["error"] = exc
                constructed.set()
                return
            constructed.set()
            try:
                app.run()
            except BaseException as exc:  # noqa: BLE001
                box["run_error"] = exc
            finally:
                app.close()

    thread = threading.Thread(target=target, name=f"app-{getattr(app_class, '__qualname__', 'app')}")
    thread.start()
    try:
        if not constructed.wait(timeout_s):
            raise PortalError(f"{app_class} was not constructed within {timeout_s} s")
        if "error" in box:
            raise box["error"]
        yield box["app"]
    finally:
        if "app" in box:
            box["app"].quit()
        thread.join(timeout_s)
        context.close()
    if "run_error" in box:
        raise box["run_error"]


class PortalClient:
    """A portal driven by the test's own thread: publish, subscribe, and ``poll`` to run callbacks.

    Use it from one thread only.  The hold settles after ``hold_settle_s`` (default 0.2 s, Goby uses 1 s).
    """

    def __init__(self, interprocess: InterProcessPortalConfig, name: str = "test_client",
                 hold_settle_s: float = 0.2) -> None:
        cfg = InterProcessPortalConfig()
        cfg.CopyFrom(interprocess)
        cfg.client_name = name
        self.context = ProcessContext(cfg, client_name=name, application=name, hold_settle_s=hold_settle_s)
        self._transports = ThreadTransports(self.context, name)
        try:
            self.portal: InterProcessPortal = self._transports.interprocess()
        except BaseException:
            self._transports.close()
            self.context.close()
            raise
        self.portal.ready()

    def publish(self, group: GroupLike, msg: Any, **kwargs: Any) -> bool:
        return self.portal.publish(group, msg, **kwargs)

    def subscribe(self, group: GroupLike, msg_type: type, callback: Callable[[Any], None], **kwargs: Any) -> None:
        """``callback`` runs on the test's thread inside :meth:`poll`."""
        self.portal.subscribe(group, msg_type, callback, **kwargs)

    def collect(self, group: GroupLike, msg_type: type, **kwargs: Any) -> list[Any]:
        """Subscribe and return the list the received messages are appended to (inside :meth:`poll`, this thread)."""
        received: list[Any] = []
        self.portal.subscribe(group, msg_type, received.append, **kwargs)
        return received

    def poll(self, timeout_s: float = 0.0) -> int:
        return self._transports.poll(timeout_s)

    def poll_until(self, predicate: Callable[[], bool], timeout_s: float = 20.0) -> bool:
        """Poll until ``predicate()`` is true; returns False on timeout."""
        deadline = time.monotonic() + timeout_s
        while not predicate():
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return False
            self.poll(min(0.05, remaining))
        return True

    def wait_ready(self, timeout_s: float = 20.0) -> bool:
        """Poll until the manager has released the hold (publications flow)."""
        return self.poll_until(lambda: not self.portal.hold_state(), timeout_s)

    def wait_subscribed(self, timeout_s: float = 20.0) -> bool:
        """Return once this client's subscriptions have reached the broker (a probe round trip), hold released."""
        if not self.wait_ready(timeout_s):
            return False
        probe_group = f"_portal_client_probe_{uuid.uuid4().hex}"
        seen: list[str] = []
        self.portal.subscribe(probe_group, str, seen.append)
        deadline = time.monotonic() + timeout_s
        try:
            while not seen and time.monotonic() < deadline:
                self.portal.publish(probe_group, "probe")
                self.poll_until(lambda: bool(seen), 0.1)
        finally:
            self.portal.unsubscribe(probe_group, str)
        return bool(seen)

    def close(self) -> None:
        self._transports.close()
        self.context.close()

    def __enter__(self) -> PortalClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()



def poll_all(clients: list[PortalClient], predicate: Callable[[], object], timeout_s: float) -> bool:
    """Poll every client in turn (their callbacks run here) until ``predicate()`` is true; False after
    ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        for c in clients:
            c.poll(0.01)
        if predicate():
            return True
    return False

def app_process(args: list[str], log_path: str | os.PathLike[str], *, env: dict[str, str] | None = None,
                cwd: str | os.PathLike[str] | None = None) -> ChildProcess:
    """An application started as a child process: its stdout (what tests wait for: ``wait_for_output``, ``lines()``)
    in ``<log_path>.out``, its stderr (the log) in ``log_path`` (``stderr_text()``)."""
    log_path = Path(log_path)
    return ChildProcess(args, log_path.with_name(log_path.name + ".out"), stderr_path=log_path, env=env,
                        cwd=cwd).start()
