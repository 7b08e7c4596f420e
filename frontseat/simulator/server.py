"""The simulator's TCP server (goby_basic_frontseat_simulator; console script ``frontseat.apps.frontseat_sim``).

One thread does everything with ``selectors``: it accepts clients, splits their bytes into ``\\r\\n`` lines,
and every ``1/(FREQ*WARP)`` real seconds feeds the lines received since the last tick to the
:class:`~frontseat.simulator.model.Simulation` and writes replies and NAV to every client (as Goby's
``TCPServer::write`` with no destination does). A client can never take the server down: over-long lines,
garbage and abrupt disconnects are logged and dropped; a client that stops reading is disconnected.
"""

from __future__ import annotations

import logging
import selectors
import socket
import threading
import time
from dataclasses import dataclass, field

from frontseat.simulator.model import Simulation
from frontseat.simulator.protocol import LineSplitter, encode_lines
from util.sockets import accept_client

log = logging.getLogger(__name__)

MAX_LINE = 64 * 1024  # bytes; longer lines are discarded (with an error logged)
MAX_BACKLOG = 1024 * 1024  # bytes queued for a client that is not reading before we drop it
MAX_LAG = 1.0  # seconds behind schedule before the tick clock is reset instead of catching up


@dataclass
class _Client:
    sock: socket.socket
    peer: str
    lines: LineSplitter = field(default_factory=lambda: LineSplitter(MAX_LINE))
    outbuf: bytearray = field(default_factory=bytearray)


class SimulatorServer:
    """The basic frontseat simulator on ``host:port`` (``port=0`` picks a free one; read :attr:`port`).

    Use as a context manager or call :meth:`start` / :meth:`stop`; the server runs on its own thread.
    """

    def __init__(self, host: str = "127.0.0.1", port: int = 0, simulation: Simulation | None = None) -> None:
        self.simulation = simulation if simulation is not None else Simulation()
        self._listener = socket.create_server((host, port), reuse_port=False)
        self._listener.setblocking(False)
        self.host, self.port = self._listener.getsockname()[:2]
        self._selector = selectors.DefaultSelector()
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._clients: dict[socket.socket, _Client] = {}
        self._pending: list[str] = []
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None
        self._closed = False

    # ----- lifecycle --------------------------------------------------------------------------------------
    def start(self) -> SimulatorServer:
        """Start serving on a background thread named ``frontseat-sim``."""
        if self._thread is not None:
            return self
        self._thread = threading.Thread(target=self._serve, name="frontseat-sim", daemon=True)
        self._thread.start()
        log.info("basic frontseat simulator listening on %s:%d", self.host, self.port)
        return self

    def stop(self) -> None:
        """Stop serving, disconnect every client and close the listening socket. Idempotent."""
        self._stopping.set()
        try:
            self._wake_w.send(b"x")
        except OSError:
            pass
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=10)
        if self._thread is None or not self._thread.is_alive():
            self._close_all()

    def __enter__(self) -> SimulatorServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    @property
    def running(self) -> bool:
        """True while the serving thread is alive."""
        return self._thread is not None and self._thread.is_alive()

    @property
    def client_count(self) -> int:
        return len(self._clients)

    # ----- the loop ---------------------------------------------------------------------------------------
    def _serve(self) -> None:
        self._selector.register(self._listener, selectors.EVENT_READ, "accept")
        self._selector.register(self._wake_r, selectors.EVENT_READ, "wake")
        next_tick = time.monotonic()
        try:
            while not self._stopping.is_set():
                timeout = max(0.0, next_tick - time.monotonic())
                for key, events in self._selector.select(timeout):
                    self._on_event(key, events)
                now = time.monotonic()
                if now >= next_tick:
                    self._tick()
                    next_tick += self.simulation.period
                    if now - next_tick > MAX_LAG:
                        log.warning("simulator fell %.1f s behind schedule; skipping ahead", now - next_tick)
                        next_tick = now
        except Exception:  # pragma: no cover - a bug; say so loudly rather than hang silently
            log.exception("simulator server loop failed")
            raise
        finally:
            self._close_all()

    def _on_event(self, key: selectors.SelectorKey, events: int) -> None:
        if key.data == "accept":
            self._accept()
        elif key.data == "wake":
            try:
                self._wake_r.recv(4096)
            except OSError:
                pass
        else:
            client = key.data
            if events & selectors.EVENT_READ:
                self._read(client)
            if events & selectors.EVENT_WRITE and client.sock in self._clients:
                self._flush(client)

    def _accept(self) -> None:
        accepted = accept_client(self._listener)
        if accepted is None:
            return
        sock, peer = accepted
        client = _Client(sock, peer)
        self._clients[sock] = client
        self._selector.register(sock, selectors.EVENT_READ, client)
        log.info("client %s connected (%d connected)", client.peer, len(self._clients))

    def _read(self, client: _Client) -> None:
        try:
            data = client.sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as exc:
            self._drop(client, f"read failed: {exc}")
            return
        if not data:
            self._drop(client, "disconnected")
            return
        self._pending.extend(client.lines.feed(data))
        if client.lines.overflowed:
            log.error("client %s sent a line longer than %d bytes (lines must end with \\r\\n); "
                      "discarding it up to the next \\r\\n", client.peer, MAX_LINE)

    def _tick(self) -> None:
        lines, self._pending = self._pending, []
        out: list[str] = []
        for line in lines:
            out.extend(self.simulation.handle_line(line))
        out.extend(self.simulation.tick())
        if out:
            self._broadcast(encode_lines(out))

    def _broadcast(self, payload: bytes) -> None:
        for client in list(self._clients.values()):
            client.outbuf += payload
            if len(client.outbuf) > MAX_BACKLOG:
                self._drop(client, f"not reading ({len(client.outbuf)} bytes queued)")
                continue
            self._flush(client)

    def _flush(self, client: _Client) -> None:
        try:
            sent = client.sock.send(client.outbuf)
        except (BlockingIOError, InterruptedError):
            sent = 0
        except OSError as exc:
            self._drop(client, f"write failed: {exc}")
            return
        del client.outbuf[:sent]
        events = selectors.EVENT_READ | (selectors.EVENT_WRITE if client.outbuf else 0)
        self._selector.modify(client.sock, events, client)

    def _drop(self, client: _Client, why: str) -> None:
        if self._clients.pop(client.sock, None) is None:
            return
        if client.lines.partial:
            log.info("client %s left a partial line of %d bytes; discarded", client.peer, client.lines.partial)
        log.info("client %s %s (%d connected)", client.peer, why, len(self._clients))
        try:
            self._selector.unregister(client.sock)
        except (KeyError, ValueError):
            pass
        client.sock.close()

    def _close_all(self) -> None:
        if self._closed:
            return
        self._closed = True
        for client in list(self._clients.values()):
            self._drop(client, "closed by server shutdown")
        self._selector.close()
        for sock in (self._listener, self._wake_r, self._wake_w):
            sock.close()
