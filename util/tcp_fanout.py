"""A TCP server on a reactor that writes the same bytes to every connected client.

Why one: the frontseat simulator's line protocol and the OpenCPN interface's AIS sentences both fan bytes out to
whoever is connected. Writes never block; a client whose unsent bytes pass ``max_backlog`` (it stopped reading) or
whose socket fails is dropped with one line, and the others carry on. What a client sends goes to ``on_data``.
"""

from __future__ import annotations

import contextlib
import logging
import socket
from collections.abc import Callable
from typing import Any

from util.reactor import Reactor
from util.sockets import accept_client

log = logging.getLogger(__name__)


class FanOutClient:
    """One connected client: its socket, peer address, unsent bytes, and whatever state its owner keeps."""

    __slots__ = ("sock", "peer", "outbuf", "state")

    def __init__(self, sock: socket.socket, peer: str, state: Any = None) -> None:
        self.sock = sock
        self.peer = peer
        self.outbuf = bytearray()
        self.state = state


class FanOutServer:
    """Serves ``listener`` (bound, listening) on ``reactor`` once :meth:`start`\\ ed; runs on the reactor's thread.

    ``on_data(client, data)`` gets what a client sends; ``new_state()`` makes each client's ``state``;
    ``on_drop(client)`` runs as a client goes.
    """

    def __init__(self, reactor: Reactor, listener: socket.socket, *, max_backlog: int, recv_size: int = 65536,
                 on_data: Callable[[FanOutClient, bytes], None] | None = None,
                 new_state: Callable[[], Any] | None = None,
                 on_drop: Callable[[FanOutClient], None] | None = None) -> None:
        self._reactor = reactor
        self._listener = listener
        self._max_backlog = max_backlog
        self._recv_size = recv_size
        self._on_data = on_data
        self._new_state = new_state
        self._on_drop = on_drop
        self._clients: dict[socket.socket, FanOutClient] = {}
        listener.setblocking(False)

    @property
    def client_count(self) -> int:
        return len(self._clients)

    def start(self) -> None:
        self._reactor.add_reader(self._listener, self._accept)

    def broadcast(self, payload: bytes) -> None:
        """Queue ``payload`` for every client and write what each socket takes now."""
        for client in list(self._clients.values()):
            client.outbuf += payload
            if len(client.outbuf) > self._max_backlog:
                self._drop(client, f"not reading ({len(client.outbuf)} bytes queued)")
                continue
            self._flush(client)

    def close(self) -> None:
        """Disconnect every client and close the listener (idempotent)."""
        for client in list(self._clients.values()):
            self._drop(client, "closed by server shutdown")
        if self._listener.fileno() >= 0:
            with contextlib.suppress(Exception):  # the reactor may be closed already
                self._reactor.remove_reader(self._listener)
            self._listener.close()

    def _accept(self) -> None:
        accepted = accept_client(self._listener)
        if accepted is None:
            return
        sock, peer = accepted
        client = FanOutClient(sock, peer, self._new_state() if self._new_state is not None else None)
        self._clients[sock] = client
        self._reactor.add_reader(sock, lambda: self._read(client))
        log.info("client %s connected (%d connected)", peer, len(self._clients))

    def _read(self, client: FanOutClient) -> None:
        try:
            data = client.sock.recv(self._recv_size)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as exc:
            self._drop(client, f"read failed: {exc}")
            return
        if not data:
            self._drop(client, "disconnected")
        elif self._on_data is not None:
            self._on_data(client, data)

    def _flush(self, client: FanOutClient) -> None:
        try:
            sent = client.sock.send(client.outbuf)
        except (BlockingIOError, InterruptedError):
            sent = 0
        except OSError as exc:
            self._drop(client, f"write failed: {exc}")
            return
        del client.outbuf[:sent]
        if client.outbuf:
            self._reactor.add_writer(client.sock, lambda: self._flush(client))
        else:
            self._reactor.remove_writer(client.sock)

    def _drop(self, client: FanOutClient, why: str) -> None:
        if self._clients.pop(client.sock, None) is None:
            return
        if self._on_drop is not None:
            self._on_drop(client)
        log.info("client %s %s (%d connected)", client.peer, why, len(self._clients))
        self._reactor.remove_reader(client.sock)
        self._reactor.remove_writer(client.sock)
        client.sock.close()
