"""TCP after a broker drop: ask the manager again where the broker's pub/sub ports are (they are ephemeral).

The request waits in its REQ socket until the manager answers, and that socket is in the owning thread's poll (added
and removed through ``on_pollable``): no timer delays recovery.  A request unanswered for ``REQUERY_TIMEOUT_S``
(sent to a dying broker) is sent again on a fresh socket.  Everything runs on the interprocess portal's owning
thread; it logs on the portal's logger, handed in.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import zmq

from gateway.goby.portal.manager_client import EndpointQuery
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig

REQUERY_TIMEOUT_S = 1.0  # TCP: a manager request unanswered this long is sent again on a fresh socket


class EndpointRequery:
    """At most one manager query in flight, and when to (re)start one (``due_at``)."""

    def __init__(self, zctx: zmq.Context, cfg: InterProcessPortalConfig, client_name: str, thread_name: str,
                 on_pollable: Callable[[zmq.Socket, bool], None], log: logging.Logger) -> None:
        self._zctx = zctx
        self._cfg = cfg
        self._client_name = client_name
        self._thread_name = thread_name
        self._on_pollable = on_pollable  # (socket, add?) for the owner's poller
        self._log = log
        self._query: EndpointQuery | None = None
        self.due_at: float | None = None  # when to (re)send the manager request for (possibly new) ports

    @property
    def socket(self) -> zmq.Socket | None:
        """The REQ socket of the query in flight, if any."""
        return None if self._query is None else self._query.socket

    def start(self, now: float) -> None:
        """Send a fresh request (dropping one in flight); the next is due ``REQUERY_TIMEOUT_S`` from ``now``."""
        self.drop()
        self.due_at = now + REQUERY_TIMEOUT_S
        try:
            self._query = EndpointQuery(self._zctx, self._cfg, self._client_name)
        except Exception as exc:  # noqa: BLE001 - cannot even connect: try again later
            self._log.debug("%s: cannot ask the manager yet (%s)", self._thread_name, exc)
            return
        self._on_pollable(self._query.socket, True)

    def cancel(self) -> None:
        """Connected again: no query, none due."""
        self.due_at = None
        self.drop()

    def drop(self) -> None:
        """Close the query in flight, if any."""
        if self._query is not None:
            self._on_pollable(self._query.socket, False)
            self._query.close()
            self._query = None

    def finish(self) -> tuple[int, tuple[str, str] | None]:
        """Read the answer once ``socket`` is readable: (events handled, the (publish, subscribe) endpoints or None
        if there is no answer yet or a broken one, which is asked again when ``due_at`` comes)."""
        assert self._query is not None
        try:
            pub, sub, _ = self._query.result()
        except zmq.Again:
            return 0, None
        except Exception as exc:  # noqa: BLE001 - a broken answer: ask again at the next retry
            self._log.warning("%s: %s", self._thread_name, exc)
            self.drop()
            return 1, None
        self.cancel()
        return 1, (pub, sub)
