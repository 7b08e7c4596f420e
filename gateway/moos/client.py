"""``comms``: a pure-Python MOOS v10 client with pymoos's API (asynchronous by default, synchronous on request).

Threads (all daemon, all ended by ``close``):
- the I/O thread connects, handshakes, re-registers, runs the on-connect callback, then reads packets and
  runs active-queue routing and the on-mail callback; it reconnects by itself when the DB goes away;
- in asynchronous mode a writer thread sends queued messages in batches and the timing message every second.

Writes from application threads go straight to the socket when the link is idle (lowest latency) and are
batched by the writer thread when they come in bursts (throughput). A sender that outruns the link blocks in
``notify`` (back-pressure); nothing is dropped quietly.
"""

from __future__ import annotations

import logging
import socket
import threading
import time as _time
from collections import deque
from collections.abc import Callable

from .active_queue import ActiveQueueRouter, MessageCallback
from .clock import DEFAULT_CLOCK, MoosClock
from .codec import encode_message, frame_packet
from .connection import PacketSocket, Welcome, client_handshake, open_socket
from .errors import ConnectionClosedError, HandshakeError, MoosError, PoisonedError, ProtocolError
from .message import (
    BINARY,
    DOUBLE,
    NOTIFY,
    NULL_MSG,
    REGISTER,
    SERVER_REQUEST,
    SERVER_REQUEST_ID,
    STRING,
    TIMING,
    TIMING_KEY,
    UNREGISTER,
    WILDCARD_REGISTER,
    WILDCARD_UNREGISTER,
    MoosMessage,
    to_bytes,
)

log = logging.getLogger(__name__)

TIMING_PERIOD_S = 1.0
WRITER_IDLE_WAKE_S = 0.333
RECONNECT_PERIOD_S = 1.0
DEFAULT_OUTBOX_LIMIT = 8192
DEFAULT_INBOX_LIMIT = 200_000
BURST_WINDOW_S = 0.0002  # a write sooner than this after the last one is left to the writer thread to batch

Callback = Callable[[], object]


def wildcard_sval(var_pattern: str, app_pattern: str, interval: float) -> bytes:
    """The ``*``/``/`` payload exactly as C++ builds it (``MOOSAddValToString``; ``%g``-style interval)."""
    return to_bytes(f"AppPattern={app_pattern},VarPattern={var_pattern},Interval={float(interval):g}")


class comms:  # noqa: N801 - pymoos's class name
    """A MOOS client. Method names, signatures and semantics follow pymoos's ``comms``."""

    def __init__(self, asynchronous: bool = True, clock: MoosClock | None = None) -> None:
        self._async = asynchronous
        self._clock = clock or DEFAULT_CLOCK
        self._lock = threading.Lock()
        self._cond = threading.Condition(self._lock)
        self._outbox: list[bytes] = []  # encoded messages, in post order
        self._outbox_limit = DEFAULT_OUTBOX_LIMIT
        self._busy = False  # a thread is writing to the socket
        self._live = False  # connected (a plain flag for the hot path; _connected is for waiting)
        self._writer_waiting = False
        self._space_waiters = 0
        self._io_ident = -1
        self._src = b""
        self._keys: dict[str, bytes] = {}
        self._last_write = 0.0
        self._last_timing = 0.0
        self._out_delay = 0.0
        self._inbox: deque[MoosMessage] = deque()
        self._inbox_cond = threading.Condition()
        self._inbox_limit = DEFAULT_INBOX_LIMIT
        self._conn: PacketSocket | None = None
        self._connected = threading.Event()
        self._stop = threading.Event()
        self._running = False
        self._io_thread: threading.Thread | None = None
        self._writer_thread: threading.Thread | None = None
        self._host = ""
        self._port = 0
        self._name = ""
        self._community = ""
        self._db_hostname = ""
        self._next_id = 0
        self._comms_tick = 5.0
        self._quiet = False
        self._time_correction = True
        self._correct_time = True
        self._timewarp_scale = 0.2
        self._registered: dict[str, float] = {}
        self._wildcards: dict[tuple[str, str], float] = {}
        self._reregistered: set[tuple[str, float]] = set()
        self._published: set[str] = set()
        self._on_connect: Callback | None = None
        self._on_disconnect: Callback | None = None
        self._on_mail: Callback | None = None
        self._queues = ActiveQueueRouter()
        self._packets_read = 0
        self._messages_read = 0
        self._messages_sent = 0
        self._bytes_sent_total = 0
        self._bytes_read_total = 0
        self._fatal: MoosError | None = None
        self.welcome: Welcome | None = None  # the DB's last WELCOME (community, skew, DB time, hostname)

    # ---- lifecycle ---------------------------------------------------------------------------------
    def run(self, server: str, port: int, name: str, comms_tick: float = 5) -> bool:
        """Start connecting to the DB at ``server:port`` as ``name``; returns at once (False if running)."""
        with self._lock:
            if self._running:
                return False
            self._running = True
        self._host, self._port, self._name = server, int(port), name
        self._src = to_bytes(name)
        if comms_tick:
            self.set_comms_tick(comms_tick)
        self._stop.clear()
        self._io_thread = threading.Thread(target=self._io_loop, name=f"moos-comms-{name}", daemon=True)
        self._io_thread.start()
        if self._async:
            self._writer_thread = threading.Thread(target=self._writer_loop, name=f"moos-writer-{name}", daemon=True)
            self._writer_thread.start()
        return True

    def close(self, nice: bool = True) -> bool:
        """Stop the client: with ``nice`` first wait (up to 2 s) for queued messages to be sent. Idempotent."""
        if nice and self._live:
            deadline = _time.monotonic() + 2.0
            with self._lock:
                self._space_waiters += 1
                self._cond.notify_all()
                while (self._outbox or self._busy) and self._live and _time.monotonic() < deadline:
                    self._cond.wait(0.05)
                self._space_waiters -= 1
        self._stop.set()
        with self._lock:
            conn = self._conn
            self._cond.notify_all()
        if conn is not None:
            conn.shutdown()
        with self._inbox_cond:
            self._inbox_cond.notify_all()
        me = threading.current_thread()
        for thread in (self._writer_thread, self._io_thread):
            if thread is not None and thread is not me:
                thread.join(10.0)
        self._queues.stop_all()
        with self._lock:
            self._running = False
            self._outbox.clear()
        self._registered.clear()
        self._wildcards.clear()
        return True

    def __enter__(self) -> comms:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close(True)

    # ---- callbacks ---------------------------------------------------------------------------------
    def set_on_connect_callback(self, func: Callback) -> bool:
        """``func()`` runs on the client's I/O thread after every (re)connection; register there."""
        self._on_connect = func
        return True

    def set_on_disconnect_callback(self, func: Callback) -> bool:
        """``func()`` runs on the client's I/O thread when the connection is lost."""
        self._on_disconnect = func
        return True

    def set_on_mail_callback(self, func: Callback) -> bool:
        """``func()`` runs on the client's I/O thread after mail arrives; it should only wake its owner,
        which then calls :meth:`fetch` on its own thread (or call ``fetch`` right there, as pymoos scripts do)."""
        self._on_mail = func
        return True

    def has_mail_callback(self) -> bool:
        return self._on_mail is not None

    # ---- active queues -----------------------------------------------------------------------------
    def add_active_queue(self, queue_name: str, func: MessageCallback) -> bool:
        """Create a queue whose ``func(msg)`` runs on the queue's own thread, once per routed message."""
        return self._queues.add_queue(queue_name, func)

    def add_message_route_to_active_queue(self, queue_name: str, msg_name: str) -> bool:
        """Send notifications of ``msg_name`` to the queue instead of the inbox (False if no such queue)."""
        return self._queues.add_route(queue_name, to_bytes(msg_name))

    def add_wildcard_active_queue(self, queue_name: str, pattern: str, func: MessageCallback) -> bool:
        """Create (if needed) a queue for every notification whose name matches the MOOS wildcard ``pattern``."""
        if not self._queues.has_queue(queue_name):
            self._queues.add_queue(queue_name, func)
        return self._queues.add_route(queue_name, to_bytes(pattern), wildcard=True)

    def remove_message_route_to_active_queue(self, queue_name: str, msg_name: str) -> bool:
        return self._queues.remove_route(queue_name, to_bytes(msg_name))

    def remove_active_queue(self, queue_name: str) -> bool:
        return self._queues.remove_queue(queue_name)

    def has_active_queue(self, queue_name: str) -> bool:
        return self._queues.has_queue(queue_name)

    def print_message_to_active_queue_routing(self) -> None:
        print(self._queues.describe())

    # ---- publishing ------------------------------------------------------------------------------
    def notify(self, name: str, value: float | str | bytes, *args: object, time: float = -1.0) -> bool:
        """Publish ``value`` (float/int → double, str/bytes → string) as ``name``.

        Forms, as pymoos: ``notify(name, value)``, ``notify(name, value, time)``, ``notify(name, value, aux)``,
        ``notify(name, value, aux, time)``. ``time=-1`` means now (MOOS time). False if not connected.
        """
        aux: str = ""
        if len(args) == 1:
            if isinstance(args[0], str):
                aux = args[0]
            else:
                time = float(args[0])  # type: ignore[arg-type]
        elif len(args) == 2:
            aux, time = str(args[0]), float(args[1])  # type: ignore[arg-type]
        elif args:
            raise TypeError("notify(name, value[, aux_src][, time])")
        if time == -1.0:
            time = self._clock.time()
        if isinstance(value, str | bytes | bytearray):
            raw = to_bytes(value) if isinstance(value, str) else bytes(value)
            cut = raw.find(b"\0")
            if cut >= 0:
                log.warning("notify %s: string value truncated at its first NUL byte, as MOOS does; "
                            "use notify_binary for arbitrary bytes", name)
                raw = raw[:cut]
            msg = MoosMessage(NOTIFY, STRING, -1, b"", to_bytes(aux), b"", self._key(name), time, -1.0, -1.0, raw)
        else:
            msg = MoosMessage(NOTIFY, DOUBLE, -1, b"", to_bytes(aux), b"", self._key(name), time, float(value))
        self._published.add(name)
        return self._post(msg)

    def notify_binary(self, name: str, binary_data: bytes | str, time: float = -1.0) -> bool:
        """Publish raw bytes as a BINARY message (the only way to send arbitrary bytes, including NUL)."""
        if time == -1.0:
            time = self._clock.time()
        data = to_bytes(binary_data) if isinstance(binary_data, str) else bytes(binary_data)
        self._published.add(name)
        return self._post(MoosMessage(NOTIFY, BINARY, key=to_bytes(name), msg_time=time, sval=data))

    # ---- registration ------------------------------------------------------------------------------
    def register(self, name: str, *args: object) -> bool:
        """``register(var, interval=0)``, or the wildcard form ``register(var_pattern, app_pattern, interval)``.

        Registrations are remembered and sent again after every reconnection. False if not connected
        (the registration is still remembered and applied on connect).
        """
        if len(args) == 2:
            return self._wildcard(WILDCARD_REGISTER, name, str(args[0]), float(args[1]))  # type: ignore[arg-type]
        if len(args) > 2:
            raise TypeError("register(name, interval=0) or register(var_pattern, app_pattern, interval)")
        interval = float(args[0]) if args else 0.0  # type: ignore[arg-type]
        if not name:
            return False
        self._registered[name] = interval
        if (name, interval) in self._reregistered:
            self._reregistered.discard((name, interval))
            return True  # already sent on this connection by the automatic re-registration
        return self._post(MoosMessage(REGISTER, DOUBLE, key=to_bytes(name), msg_time=self._clock.time(), dval=interval))

    def unregister(self, name: str, app_pattern: str | None = None) -> bool:
        """``unregister(var)``, or ``unregister(var_pattern, app_pattern)`` for a wildcard registration."""
        if app_pattern is not None:
            self._wildcards.pop((name, app_pattern), None)
            return self._wildcard(WILDCARD_UNREGISTER, name, app_pattern, 0.0, remember=False)
        self._registered.pop(name, None)
        return self._post(MoosMessage(UNREGISTER, DOUBLE, key=to_bytes(name), msg_time=self._clock.time(), dval=0.0))

    def _wildcard(self, kind: bytes, var_pattern: str, app_pattern: str, interval: float, remember: bool = True) -> bool:
        if remember:
            self._wildcards[(var_pattern, app_pattern)] = interval
        msg = MoosMessage(kind, STRING, key=to_bytes(self._name), msg_time=self._clock.time(),
                          sval=wildcard_sval(var_pattern, app_pattern, interval))
        return self._post(msg)

    def is_registered_for(self, name: str) -> bool:
        return name in self._registered

    def get_registered(self) -> set[str]:
        return set(self._registered)

    def get_published(self) -> set[str]:
        return set(self._published)

    def server_request(self, what: str, timeout: float = 2.0) -> list[MoosMessage]:
        """Send a ``Q`` request (``ALL``, ``PROC_SUMMARY``, ``VAR_SUMMARY``, ``DB_CLEAR``) and collect replies.

        Replies (id -2) are taken out of the inbox; other mail stays for ``fetch``. The DB sends all replies
        to one request in one packet, so this returns as soon as they arrive (or ``[]`` after ``timeout``).
        """
        msg = MoosMessage(SERVER_REQUEST, STRING, msg_id=SERVER_REQUEST_ID, key=to_bytes(what), msg_time=self._clock.time())
        if not self._post(msg, assign_id=False):
            return []
        replies: list[MoosMessage] = []
        deadline = _time.monotonic() + timeout
        with self._inbox_cond:
            while _time.monotonic() < deadline:
                keep = [m for m in self._inbox if m.msg_id != SERVER_REQUEST_ID]
                got = [m for m in self._inbox if m.msg_id == SERVER_REQUEST_ID]
                if got:
                    self._inbox.clear()
                    self._inbox.extend(keep)
                    replies.extend(got)
                    break
                self._inbox_cond.wait(0.02)
        return replies

    # ---- reading mail ------------------------------------------------------------------------------
    def fetch(self) -> list[MoosMessage]:
        """All mail received since the last fetch, in arrival order (thread-safe)."""
        with self._inbox_cond:
            if not self._inbox:
                return []
            mail = list(self._inbox)
            self._inbox.clear()
            self._inbox_cond.notify_all()
        return mail

    # ---- state -------------------------------------------------------------------------------------
    def is_connected(self) -> bool:
        return self._live

    def wait_until_connected(self, n_ms: float) -> bool:
        """Block until connected or ``n_ms`` milliseconds pass."""
        return self._connected.wait(max(0.0, n_ms) / 1000.0)

    def is_running(self) -> bool:
        return self._running

    def is_asynchronous(self) -> bool:
        return self._async

    def get_community_name(self) -> str:
        return self._community if self._connected.is_set() else ""

    def get_moos_name(self) -> str:
        return self._name

    def get_description(self) -> str:
        return f"{self._host}:{self._port}"

    def get_db_hostname(self) -> str:
        return self._host

    def get_db_host_port(self) -> int:
        return self._port

    def get_db_host_name_as_seen_by_db(self) -> str:
        return self._db_hostname

    def get_fatal_error(self) -> MoosError | None:
        """The error that stopped the client for good (e.g. POISON for a duplicate name), if any."""
        return self._fatal

    def get_number_of_unread_messages(self) -> int:
        return len(self._inbox)

    def get_number_of_unsent_messages(self) -> int:
        return len(self._outbox)

    def get_number_bytes_sent(self) -> int:
        return self._bytes_sent_total + (self._conn.bytes_sent if self._conn else 0)

    def get_number_bytes_read(self) -> int:
        return self._bytes_read_total + (self._conn.bytes_read if self._conn else 0)

    def get_number_messages_sent(self) -> int:
        return self._messages_sent

    def get_number_message_read(self) -> int:
        return self._messages_read

    # ---- tuning (pymoos names) ---------------------------------------------------------------------
    def set_comms_tick(self, comms_tick: float) -> bool:
        """Synchronous mode's exchanges per MOOS second (1..200, as libMOOS caps it)."""
        self._comms_tick = min(200.0, max(1.0, float(comms_tick)))
        return True

    def set_quiet(self, quiet: bool) -> None:
        self._quiet = bool(quiet)

    def set_verbose_debug(self, verbose: bool) -> None:
        log.setLevel(logging.DEBUG if verbose else logging.NOTSET)

    def do_local_time_correction(self, enable: bool) -> None:
        self._time_correction = bool(enable)

    def set_comms_control_timewarp_scale_factor(self, scale_factor: float) -> None:
        self._timewarp_scale = min(10.0, max(0.0, float(scale_factor)))

    def get_comms_control_timewarp_scale_factor(self) -> float:
        return self._timewarp_scale

    def enable_comms_status_monitoring(self, enable: bool) -> None:
        """Subscribe to (or drop) DB_QOS and DB_RWSUMMARY, as libMOOS's monitoring does."""
        for var in ("DB_QOS", "DB_RWSUMMARY"):
            if enable:
                self.register(var, 0)
            else:
                self.unregister(var)

    def set_outbox_limit(self, limit: int) -> None:
        """Messages queued before ``notify`` blocks (back-pressure instead of libMOOS's silent drop)."""
        self._outbox_limit = max(1, int(limit))

    def set_inbox_limit(self, limit: int) -> None:
        """Unfetched messages before the reader stops reading (back-pressure instead of a silent purge)."""
        self._inbox_limit = max(1, int(limit))

    # ---- outgoing path -----------------------------------------------------------------------------
    def _key(self, name: str) -> bytes:
        raw = self._keys.get(name)
        if raw is None:
            raw = to_bytes(name)
            if len(self._keys) < 10_000:
                self._keys[name] = raw
        return raw

    def _post(self, msg: MoosMessage, assign_id: bool = True) -> bool:
        """Queue ``msg`` (encoded at once) and get it written: directly if the link is idle, else by the writer."""
        msg.raw_src = self._src
        on_io_thread = threading.get_ident() == self._io_ident
        with self._lock:
            if not self._live:
                return False
            if assign_id:
                msg.msg_id = self._next_id
                self._next_id += 1
            if not on_io_thread and len(self._outbox) >= self._outbox_limit:
                self._wait_for_space()
            self._outbox.append(encode_message(msg))
            direct = (
                self._async
                and not self._busy
                and not on_io_thread
                and self._out_delay <= 0.0
                and _time.monotonic() - self._last_write > BURST_WINDOW_S
            )
            if direct:
                self._busy = True
            elif self._writer_waiting:
                self._cond.notify()
        if direct:
            self._drain()
        return True

    def _wait_for_space(self) -> None:
        """Back-pressure: block (lock held by the caller) until the outbox drains below its limit."""
        self._space_waiters += 1
        try:
            while len(self._outbox) >= self._outbox_limit and self._live and not self._stop.is_set():
                if self._writer_waiting:
                    self._cond.notify()
                self._cond.wait(0.1)
        finally:
            self._space_waiters -= 1

    def _take_batch(self) -> tuple[list[bytes], PacketSocket | None]:
        """Under the lock: everything queued, with the timing message in front when one is due."""
        batch, self._outbox = self._outbox, []
        if self._async:
            now = _time.monotonic()
            if now - self._last_timing >= TIMING_PERIOD_S:
                self._last_timing = now
                timing = MoosMessage(TIMING, DOUBLE, key=TIMING_KEY, msg_time=self._clock.local_time(), dval=0.0)
                batch.insert(0, encode_message(timing))
        if self._space_waiters:
            self._cond.notify_all()
        return batch, self._conn

    def _drain(self) -> None:
        """Write until the outbox is empty; the caller has set ``_busy``."""
        while True:
            with self._lock:
                if not self._outbox or self._conn is None or not self._live:
                    self._busy = False
                    self._last_write = _time.monotonic()
                    if self._space_waiters:
                        self._cond.notify_all()
                    return
                batch, conn = self._take_batch()
            if not self._write(conn, batch):
                with self._lock:
                    self._busy = False
                    self._cond.notify_all()
                return

    def _write(self, conn: PacketSocket | None, batch: list[bytes]) -> bool:
        if conn is None:
            return False
        try:
            conn.send(frame_packet(batch))
        except ConnectionClosedError as exc:
            log.warning("%s: %d message(s) not sent, the connection failed while writing: %s",
                        self._name, len(batch), exc)
            conn.shutdown()
            return False
        self._messages_sent += len(batch)
        return True

    def _writer_loop(self) -> None:
        """Async writer: batch what is queued, keep the timing message going, honour the DB's delay."""
        while not self._stop.is_set():
            with self._lock:
                timing_due = self._last_timing + TIMING_PERIOD_S - _time.monotonic()
                if self._busy or not self._live or (not self._outbox and timing_due > 0):
                    self._writer_waiting = True
                    self._cond.wait(min(WRITER_IDLE_WAKE_S, max(timing_due, 0.001)))
                    self._writer_waiting = False
                    continue
                self._busy = True
                batch, conn = self._take_batch()
            ok = self._write(conn, batch)
            with self._lock:
                self._busy = False
                self._last_write = _time.monotonic()
                if self._space_waiters:
                    self._cond.notify_all()
            if ok and self._out_delay > 0.0:
                self._stop.wait(self._out_delay)

    # ---- I/O thread --------------------------------------------------------------------------------
    def _io_loop(self) -> None:
        self._io_ident = threading.get_ident()
        while not self._stop.is_set():
            try:
                conn = PacketSocket(open_socket(self._host, self._port))
            except OSError as exc:
                log.debug("%s: cannot reach the DB at %s:%d (%s); retrying", self._name, self._host, self._port, exc)
                self._stop.wait(RECONNECT_PERIOD_S)
                continue
            try:
                welcome = client_handshake(conn, self._name, self._async, self._clock)
            except PoisonedError as exc:
                log.error("%s: %s; giving up, as libMOOS does", self._name, exc)
                self._fatal = exc
                conn.close()
                return
            except (HandshakeError, OSError) as exc:
                log.warning("%s: handshake with %s:%d failed (%s); retrying", self._name, self._host, self._port, exc)
                conn.close()
                self._stop.wait(RECONNECT_PERIOD_S)
                continue
            try:
                self._serve(conn, welcome)
            finally:
                self._disconnected(conn)
            if not self._stop.is_set():
                self._stop.wait(RECONNECT_PERIOD_S)

    def _serve(self, conn: PacketSocket, welcome: Welcome) -> None:
        """One connection's life: apply the WELCOME, re-register, call on-connect, then read until it ends."""
        self.welcome = welcome
        self._community = welcome.community
        self._db_hostname = welcome.db_hostname
        same_host = welcome.db_hostname == socket.gethostname()
        self._correct_time = self._time_correction and (self._quiet or not same_host)
        if self._correct_time:
            self._clock.skew = welcome.skew
        self._packets_read = 0
        with self._lock:
            self._conn = conn
            self._last_timing = 0.0
            self._out_delay = 0.0
            self._live = True
            self._connected.set()
            self._cond.notify_all()
        log.info("%s: connected to %s:%d (community %r)", self._name, self._host, self._port, self._community)
        self._reregister()
        self._run_callback(self._on_connect, "on-connect")
        self._reregistered = set()  # only on-connect's repeats of the automatic registrations are skipped
        try:
            if self._async:
                self._read_async(conn)
            else:
                self._exchange_sync(conn)
        except ConnectionClosedError as exc:
            if not self._stop.is_set():
                log.warning("%s: lost the DB at %s:%d: %s", self._name, self._host, self._port, exc)
        except ProtocolError as exc:
            log.error("%s: malformed data from the DB, dropping the connection: %s", self._name, exc)

    def _reregister(self) -> None:
        self._reregistered = set()
        for name, interval in list(self._registered.items()):
            self._post(MoosMessage(REGISTER, DOUBLE, key=to_bytes(name), msg_time=self._clock.time(), dval=interval))
            self._reregistered.add((name, interval))
        for (var_pattern, app_pattern), interval in list(self._wildcards.items()):
            self._wildcard(WILDCARD_REGISTER, var_pattern, app_pattern, interval)

    def _disconnected(self, conn: PacketSocket) -> None:
        with self._lock:
            was_connected = self._live
            self._live = False
            self._connected.clear()
            self._conn = None
            self._bytes_sent_total += conn.bytes_sent
            self._bytes_read_total += conn.bytes_read
            self._cond.notify_all()
        conn.close()
        if self._outbox and not self._stop.is_set():
            log.info("%s: %d queued message(s) will be sent after reconnecting", self._name, len(self._outbox))
        if was_connected:
            self._run_callback(self._on_disconnect, "on-disconnect")

    def _run_callback(self, func: Callback | None, what: str) -> None:
        if func is None:
            return
        try:
            func()
        except Exception:
            log.exception("%s: %s callback raised; carrying on", self._name, what)

    def _read_async(self, conn: PacketSocket) -> None:
        while not self._stop.is_set():
            for packet in conn.read_packets():
                self._packets_read += 1
                if packet and packet[0].msg_type == TIMING:
                    timing = packet.pop(0)
                    if self._packets_read > 1 and self._correct_time:
                        self._clock.update_skew(timing.msg_time, timing.dval, self._clock.local_time())
                    self._out_delay = max(0.0, timing.dval2)
                elif packet and packet[0].msg_type == NULL_MSG and self._correct_time:
                    null = packet.pop(0)
                    now = self._clock.local_time()
                    self._clock.update_skew(now, null.dval, now)
                self._deliver(packet)

    def _exchange_sync(self, conn: PacketSocket) -> None:
        """Synchronous mode: one packet out (a NULL when idle), exactly one reply back, every comms tick."""
        while not self._stop.is_set():
            with self._lock:
                batch, self._outbox = self._outbox, []
                self._busy = bool(batch)
                self._cond.notify_all()
            if not batch:
                batch = [encode_message(MoosMessage(NULL_MSG, DOUBLE, src=self._src))]
            tx = self._clock.local_time()
            self._write(conn, batch)
            with self._lock:
                self._busy = False
                self._cond.notify_all()
            reply = conn.read_packet()
            rx = self._clock.local_time()
            self._packets_read += 1
            if reply and reply[0].msg_type == NULL_MSG:
                if self._correct_time:
                    self._clock.update_skew(tx, reply[0].dval, rx)
            self._deliver(reply)
            period = 1.0 / (self._comms_tick * self._clock.warp)
            with self._lock:
                if not self._outbox and not self._stop.is_set():
                    self._writer_waiting = True
                    self._cond.wait(period)
                    self._writer_waiting = False

    def _deliver(self, packet: list[MoosMessage]) -> None:
        """Route to active queues, append the rest to the inbox in order, then run the on-mail callback."""
        mail = [m for m in packet if m.msg_type != NULL_MSG]
        if not mail:
            return
        self._messages_read += len(mail)
        if self._queues:
            dispatch = self._queues.dispatch
            mail = [m for m in mail if not (m.msg_type == NOTIFY and dispatch(m))]
            if not mail:
                return
        with self._inbox_cond:
            while len(self._inbox) >= self._inbox_limit and not self._stop.is_set():
                log.warning("%s: %d unfetched messages; pausing reads until fetch() catches up",
                            self._name, len(self._inbox))
                self._inbox_cond.wait(1.0)
            self._inbox.extend(mail)
            self._inbox_cond.notify_all()
        if self._on_mail is not None:
            self._run_callback(self._on_mail, "on-mail")
