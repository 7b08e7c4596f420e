"""A TCP connection for ``\\r\\n``-delimited line protocols that keeps itself up, on its owner's reactor.

No thread of its own: the socket is non-blocking and registered on the owner's :class:`~util.reactor.Reactor` (the
frontseat interface's main thread), so each line is handed to ``on_line`` as soon as it arrives.  Connecting is
non-blocking too; a failed or lost connection is retried by a timer every ``reconnect_interval`` seconds.  Writes
queue at most ``max_pending`` bytes and are flushed while the socket is writable; a peer that stops reading is
detected (no progress for ``io_timeout`` seconds, or the queue full) and the link is re-established, so the
owner's thread never blocks on the frontseat.

Threading: every method, and every callback (``on_line``, ``on_connect``, ``on_disconnect``), runs on the reactor's
thread.
"""

from __future__ import annotations

import errno
import logging
import os
import socket
import time
from collections.abc import Callable

from frontseat.simulator.protocol import LineSplitter, encode_lines
from util.reactor import Reactor, Timer

log = logging.getLogger(__name__)

RECV_SIZE = 65536
_IN_PROGRESS = (errno.EINPROGRESS, errno.EWOULDBLOCK, errno.EALREADY)


def _ignore() -> None:
    return None


class LineConnection:
    """Keeps a TCP connection to ``host:port`` up and passes it lines both ways; call :meth:`start`, then
    :meth:`write_line`; :meth:`close` when done (idempotent).  A context manager."""

    def __init__(
        self,
        reactor: Reactor,
        host: str,
        port: int,
        *,
        on_line: Callable[[str], None],
        on_connect: Callable[[], None] = _ignore,
        on_disconnect: Callable[[], None] = _ignore,
        reconnect_interval: float = 1.0,
        max_line: int = 64 * 1024,
        max_pending: int = 1024 * 1024,
        io_timeout: float = 5.0,
        name: str = "line-client",
    ) -> None:
        self.host, self.port = host, port
        self.reconnect_interval = max(0.01, reconnect_interval)
        self.max_line = max_line
        self.max_pending = max_pending
        self.io_timeout = io_timeout  # how long a connect, or a write that makes no progress, may take
        self.name = name
        self._reactor = reactor
        self._on_line = on_line
        self._on_connect = on_connect
        self._on_disconnect = on_disconnect
        self._sock: socket.socket | None = None  # connected
        self._connecting: socket.socket | None = None  # connect in progress
        self._addresses: list[tuple[int, int, int, tuple[object, ...]]] = []  # left to try in this attempt
        self._splitter = LineSplitter(max_line)
        self._outbuf = bytearray()
        self._writing = False
        self._last_progress = 0.0
        self._retry: Timer | None = None
        self._deadline: Timer | None = None  # connect timeout, or write-stall check
        self._failures = 0
        self._started = False
        self._closed = False

    @property
    def address(self) -> str:
        return f"{self.host}:{self.port}"

    @property
    def connected(self) -> bool:
        return self._sock is not None

    @property
    def pending(self) -> int:
        """Bytes written and not yet accepted by the socket."""
        return len(self._outbuf)

    def start(self) -> LineConnection:
        """Begin connecting, from the reactor (so no callback runs inside this call); idempotent."""
        if not self._started and not self._closed:
            self._started = True
            self._retry = self._reactor.call_later(0.0, self._attempt)
        return self

    def close(self) -> None:
        """Disconnect and stop retrying (no ``on_disconnect``); idempotent."""
        if self._closed:
            return
        self._closed = True
        self._cancel_timers()
        for sock in (self._sock, self._connecting):
            if sock is not None:
                self._release(sock)
        self._sock = self._connecting = None
        if self._outbuf:
            log.info("%s: %d unsent byte(s) discarded at close", self.address, len(self._outbuf))
        self._outbuf.clear()

    def __enter__(self) -> LineConnection:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ----- writing ----------------------------------------------------------------------------------------
    def write_line(self, line: str) -> bool:
        """Queue ``line`` plus ``\\r\\n`` and send what the socket takes now; False (nothing queued) when not
        connected, when the line alone is over ``max_pending``, or when the peer has stopped reading (then the
        link is re-established)."""
        sock = self._sock
        if sock is None:
            return False
        data = encode_lines([line])
        if len(data) > self.max_pending:
            log.error("%s: line of %d bytes not sent: over the output bound of %d bytes",
                      self.address, len(data), self.max_pending)
            return False
        if len(self._outbuf) + len(data) > self.max_pending:
            self._lost(f"the peer is not reading ({len(self._outbuf)} bytes queued)", log.error)
            return False
        self._outbuf += data
        if not self._writing:
            self._flush()
        return self._sock is sock  # False if the send failed and took the connection with it

    def _flush(self) -> None:
        sock = self._sock
        if sock is None:
            return
        try:
            sent = sock.send(self._outbuf)
        except (BlockingIOError, InterruptedError):
            sent = 0
        except OSError as exc:
            self._lost(f"write failed: {exc}", log.warning)
            return
        if sent:
            del self._outbuf[:sent]
            self._last_progress = time.monotonic()
        if self._outbuf and not self._writing:
            self._writing = True
            self._last_progress = time.monotonic()
            self._reactor.add_writer(sock, self._flush)
            self._arm_deadline(self.io_timeout, self._check_stall)
        elif not self._outbuf and self._writing:
            self._writing = False
            self._reactor.remove_writer(sock)
            self._cancel_deadline()

    def _check_stall(self) -> None:
        if not self._writing:
            return
        idle = time.monotonic() - self._last_progress
        if idle >= self.io_timeout:
            self._lost(f"write made no progress for {self.io_timeout:.1f} s ({len(self._outbuf)} bytes queued)",
                       log.error)
        else:
            self._arm_deadline(self.io_timeout - idle, self._check_stall)

    # ----- reading ----------------------------------------------------------------------------------------
    def _read(self) -> None:
        sock = self._sock
        if sock is None:
            return
        try:
            data = sock.recv(RECV_SIZE)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as exc:
            self._lost(f"read failed: {exc}", log.warning)
            return
        if not data:
            self._lost("closed by the peer", log.warning)
            return
        lines = self._splitter.feed(data)
        if self._splitter.overflowed:
            log.error("%s sent a line longer than %d bytes; discarding it", self.address, self.max_line)
        for line in lines:
            try:
                self._on_line(line)
            except Exception:
                log.exception("%s: handling line %r failed; continuing", self.address, line[:200])
            if self._sock is not sock:  # the handler closed or lost the link: the rest belongs to no connection
                return

    # ----- connecting -------------------------------------------------------------------------------------
    def _attempt(self) -> None:
        self._retry = None
        try:  # an address resolves at once; a host name may ask the resolver (the only wait this link has)
            infos = socket.getaddrinfo(self.host, self.port, type=socket.SOCK_STREAM)
        except OSError as exc:
            self._failed(f"cannot resolve {self.host}: {exc}")
            return
        self._addresses = [(family, kind, proto, address) for family, kind, proto, _, address in infos]
        self._next_address("")

    def _next_address(self, why: str) -> None:
        while self._addresses:
            family, kind, proto, address = self._addresses.pop(0)
            try:
                sock = socket.socket(family, kind, proto)
            except OSError as exc:
                why = str(exc)
                continue
            sock.setblocking(False)
            code = sock.connect_ex(address)
            if code == 0:
                self._connected(sock)
                return
            if code in _IN_PROGRESS:
                self._connecting = sock
                self._reactor.add_writer(sock, self._connect_finished)
                self._arm_deadline(self.io_timeout, self._connect_timed_out)
                return
            why = f"[Errno {code}] {os.strerror(code)}"
            sock.close()
        self._failed(why or "no address")

    def _connect_finished(self) -> None:
        sock = self._connecting
        if sock is None:
            return
        self._connecting = None
        self._reactor.remove_writer(sock)
        self._cancel_deadline()
        code = sock.getsockopt(socket.SOL_SOCKET, socket.SO_ERROR)
        if code == 0:
            self._connected(sock)
        else:
            sock.close()
            self._next_address(f"[Errno {code}] {os.strerror(code)}")

    def _connect_timed_out(self) -> None:
        sock, self._connecting = self._connecting, None
        if sock is not None:
            self._release(sock)
            self._next_address(f"no answer within {self.io_timeout:.1f} s")

    def _connected(self, sock: socket.socket) -> None:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._sock = sock
        self._failures = 0
        self._splitter = LineSplitter(self.max_line)
        self._reactor.add_reader(sock, self._read)
        log.info("connected to %s", self.address)
        self._notify(self._on_connect)

    def _failed(self, why: str) -> None:
        self._failures += 1
        # one warning, then quiet retries, so an absent peer does not flood the log
        (log.warning if self._failures == 1 else log.debug)("cannot connect to %s: %s", self.address, why)
        self._schedule_retry()

    def _lost(self, why: str, level: Callable[..., None]) -> None:
        sock, self._sock = self._sock, None
        if sock is None:
            return
        self._cancel_deadline()
        self._release(sock)
        if self._outbuf:
            log.warning("%s: %d unsent byte(s) discarded with the connection", self.address, len(self._outbuf))
        self._outbuf.clear()
        if self._splitter.partial:
            log.info("%s: a partial line of %d bytes discarded with the connection", self.address,
                     self._splitter.partial)
        level("connection to %s lost: %s; retrying every %.1f s", self.address, why, self.reconnect_interval)
        self._schedule_retry()
        self._notify(self._on_disconnect)

    # ----- helpers ----------------------------------------------------------------------------------------
    def _notify(self, callback: Callable[[], None]) -> None:
        """Run the owner's connect/disconnect callback; a failure in it is logged, the link carries on."""
        try:
            callback()
        except Exception:
            log.exception("%s: the %s callback failed; continuing", self.address, getattr(callback, "__name__", ""))

    def _release(self, sock: socket.socket) -> None:
        """Unregister (while the descriptor is still valid) and close."""
        if not self._reactor.closed:
            self._reactor.remove_reader(sock)
            self._reactor.remove_writer(sock)
        self._writing = False
        try:
            sock.close()
        except OSError:
            pass

    def _schedule_retry(self) -> None:
        if not self._closed and self._retry is None and not self._reactor.closed:
            self._retry = self._reactor.call_later(self.reconnect_interval, self._attempt)

    def _arm_deadline(self, delay: float, fn: Callable[[], None]) -> None:
        self._cancel_deadline()
        self._deadline = self._reactor.call_later(delay, fn)

    def _cancel_deadline(self) -> None:
        if self._deadline is not None:
            self._deadline.cancel()
            self._deadline = None

    def _cancel_timers(self) -> None:
        self._cancel_deadline()
        if self._retry is not None:
            self._retry.cancel()
            self._retry = None
