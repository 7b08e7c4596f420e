"""A portal thread of the demo (recorder, operator) run on a Python thread of its own.

Portal threads own their sockets, so the ``SimpleThread`` is built on the thread that runs it; ``close()`` quits it
even when it is still being built.
"""

from __future__ import annotations

import logging
import threading
from abc import ABC, abstractmethod

from gateway.goby.portal import SimpleThread


class BackgroundPortalThread(ABC):
    """Builds (:meth:`_build`) and runs one portal thread on a daemon thread; ``error`` keeps what stopped it."""

    def __init__(self, thread_name: str, log: logging.Logger, stopped: str) -> None:
        self._log = log
        self._stopped = stopped
        self._portal: SimpleThread | None = None
        self._lock = threading.Lock()
        self._closing = False
        self._thread = threading.Thread(target=self._run, name=thread_name, daemon=True)
        self.error: BaseException | None = None

    @abstractmethod
    def _build(self) -> SimpleThread:
        """The portal thread; called on the new thread."""

    def _run(self) -> None:
        try:
            portal = self._build()
            with self._lock:
                self._portal = portal
                if self._closing:
                    portal.quit()
            try:
                portal.run()
            finally:
                portal.close()
        except Exception as exc:  # reported by the demo; the thread must not die silently
            self.error = exc
            self._log.exception(self._stopped)

    def start(self) -> None:
        self._thread.start()

    def close(self) -> None:
        with self._lock:
            self._closing = True
            if self._portal is not None:
                self._portal.quit()
        self._thread.join(timeout=15)
