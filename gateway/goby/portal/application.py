"""Applications in Goby's shape: the main thread is itself a :class:`SimpleThread`; a multi-thread application
launches and joins further threads, each running its own poll loop on its own Python thread.

With an ``interprocess`` configuration every application answers goby-coroner's health requests
(``gateway.goby.portal.health``) and quits on a goby-terminate request naming it
(``gateway.goby.portal.terminate``), as Goby3's applications do (docs/health.md).
"""

from __future__ import annotations

import logging
import threading
from typing import Any

from google.protobuf.message import Message

from gateway.goby.portal.config import app_config_of, interprocess_config_of
from gateway.goby.portal.context import start_on_thread
from gateway.goby.portal.errors import ThreadError
from gateway.goby.portal.group import Group
from gateway.goby.portal.health import ThreadHealthCollector, answer_at_once
from gateway.goby.portal.protobuf.coroner_pb2 import HEALTH__OK, ThreadHealth
from gateway.goby.portal.terminate import subscribe_terminate
from gateway.goby.portal.thread import SimpleThread

log = logging.getLogger(__name__)

#: Goby3's ``goby::middleware::groups::configuration`` (src/middleware/application/groups.h): every application
#: publishes its whole configuration there at start (single_thread.h / multi_thread.h constructors).
CONFIGURATION_GROUP = Group("goby::configuration")


class _Application(SimpleThread):
    """Common base: return code, ``quit(code)``, eager portal (so the main thread runs the hold handshake)."""

    def __init__(self, cfg: Any, loop_frequency_hz: float = 0.0) -> None:
        super().__init__(cfg, loop_frequency_hz)
        self._return_code = 0
        if interprocess_config_of(cfg) is not None:
            self.interprocess()
            if isinstance(cfg, Message):  # Goby's start-up announcement (PROTOBUF; held until the broker releases)
                self.interprocess().publish(CONFIGURATION_GROUP, cfg)
            subscribe_terminate(self, self.app_name, self.quit)
            self._subscribe_health()

    @property
    def return_code(self) -> int:
        return self._return_code

    def quit(self, code: int = 0) -> None:
        """Stop the application with exit ``code`` (thread-safe; the first non-zero code wins)."""
        if code and not self._return_code:
            self._return_code = code
        super().quit()

    def app_name(self) -> str:
        return self.context.application

    def health(self, health: ThreadHealth) -> None:
        """The main thread's health: named after the application, ``HEALTH__OK`` (Goby's application default)."""
        health.name = self.app_name()
        health.state = HEALTH__OK

    def _subscribe_health(self) -> None:
        """Answer goby-coroner's requests (main thread)."""
        answer_at_once(self, self.app_name)

    def _after_initialize(self) -> None:
        if self._transports.has_interprocess:
            self.interprocess().ready()


class SingleThreadApplication(_Application):
    """One thread: subscriptions, ``loop()`` and ``call_soon`` work all run on the main thread."""


class MultiThreadApplication(_Application):
    """The main thread plus threads started with :meth:`launch_thread`."""

    def __init__(self, cfg: Any, loop_frequency_hz: float = 0.0) -> None:
        self._threads: list[tuple[SimpleThread, threading.Thread]] = []
        self._threads_lock = threading.Lock()
        self._next_uid = 0  # Goby's thread uid: launch order, from 0
        super().__init__(cfg, loop_frequency_hz)

    def _subscribe_health(self) -> None:
        """Collect every launched thread's answer, unless ``app.health_cfg.run_health_monitor_thread`` is false:
        then, as Goby without its HealthMonitorThread, the application does not answer over interprocess."""
        app_cfg = app_config_of(self.cfg())
        if app_cfg is not None and not app_cfg.health_cfg.run_health_monitor_thread:
            log.debug("health_cfg.run_health_monitor_thread is false: not answering health requests")
            return
        ThreadHealthCollector(self, self.app_name, self.threads)

    def launch_thread(self, thread_class: type[SimpleThread], *args: Any, **kwargs: Any) -> SimpleThread:
        """Start ``thread_class(*args, **kwargs)`` (default args: ``(self.cfg(),)``) on a new Python thread.

        The instance is constructed on the new thread (so its subscriptions and sockets belong there); this call
        returns once construction finished, and raises ``ThreadError`` if the constructor raised.  If the
        thread's ``loop()`` later raises, the error is logged and the application quits with code 1.
        """
        if not args and not kwargs:
            args = (self.cfg(),)
        uid, self._next_uid = self._next_uid, self._next_uid + 1

        def build() -> SimpleThread:
            instance = thread_class(*args, **kwargs)
            name = f"{thread_class.__module__}.{thread_class.__qualname__}"
            instance.set_identity(name if instance.index < 0 else f"{name}/{instance.index}", uid)
            return instance

        def run(instance: SimpleThread) -> None:
            try:
                instance.run()
            except Exception:
                log.exception("thread %s failed; quitting the application", thread_class.__qualname__)
                self.quit(1)
            finally:
                instance.close()

        try:
            instance, pythread = start_on_thread(self.context, build, run,
                                                 thread_class.__qualname__)
        except BaseException as exc:
            raise ThreadError(f"{thread_class.__qualname__} failed to start: {exc}") from exc
        with self._threads_lock:
            self._threads.append((instance, pythread))
        log.debug("launched thread %s", thread_class.__qualname__)
        return instance

    def join_thread(self, which: type[SimpleThread] | SimpleThread, timeout: float | None = None) -> int:
        """Stop and join the launched threads of a class (or one instance); returns how many have ended.

        A thread that does not end within ``timeout`` is logged and stays listed, so ``close()`` joins it again.
        """
        with self._threads_lock:
            chosen = [
                (inst, t) for inst, t in self._threads
                if inst is which or (isinstance(which, type) and type(inst) is which)
            ]
        for inst, _ in chosen:
            inst.quit()
        joined = []
        for inst, pythread in chosen:
            pythread.join(timeout)
            if pythread.is_alive():
                # Keep it listed, so close() tries again rather than forgetting a live thread.
                log.error("thread %s did not stop within %s s", type(inst).__qualname__, timeout)
            else:
                joined.append((inst, pythread))
        with self._threads_lock:
            self._threads = [pair for pair in self._threads if pair not in joined]
        return len(joined)

    def threads(self) -> list[SimpleThread]:
        """The launched threads still running (not yet joined)."""
        with self._threads_lock:
            return [inst for inst, _ in self._threads]

    def close(self) -> None:
        """Join every launched thread, then close the main thread's transports; idempotent."""
        with self._threads_lock:
            remaining = list(self._threads)
        for inst, _ in remaining:
            self.join_thread(inst)
        super().close()
