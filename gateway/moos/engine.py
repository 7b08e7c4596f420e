"""The machinery under ``comms``: connection life cycle, the outgoing queue and the incoming path.

Threads (all daemon, all ended by ``close``):
- the I/O thread connects, handshakes, re-registers, runs the on-connect callback, then reads packets and
  runs active-queue routing and the on-mail callback; it reconnects by itself when the DB goes away;
- in asynchronous mode a writer thread sends queued messages in batches and the timing message every second.

Writes from application threads go straight to the socket when the link is idle (lowest latency) and are
batched by the writer thread when they come in bursts (throughput). A sender that outruns the link blocks in
``notify`` (back-pressure); nothing is dropped quietly. Messages are encoded when posted, so the outbox holds
bytes and a batch is framed with one join.

Accounting across DB restarts (docs/moos.md "Restarts"): a post while disconnected is refused (False, as
pymoos) and counted; what was queued when the link went down is sent, in order, after the reconnection. A
written batch is only *confirmed* when the DB has processed it: an asynchronous batch starts with a timing
message whose id the DB echoes after processing the packet, a synchronous one gets its reply. Batches written but
unconfirmed when the connection is lost (the message in flight at a crash) are reported undelivered through the
on-undelivered callback and a counter, never assumed sent; so are messages discarded by ``close``.

A confirmed message reaches the clients registered for it *when the DB processed it*. So that a restart does not
lose what is published before a subscriber has registered again, a client that publishes asks the DB every second
which clients subscribe to what (``PROC_SUMMARY``, as uMS does). After a reconnection, posts of a variable that had
other subscribers are refused (False, counted) and its queued mail is held until the DB lists those subscribers
again (polled every 50 ms; given up after ``RESUBSCRIBE_WAIT_S``, with a WARNING naming them). What to ask, hold
and release is decided by ``subscriber_watch.py``; this module sends, logs and moves the mail.
"""

from __future__ import annotations

import logging
import socket
import threading
import time as _time
from collections import deque
from collections.abc import Callable, Iterable

from .active_queue import ActiveQueueRouter
from .clock import MoosClock
from .codec import PacketReader, encode_fields, encode_message, frame_packet
from .connection import PacketSocket, Welcome, client_handshake, open_socket
from .errors import ConnectionClosedError, HandshakeError, MoosError, PoisonedError, ProtocolError
from .message import DOUBLE, NOTIFY, NULL_MSG, TIMING, TIMING_KEY, MoosMessage, to_bytes
from .subscriber_watch import (
    RESUBSCRIBE_WAIT_S,
    SubscriberWatch,
    is_summary_reply,
    parse_proc_summary,
    summary_request,
)

log = logging.getLogger(__name__)

TIMING_PERIOD_S = 1.0
WRITER_IDLE_WAKE_S = 0.333
RECONNECT_PERIOD_S = 1.0
DEFAULT_OUTBOX_LIMIT = 8192
DEFAULT_INBOX_LIMIT = 200_000
BURST_WINDOW_S = 0.0002  # a write sooner than this after the last one is left to the writer thread to batch

Callback = Callable[[], object]
UndeliveredCallback = Callable[[list[MoosMessage]], object]


class ClientEngine:
    """State and threads of one MOOS client; ``comms`` adds the pymoos-compatible API on top."""

    def __init__(self, asynchronous: bool, clock: MoosClock) -> None:
        self._async = asynchronous
        self._clock = clock
        self._lock = threading.Lock()
        self._cond = threading.Condition(self._lock)
        self._outbox: list[bytes] = []  # encoded messages, in post order
        self._outbox_limit = DEFAULT_OUTBOX_LIMIT
        self._busy = False  # a thread is writing to the socket
        self._live = False  # connected (a plain flag for the hot path; _connected is for waiting)
        self._writable = False  # live and on-connect has run: queued mail may go (after the re-registrations)
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
        # Written batches the DB has not confirmed yet: (confirmation token, encoded messages), oldest first.
        self._unconfirmed: deque[tuple[int, list[bytes]]] = deque()
        self._token = 0
        self._skew_token = -1  # the token of the last timing message sent to measure the skew (once a second)
        self._refused = 0  # posts refused because the link was down
        self._undelivered = 0  # accepted posts reported undelivered (in flight at a crash, or discarded by close)
        self._on_undelivered: UndeliveredCallback | None = None
        # Who else subscribes to the variables we publish, and what waits for them after a reconnection.
        self._watch = SubscriberWatch()
        self.welcome: Welcome | None = None  # the DB's last WELCOME (community, skew, DB time, hostname)

    @property
    def clock(self) -> MoosClock:
        """The :class:`MoosClock` this client stamps messages with and writes its skew into."""
        return self._clock

    def _reregister(self) -> None:
        """Send the remembered registrations again (the API layer fills this in)."""

    def _start_threads(self) -> None:
        self._stop.clear()
        self._io_thread = threading.Thread(target=self._io_loop, name=f"moos-comms-{self._name}", daemon=True)
        self._io_thread.start()
        if self._async:
            self._writer_thread = threading.Thread(
                target=self._writer_loop, name=f"moos-writer-{self._name}", daemon=True
            )
            self._writer_thread.start()

    def _stop_threads(self, nice: bool) -> None:
        """Optionally let queued messages go out (up to 2 s), then end the threads and the connection."""
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
            discarded, self._outbox = self._outbox, []
        if discarded:
            log.warning("%s: closed with %d message(s) still unsent; they are reported undelivered",
                        self._name, len(discarded))
            self._report_undelivered([discarded])

    # ---- outgoing path -----------------------------------------------------------------------------
    def _key(self, name: str) -> bytes:
        raw = self._keys.get(name)
        if raw is None:
            raw = to_bytes(name)
            if len(self._keys) < 10_000:
                self._keys[name] = raw
        return raw

    def _post(self, msg: MoosMessage, assign_id: bool = True) -> bool:
        """Queue ``msg`` with our name as its source (and the next id unless told otherwise)."""
        return self._post_fields(
            msg.msg_type, msg.data_type, msg.raw_key, msg.raw_aux, msg.msg_time, msg.dval, msg.raw_sval,
            None if assign_id else msg.msg_id,
        )

    def _post_fields(
        self, msg_type: bytes, data_type: bytes, key: bytes, aux: bytes, msg_time: float, dval: float,
        sval: bytes, msg_id: int | None = None,
    ) -> bool:
        """Encode a message at once and get it written: directly if the link is idle, else by the writer."""
        on_io_thread = threading.get_ident() == self._io_ident
        with self._lock:
            missing = self._watch.missing
            if not self._live or (missing and msg_type == NOTIFY and key in missing):
                self._refused += 1
                return False
            if msg_id is None:
                msg_id = self._next_id
                self._next_id += 1
            if not on_io_thread and len(self._outbox) >= self._outbox_limit:
                self._wait_for_space()
            self._outbox.append(
                encode_fields(msg_type, data_type, msg_id, self._src, aux, b"", key, msg_time, dval, -1.0, sval)
            )
            direct = (
                self._async
                and self._writable
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
        self._token += 1
        if batch:
            self._unconfirmed.append((self._token, batch))
        if self._async:  # every batch asks for the DB's confirmation: a timing message carrying the token
            now = _time.monotonic()
            if now - self._last_timing >= TIMING_PERIOD_S:  # the once-a-second one also measures the skew
                self._last_timing = now
                self._skew_token = self._token
            timing = MoosMessage(TIMING, DOUBLE, msg_id=self._token, key=TIMING_KEY,
                                 msg_time=self._clock.local_time(), dval=0.0)
            batch = [encode_message(timing), *batch]
        summary = self._summary_request(_time.monotonic())
        if summary is not None:
            batch.append(summary)
        if self._space_waiters:
            self._cond.notify_all()
        return batch, self._conn

    def _drain(self) -> None:
        """Write until the outbox is empty; the caller has set ``_busy``."""
        while True:
            with self._lock:
                if not self._outbox or self._conn is None or not self._writable:
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
                now = _time.monotonic()
                timing_due = self._last_timing + TIMING_PERIOD_S - now
                # while waiting for subscribers to register again, ask the DB soon
                timing_due = min(timing_due, self._watch.next_poll_in(now))
                if self._busy or not self._writable or (not self._outbox and timing_due > 0):
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
        with self._lock:  # what was queued while down, or by on-connect, goes now: after the re-registrations
            self._outbox = self._watch.reconnected(_time.monotonic(), self._outbox)
            self._writable = True
            self._cond.notify_all()
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
        except Exception:
            log.exception("%s: unexpected error on the I/O thread; reconnecting", self._name)

    def _disconnected(self, conn: PacketSocket) -> None:
        with self._lock:
            was_connected = self._live
            self._live = self._writable = False
            self._connected.clear()
            self._conn = None
            self._bytes_sent_total += conn.bytes_sent
            self._bytes_read_total += conn.bytes_read
            in_doubt = [batch for _, batch in self._unconfirmed]
            self._unconfirmed.clear()
            self._watch.lost()  # what we publish to others waits, after reconnecting, for them to be back
            self._cond.notify_all()
        conn.close()
        if in_doubt:
            log.warning("%s: %d message(s) written but not confirmed by the DB when the connection was lost; "
                        "reported undelivered", self._name, sum(map(len, in_doubt)))
            self._report_undelivered(in_doubt)
        if self._outbox and not self._stop.is_set():
            log.info("%s: %d queued message(s) will be sent after reconnecting", self._name, len(self._outbox))
        if was_connected:
            self._run_callback(self._on_disconnect, "on-disconnect")

    # ---- subscribers of what we publish (subscriber_watch.py decides) --------------------------------
    def _summary_request(self, now: float) -> bytes | None:
        """Under the lock: a ``PROC_SUMMARY`` request when one is due (we publish something), else None; gives up
        waiting for subscribers that have not come back within ``RESUBSCRIBE_WAIT_S``."""
        poll = self._watch.poll(now, bool(self._published))
        if poll.gave_up:
            log.warning("%s: subscriber(s) of %s did not register again within %.1f s of reconnecting; publishing "
                        "to those variables again", self._name,
                        ", ".join(sorted(k.decode(errors="replace") for k in poll.gave_up)), RESUBSCRIBE_WAIT_S)
            self._release_held(poll.release)
        return summary_request(self._src, self._clock.time()) if poll.ask else None

    def _release_held(self, held: list[bytes]) -> None:
        """Under the lock: held mail goes before anything queued since (it is older)."""
        if held:
            self._outbox[:0] = held
            self._cond.notify_all()

    def _on_summary(self, replies: list[MoosMessage]) -> None:
        """The DB's answer to our ``PROC_SUMMARY``; releases the variables whose subscribers are all back. Runs on
        the I/O thread."""
        published = [to_bytes(name) for name in list(self._published)]
        subscribers = parse_proc_summary((reply.raw_sval for reply in replies), self._src, published)
        with self._lock:
            released = self._watch.summary(subscribers)
            if released is not None:
                log.info("%s: the subscribers of what we publish have registered again", self._name)
                self._release_held(released)

    def _confirm(self, token: int | None) -> None:
        """The DB has processed every batch up to ``token`` (None: everything written)."""
        with self._lock:
            unconfirmed = self._unconfirmed
            while unconfirmed and (token is None or unconfirmed[0][0] <= token):
                unconfirmed.popleft()

    def _report_undelivered(self, batches: Iterable[list[bytes]]) -> None:
        """Count and hand over messages that were accepted but may not have reached the DB."""
        messages = [m for batch in batches for m in PacketReader(2**31 - 1).feed(frame_packet(batch))[0]]
        self._undelivered += len(messages)
        func = self._on_undelivered
        if func is not None and messages:
            try:
                func(messages)
            except Exception:
                log.exception("%s: on-undelivered callback raised; carrying on", self._name)

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
                    self._confirm(timing.msg_id)
                    if self._packets_read > 1 and self._correct_time and timing.msg_id == self._skew_token:
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
                if batch:
                    self._unconfirmed.append((0, batch))
                self._cond.notify_all()
            with self._lock:
                summary = self._summary_request(_time.monotonic())
            if summary is not None:
                batch = [*batch, summary]
            if not batch:
                batch = [encode_message(MoosMessage(NULL_MSG, DOUBLE, src=self._src))]
            tx = self._clock.local_time()
            self._write(conn, batch)
            with self._lock:
                self._busy = False
                self._cond.notify_all()
            reply = conn.read_packet()
            self._confirm(None)  # one reply per packet: the DB has processed what we wrote
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
        if self._watch.pending:
            summary = [m for m in mail if is_summary_reply(m)]
            if summary:
                self._on_summary(summary)
                mail = [m for m in mail if not is_summary_reply(m)]
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
