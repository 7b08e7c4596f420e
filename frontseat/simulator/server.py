"""The simulator's TCP server (goby_basic_frontseat_simulator; console script ``frontseat.apps.frontseat_sim``).

One thread does everything on one :class:`~util.reactor.Reactor`: it accepts clients and splits their bytes into
``\\r\\n`` lines as they arrive, and a timer every ``1/(FREQ*WARP)`` real seconds feeds the lines received since
the last tick to the :class:`~frontseat.simulator.model.Simulation` and writes replies and NAV to every client (as
Goby's ``TCPServer::write`` with no destination does).  The timer runs only while the simulation is started or
lines wait, so an idle simulator sleeps.  A client can never take the server down: over-long lines, garbage and
abrupt disconnects are logged and dropped; a client that stops reading is disconnected.
"""

from __future__ import annotations

import logging
import socket
import threading

from frontseat.simulator.model import Simulation
from frontseat.simulator.protocol import LineSplitter, encode_lines
from util.reactor import Reactor, Timer
from util.tcp_fanout import FanOutClient, FanOutServer

log = logging.getLogger(__name__)

MAX_LINE = 64 * 1024  # bytes; longer lines are discarded (with an error logged)
MAX_BACKLOG = 1024 * 1024  # bytes queued for a client that is not reading before we drop it
RECV_SIZE = 65536


class SimulatorServer:
    """The basic frontseat simulator on ``host:port`` (``port=0`` picks a free one; read :attr:`port`).

    Either :meth:`run` it on the calling thread until :meth:`stop` (the console script), or :meth:`start` it on a
    thread of its own named ``frontseat-sim`` (tests); a context manager starts and stops it.  Only :meth:`stop`
    may be called from another thread (or a signal handler).
    """

    def __init__(self, host: str = "127.0.0.1", port: int = 0, simulation: Simulation | None = None) -> None:
        self.simulation = simulation if simulation is not None else Simulation()
        self._listener = socket.create_server((host, port), reuse_port=False)
        self.host, self.port = self._listener.getsockname()[:2]
        self._reactor = Reactor("frontseat-sim")
        self._clients = FanOutServer(self._reactor, self._listener, max_backlog=MAX_BACKLOG, recv_size=RECV_SIZE,
                                     on_data=self._on_data, new_state=lambda: LineSplitter(MAX_LINE),
                                     on_drop=self._on_drop)
        self._pending: list[str] = []
        self._tick_timer: Timer | None = None
        self._stopping = threading.Event()
        self._serving = False
        self._thread: threading.Thread | None = None
        self._closed = False

    # ----- lifecycle --------------------------------------------------------------------------------------
    def start(self) -> SimulatorServer:
        """Serve on a background thread named ``frontseat-sim`` (idempotent)."""
        if self._thread is None:
            self._thread = threading.Thread(target=self.run, name="frontseat-sim", daemon=True)
            self._serving = True  # from now on, running is true until the thread ends
            self._thread.start()
        return self

    def run(self) -> None:
        """Serve on the calling thread until :meth:`stop`; then disconnect every client and close the listener."""
        self._serving = True
        log.info("basic frontseat simulator listening on %s:%d", self.host, self.port)
        try:
            if not self._stopping.is_set():
                self._clients.start()
                self._reactor.run(until=self._stopping.is_set)
        except Exception:  # pragma: no cover - a bug; say so loudly rather than hang silently
            log.exception("simulator server loop failed")
            raise
        finally:
            self._serving = False
            self._close_all()

    def stop(self) -> None:
        """Stop serving, disconnect every client and close the listening socket. Idempotent; thread-safe."""
        self._stopping.set()
        self._reactor.stop()
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=10)
        if thread is None or not thread.is_alive():
            if not self._serving:
                self._close_all()

    def __enter__(self) -> SimulatorServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    @property
    def running(self) -> bool:
        """True while the server is serving (on its own thread or in :meth:`run`)."""
        thread = self._thread
        return self._serving and (thread is None or thread.is_alive())

    @property
    def client_count(self) -> int:
        return self._clients.client_count

    # ----- sockets (the serving thread) -------------------------------------------------------------------
    def _on_data(self, client: FanOutClient, data: bytes) -> None:
        splitter: LineSplitter = client.state
        lines = splitter.feed(data)
        if splitter.overflowed:
            log.error("client %s sent a line longer than %d bytes (lines must end with \\r\\n); "
                      "discarding it up to the next \\r\\n", client.peer, MAX_LINE)
        if lines:
            self._pending.extend(lines)
            self._keep_ticking()

    @staticmethod
    def _on_drop(client: FanOutClient) -> None:
        splitter: LineSplitter = client.state
        if splitter.partial:
            log.info("client %s left a partial line of %d bytes; discarded", client.peer, splitter.partial)

    def _keep_ticking(self) -> None:
        """Arm the tick timer (aligned to the simulation's period, read at every tick: a START may change it)."""
        if self._tick_timer is None or not self._tick_timer.active:
            self._tick_timer = self._reactor.call_every(lambda: self.simulation.period, self._tick)

    def _tick(self) -> None:
        lines, self._pending = self._pending, []
        out: list[str] = []
        for line in lines:
            out.extend(self.simulation.handle_line(line))
        out.extend(self.simulation.tick())
        if out:
            self._clients.broadcast(encode_lines(out))
        if not self.simulation.started and not self._pending and self._tick_timer is not None:
            self._tick_timer.cancel()  # nothing to simulate: sleep until a line arrives

    def _close_all(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._clients.close()
        self._reactor.close()
