"""The machinery under ``comms``: connection life cycle, the outgoing queue and the incoming path, on one reactor.

Threads. Everything here runs on one :class:`util.reactor.Reactor`: the client's own ``moos-comms-<name>`` thread,
or, with ``comms(reactor=r)``, the thread that runs ``r`` (then the client has no thread at all). That thread
connects (non-blocking), handshakes, re-registers, runs on-connect, reads packets, calls the active queues and
on-mail, writes what application threads left to it, and reconnects; the timing message, the reconnection and the
PROC_SUMMARY polls are timers. Nothing polls on a period: an idle client wakes once a second (the timing message
that keeps the connection alive).

Writing. Application threads encode at ``notify`` and queue bytes. When the link is idle the posting thread writes
the packet itself (lowest latency, no hand-off); in a burst (a write within ``BURST_WINDOW_S`` of the last) it
posts one flush to the reactor, which writes everything queued by then as one packet. The socket is non-blocking:
what the kernel does not take is finished by the reactor (``add_writer``). A sender that outruns the link blocks in
``notify`` once ``set_outbox_limit`` messages wait (back-pressure); on the reactor's own thread, which cannot wait
for itself, ``notify`` writes out synchronously instead. Posts made on the reactor thread are written at the end
of the callback that made them (one packet for an on-mail callback's replies).

Accounting across DB restarts (docs/moos.md "Restarts"): a post while disconnected is refused (False, as
pymoos) and counted; what was queued when the link went down is sent, in order, after the reconnection. A
written batch is *confirmed* when the DB has processed it: an asynchronous packet may start with a timing message
whose id the DB echoes after processing the packet (MOOSDB and ours both do), which confirms it and everything
before; a synchronous one gets its reply. A packet carries a timing message when ``CONFIRM_INTERVAL_S`` has passed
since the last one (so a lone post is confirmed at once and a stream about every 0.1 s, not every packet: each echo
costs the DB a write and the client a wake-up), and at least once a second (that one also measures the skew).
Batches written but unconfirmed when the connection is lost are reported undelivered through the on-undelivered
callback and a counter, never assumed sent; so are messages ``close`` could not get confirmed.

A confirmed message reaches the clients registered for it *when the DB processed it*. So that a restart does not
lose what is published before a subscriber has registered again, a client that publishes asks the DB once a second
which clients subscribe to what (``PROC_SUMMARY``, in the packet of the once-a-second timing message, so it costs
no extra packet or wake-up; an unchanged answer is not parsed again). After a reconnection, posts of a variable
that had other subscribers are refused (False, counted) and its queued mail is held until the DB lists those
subscribers again (asked every 50 ms; given up after ``RESUBSCRIBE_WAIT_S``, with a WARNING naming them). What to
ask, hold and release is decided by ``subscriber_watch.py``; this module sends, logs and moves the mail.
"""

from __future__ import annotations

import logging
import math
import os
import select
import socket
import threading
import time as _time
from collections import deque
from collections.abc import Callable, Iterable

from util.reactor import Reactor, ReactorClosedError, Timer

from .active_queue import ActiveQueueRouter
from .clock import MoosClock
from .codec import PacketReader, encode_fields, encode_message, frame_packet
from .connection import (
    RECV_BYTES,
    Welcome,
    close_socket,
    connect_error,
    hello_bytes,
    parse_welcome,
    resolve,
    start_connect,
)
from .errors import HandshakeError, MoosError, PoisonedError, ProtocolError
from .message import DOUBLE, NOTIFY, NULL_MSG, TIMING, TIMING_KEY, MoosMessage, to_bytes
from .subscriber_watch import (
    RESUBSCRIBE_POLL_S,
    RESUBSCRIBE_WAIT_S,
    SubscriberWatch,
    is_summary_reply,
    parse_proc_summary,
    summary_request,
)

log = logging.getLogger(__name__)

TIMING_PERIOD_S = 1.0  # a timing message at least this often: keeps the link alive, measures the skew
CONFIRM_INTERVAL_S = 0.1  # a packet asks for the DB's confirmation when this long passed since the last ask
RECONNECT_PERIOD_S = 1.0
HANDSHAKE_TIMEOUT_S = 10.0
CLOSE_GRACE_S = 2.0  # close(nice=True) waits this long for queued mail to be written and confirmed
DEFAULT_OUTBOX_LIMIT = 8192
DEFAULT_INBOX_LIMIT = 200_000
BURST_WINDOW_S = 0.0002  # a write sooner than this after the last one is left to the reactor to batch
MAX_BATCH_BYTES = 4 * 1024 * 1024  # one packet's messages (the DB's default packet cap is 64 MiB)

STOPPED, WAITING, CONNECTING, HANDSHAKE, LIVE = range(5)

Callback = Callable[[], object]
UndeliveredCallback = Callable[[list[MoosMessage]], object]


def _try_send(sock: socket.socket, data: bytes | memoryview) -> tuple[int, str]:
    """One non-blocking ``send``: the bytes the kernel took, and why the link failed ("" if it did not)."""
    try:
        return sock.send(data), ""
    except (BlockingIOError, InterruptedError):
        return 0, ""
    except OSError as exc:
        return 0, f"send failed: {exc}"


class ClientEngine:
    """State and reactor work of one MOOS client; ``comms`` adds the pymoos-compatible API on top."""

    def __init__(self, asynchronous: bool, clock: MoosClock, reactor: Reactor | None = None) -> None:
        self._async = asynchronous
        self._clock = clock
        self._given_reactor = reactor
        self._reactor: Reactor | None = reactor
        self._thread: threading.Thread | None = None
        self._lock = threading.Lock()
        self._cond = threading.Condition(self._lock)  # outbox space, confirmations at close, teardown done
        # ---- shared with application threads (under _lock) ----
        self._outbox: list[bytes] = []  # encoded messages, in post order
        self._outbox_bytes = 0
        self._outbox_limit = DEFAULT_OUTBOX_LIMIT
        self._space_waiters = 0
        self._running = False
        self._live = False  # connected (WELCOME received)
        self._writable = False  # live and on-connect has run: queued mail may go (after the re-registrations)
        self._writing = False  # a thread is inside send() on the socket
        self._pending: memoryview | None = None  # the unsent tail of a packet: the reactor's writer finishes it
        self._flush_scheduled = False  # a flush is posted to (or scheduled on) the reactor
        self._close_after_write: socket.socket | None = None  # lost while another thread was writing to it
        self._closing = False  # close(nice) is waiting: every packet asks for confirmation
        self._last_write = 0.0
        self._last_timing = -math.inf  # when a packet last asked for confirmation
        self._last_skew_timing = -math.inf  # when the once-a-second timing message last went
        self._out_delay = 0.0
        self._seq = 0  # batch numbers; a timing message carries its batch's number
        self._skew_token = -1
        self._unconfirmed: deque[tuple[int, list[bytes]]] = deque()  # written, not yet confirmed, oldest first
        self._sock: socket.socket | None = None
        self._generation = 0  # connections so far: work posted for an older one is dropped
        self._teardown_done = True
        self._sync_awaiting = False
        self._sync_tx = 0.0
        self._inbox: list[MoosMessage] = []
        self._inbox_cond = threading.Condition()
        self._inbox_limit = DEFAULT_INBOX_LIMIT
        self._connected = threading.Event()
        # ---- reactor thread only ----
        self._state = STOPPED
        self._stopping = False
        self._reader = PacketReader()
        self._rbuf = bytearray(RECV_BYTES)
        self._rview = memoryview(self._rbuf)
        self._paused = False  # reading stopped because the inbox is full
        self._in_handler = False
        self._flush_after_handler = False
        self._handshake_timer: Timer | None = None
        self._reconnect_timer: Timer | None = None
        self._tick_timer: Timer | None = None
        self._watch_timer: Timer | None = None
        self._packets_read = 0
        self._last_summary: tuple[tuple[bytes, ...], int, dict[bytes, frozenset[bytes]]] | None = None
        # ---- configuration and statistics ----
        self._host = ""
        self._port = 0
        self._name = ""
        self._src = b""
        self._com = b""  # the DB's community, stamped on what we send so the DB can forward it as received
        self._community = ""
        self._db_hostname = ""
        self._next_id = 0
        self._comms_tick = 5.0
        self._quiet = False
        self._time_correction = True
        self._correct_time = True
        self._timewarp_scale = 0.2
        self._keys: dict[str, bytes] = {}
        self._registered: dict[str, float] = {}
        self._wildcards: dict[tuple[str, str], float] = {}
        self._reregistered: set[tuple[str, float]] = set()
        self._published: set[str] = set()
        self._asked_about = 0  # how many of _published the last PROC_SUMMARY request covered
        self._on_connect: Callback | None = None
        self._on_disconnect: Callback | None = None
        self._on_mail: Callback | None = None
        self._on_undelivered: UndeliveredCallback | None = None
        self._queues = ActiveQueueRouter()
        self._messages_read = 0
        self._messages_sent = 0
        self._bytes_sent = 0
        self._bytes_read = 0
        self._refused = 0  # posts refused because the link was down
        self._undelivered = 0  # accepted posts reported undelivered (in flight at a crash, or unconfirmed at close)
        self._fatal: MoosError | None = None
        # Who else subscribes to the variables we publish, and what waits for them after a reconnection.
        self._watch = SubscriberWatch()
        self.welcome: Welcome | None = None  # the DB's last WELCOME (community, skew, DB time, hostname)

    @property
    def clock(self) -> MoosClock:
        """The :class:`MoosClock` this client stamps messages with and writes its skew into."""
        return self._clock

    def _reregister(self) -> None:
        """Send the remembered registrations again (the API layer fills this in)."""

    def _on_io_thread(self) -> bool:
        reactor = self._reactor
        return reactor is not None and reactor.in_owner_thread()

    # ---- starting and stopping ---------------------------------------------------------------------------
    def _start(self) -> None:
        """Begin connecting: on our own new thread, or on the given reactor (without blocking)."""
        self._stopping = False
        self._teardown_done = False
        given = self._given_reactor
        if given is None:
            ready = threading.Event()
            self._thread = threading.Thread(target=self._thread_main, args=(ready,), name=f"moos-comms-{self._name}",
                                            daemon=True)
            self._thread.start()
            ready.wait()
        elif given.in_owner_thread():
            self._connect()
        else:
            given.post(self._connect)

    def _thread_main(self, ready: threading.Event) -> None:
        reactor = Reactor(f"moos-comms-{self._name}")  # built here: this thread owns it from the start
        self._reactor = reactor
        try:
            reactor.call_later(0.0, self._connect)
        finally:
            ready.set()
        try:
            reactor.run()
        except Exception:
            log.exception("%s: the comms thread failed", self._name)
            self._teardown(nice=False)
        finally:
            reactor.close()

    def _stop(self, nice: bool) -> None:
        """Optionally let queued messages go out and be confirmed (up to 2 s), then drop the link and the timers."""
        reactor = self._reactor
        if reactor is None or not self._running:
            return
        if self._on_io_thread():
            self._teardown(nice)
            return
        if nice:
            self._wait_for_confirmation(reactor)
        try:
            reactor.post(self._teardown, False)
        except ReactorClosedError:  # the user's reactor is gone: nothing else touches our socket any more
            self._teardown(False)
        with self._lock:
            if not self._cond.wait_for(lambda: self._teardown_done, 5.0):
                log.warning("%s: the reactor did not run close() within 5 s (is it still running?); closing the "
                            "socket from this thread", self._name)
        if not self._teardown_done:
            self._teardown(False)
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(10.0)
            self._thread = None
            self._reactor = None  # closed; its thread's id may be reused by another thread

    def _wait_for_confirmation(self, reactor: Reactor) -> None:
        """From an application thread: until what is queued is written and confirmed, the link fails, or 2 s."""
        with self._lock:
            if not self._live:
                return
            self._closing = True
        try:
            reactor.post(self._flush_for_close)
        except ReactorClosedError:
            return
        deadline = _time.monotonic() + CLOSE_GRACE_S
        with self._lock:
            self._space_waiters += 1
            try:
                while self._closing_waits():
                    remaining = deadline - _time.monotonic()
                    if remaining <= 0:
                        break
                    self._cond.wait(min(remaining, 0.1))
            finally:
                self._space_waiters -= 1

    def _closing_waits(self) -> bool:
        """Under the lock: still connected with something unwritten or unconfirmed."""
        return self._live and bool(self._outbox or self._unconfirmed or self._pending is not None)

    def _flush_for_close(self) -> None:
        """Reactor: write what is queued with a timing message in front, so the DB confirms the last of it."""
        if self._state == LIVE and self._async:
            self._write_batches(force=True, timing=True)
        elif self._state == LIVE:
            self._sync_exchange()

    def _teardown(self, nice: bool) -> None:
        """On the reactor thread (or once it is gone): drop the connection, the timers; report what is left."""
        if nice and self._state == LIVE:
            self._drain_here(_time.monotonic() + CLOSE_GRACE_S)
        self._stopping = True
        was_live = self._live
        self._cancel_timers(self._reconnect_timer, self._handshake_timer, self._tick_timer, self._watch_timer)
        self._reconnect_timer = self._handshake_timer = self._tick_timer = self._watch_timer = None
        sock = self._drop_socket()
        with self._lock:
            discarded, self._outbox, self._outbox_bytes = self._outbox, [], 0
            in_doubt = [batch for _, batch in self._unconfirmed]
            self._unconfirmed.clear()
            self._live = self._writable = self._closing = False
            self._connected.clear()
            self._state = STOPPED
            self._running = False
            self._cond.notify_all()
        if sock is not None:
            self._close_unless_writing(sock)
        if in_doubt:
            log.warning("%s: closed with %d message(s) written but not confirmed by the DB; reported undelivered",
                        self._name, sum(map(len, in_doubt)))
        if discarded:
            log.warning("%s: closed with %d message(s) still unsent; they are reported undelivered",
                        self._name, len(discarded))
        self._report_undelivered([*in_doubt, discarded])
        if was_live:
            self._run_callback(self._on_disconnect, "on-disconnect")
        self._queues.clear()
        with self._inbox_cond:
            self._inbox_cond.notify_all()
        with self._lock:
            self._teardown_done = True
            self._cond.notify_all()
        if self._given_reactor is None and self._reactor is not None:
            self._reactor.stop()

    def _drain_here(self, deadline: float) -> None:
        """close(nice) on the reactor thread itself: write out what is queued, then read until it is confirmed."""
        with self._lock:
            self._closing = True
        if self._async:
            self._write_batches(force=True, timing=True)
        else:
            self._sync_exchange()
        self._write_blocking(lambda: not self._outbox and self._pending is None, deadline)
        sock = self._sock
        poller = select.poll()
        if sock is None:
            return
        poller.register(sock, select.POLLIN)
        while self._unconfirmed and self._state == LIVE and self._sock is sock:
            remaining = deadline - _time.monotonic()
            if remaining <= 0 or not poller.poll(remaining * 1000):
                return
            self._on_readable(callbacks=False)

    @staticmethod
    def _cancel_timers(*timers: Timer | None) -> None:
        for timer in timers:
            if timer is not None:
                timer.cancel()

    # ---- connecting ----------------------------------------------------------------------------------------
    def _connect(self) -> None:
        """Reactor: start a non-blocking connection to the DB (retried every second while nobody listens)."""
        self._reconnect_timer = None
        if self._stopping or self._state not in (STOPPED, WAITING):
            return
        try:
            sock, done = start_connect(resolve(self._host, self._port))
        except OSError as exc:
            log.debug("%s: cannot reach the DB at %s:%d (%s); retrying", self._name, self._host, self._port, exc)
            self._retry_later()
            return
        with self._lock:
            self._sock = sock
            self._generation += 1
        self._state = CONNECTING
        self._reader = PacketReader()
        self._handshake_timer = self._reactor_call_later(HANDSHAKE_TIMEOUT_S, self._handshake_timeout)
        if done:
            self._on_connect_done()
        else:
            self._reactor_().add_writer(sock, self._on_connect_done)

    def _on_connect_done(self) -> None:
        sock = self._sock
        if sock is None or self._state != CONNECTING:
            return
        reactor = self._reactor_()
        reactor.remove_writer(sock)
        err = connect_error(sock)
        if err:
            log.debug("%s: cannot reach the DB at %s:%d (%s); retrying", self._name, self._host, self._port,
                      os.strerror(err))
            self._abandon(None)
            return
        self._state = HANDSHAKE
        reactor.add_reader(sock, self._on_readable)
        self._send_raw(hello_bytes(self._name, self._async, self._clock))

    def _handshake_timeout(self) -> None:
        self._handshake_timer = None
        if self._state in (CONNECTING, HANDSHAKE):
            self._abandon(f"no answer from the DB at {self._host}:{self._port} within {HANDSHAKE_TIMEOUT_S:g} s")

    def _abandon(self, reason: str | None, fatal: bool = False) -> None:
        """A connection that never got live: close it and try again later (unless fatal)."""
        if reason is not None:
            (log.error if fatal else log.warning)("%s: handshake with %s:%d failed (%s)%s", self._name, self._host,
                                                   self._port, reason, "; giving up, as libMOOS does" if fatal
                                                   else "; retrying")
        self._cancel_timers(self._handshake_timer)
        self._handshake_timer = None
        sock = self._drop_socket()
        if sock is not None:
            self._close_unless_writing(sock)
        if fatal:
            self._state = STOPPED
        else:
            self._retry_later()

    def _retry_later(self) -> None:
        self._state = WAITING
        if not self._stopping:
            self._reconnect_timer = self._reactor_call_later(RECONNECT_PERIOD_S, self._connect)

    def _on_welcome(self, welcome: Welcome) -> None:
        """Apply the WELCOME, re-register, call on-connect, then let queued mail go."""
        self._cancel_timers(self._handshake_timer)
        self._handshake_timer = None
        self.welcome = welcome
        self._community = welcome.community
        self._com = to_bytes(welcome.community)
        self._db_hostname = welcome.db_hostname
        same_host = welcome.db_hostname == socket.gethostname()
        self._correct_time = self._time_correction and (self._quiet or not same_host)
        if self._correct_time:
            self._clock.skew = welcome.skew
        self._packets_read = 1
        self._state = LIVE
        with self._lock:
            self._last_timing = self._last_skew_timing = -math.inf
            self._out_delay = 0.0
            self._live = True
            self._connected.set()
            self._cond.notify_all()
        log.info("%s: connected to %s:%d (community %r)", self._name, self._host, self._port, self._community)
        self._reregister()
        self._run_callback(self._on_connect, "on-connect")
        if self._state != LIVE:  # on-connect closed the client, or the link failed meanwhile
            return
        with self._lock:  # what was queued while down, or by on-connect, goes now: after the re-registrations
            self._outbox = self._watch.reconnected(_time.monotonic(), self._outbox)
            self._outbox_bytes = sum(map(len, self._outbox))
            self._writable = True
        self._reregistered = set()  # only on-connect's repeats of the automatic registrations are skipped
        reactor = self._reactor_()
        if self._async:
            self._tick_timer = reactor.call_later(TIMING_PERIOD_S, self._tick)
        else:
            self._tick_timer = reactor.call_every(self._sync_period, self._sync_exchange, align=False)
        if self._watch.missing:
            self._watch_timer = reactor.call_every(RESUBSCRIBE_POLL_S, self._poll_subscribers, align=False)
        self._flush()

    # ---- losing the connection -----------------------------------------------------------------------------
    def _drop_socket(self) -> socket.socket | None:
        """Unregister and forget the socket (reactor thread); the caller closes it."""
        sock = self._sock
        if sock is None:
            return None
        reactor = self._reactor
        if reactor is not None and not reactor.closed:
            reactor.remove_reader(sock)
            reactor.remove_writer(sock)
        with self._lock:
            self._sock = None
            self._generation += 1
            self._pending = None
            self._flush_scheduled = False
            self._sync_awaiting = False
        self._paused = False
        return sock

    def _close_unless_writing(self, sock: socket.socket) -> None:
        """Close now, or, while an application thread is inside send() on it, as soon as that returns (so the
        descriptor number is not reused under it)."""
        with self._lock:
            if self._writing:
                self._close_after_write = sock
                try:
                    sock.shutdown(socket.SHUT_RDWR)
                except OSError:
                    pass
                return
        close_socket(sock)

    def _lost(self, reason: str, level: int = logging.WARNING) -> None:
        """Reactor: the live connection failed. Report what is in doubt, call on-disconnect, reconnect later."""
        if self._state == LIVE and not self._stopping:
            log.log(level, "%s: lost the DB at %s:%d: %s", self._name, self._host, self._port, reason)
        elif self._state in (CONNECTING, HANDSHAKE):
            self._abandon(reason)
            return
        self._cancel_timers(self._tick_timer, self._watch_timer)
        self._tick_timer = self._watch_timer = None
        sock = self._drop_socket()
        with self._lock:
            was_live = self._live
            self._live = self._writable = False
            self._connected.clear()
            in_doubt = [batch for _, batch in self._unconfirmed]
            self._unconfirmed.clear()
            self._watch.lost()  # what we publish to others waits, after reconnecting, for them to be back
            self._cond.notify_all()
        if sock is not None:
            self._close_unless_writing(sock)
        if in_doubt:
            log.warning("%s: %d message(s) written but not confirmed by the DB when the connection was lost; "
                        "reported undelivered", self._name, sum(map(len, in_doubt)))
            self._report_undelivered(in_doubt)
        if self._outbox and not self._stopping:
            log.info("%s: %d queued message(s) will be sent after reconnecting", self._name, len(self._outbox))
        if was_live:
            self._run_callback(self._on_disconnect, "on-disconnect")
        self._retry_later()

    def _lost_in_thread(self, generation: int, reason: str) -> None:
        """A write from an application thread failed: the reactor handles the loss."""
        if generation == self._generation and self._state == LIVE:
            self._lost(reason)

    # ---- outgoing path -------------------------------------------------------------------------------------
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
        sval: bytes, msg_id: int | None = None, src: bytes | None = None,
    ) -> bool:
        """Encode a message at once and get it written: directly if the link is idle, else by the reactor.
        ``src``: the source to send (default: our name)."""
        on_io = self._on_io_thread()
        if on_io and len(self._outbox) >= self._outbox_limit and self._writable:
            # the reactor cannot wait for itself: write out until there is room (the link's own back-pressure)
            self._write_blocking(lambda: len(self._outbox) < self._outbox_limit, None)
        with self._lock:
            missing = self._watch.missing
            if not self._live or (missing and msg_type == NOTIFY and key in missing):
                self._refused += 1
                return False
            if msg_id is None:
                msg_id = self._next_id
                self._next_id += 1
            if not on_io and len(self._outbox) >= self._outbox_limit:
                self._wait_for_space()
            wire = encode_fields(msg_type, data_type, msg_id, self._src if src is None else src, aux, self._com, key,
                                 msg_time, dval, -1.0, sval)
            self._outbox.append(wire)
            self._outbox_bytes += len(wire)
            if not self._writable or self._flush_scheduled or self._writing or self._pending is not None:
                return True  # whoever holds the link takes it with the rest
            direct = (not on_io and self._async and self._out_delay <= 0.0
                      and _time.monotonic() - self._last_write > BURST_WINDOW_S)
            if not direct:
                self._flush_scheduled = True
        if direct:
            self._write_batches()
        elif not on_io:
            self._post_to_reactor(self._flush)
        elif self._in_handler:
            self._flush_after_handler = True
        else:
            self._reactor_().call_later(0.0, self._flush)
        return True

    def _wait_for_space(self) -> None:
        """Back-pressure: block (lock held by the caller) until the outbox drains below its limit."""
        self._space_waiters += 1
        try:
            while len(self._outbox) >= self._outbox_limit and self._live and self._running:
                self._cond.wait(0.1)
        finally:
            self._space_waiters -= 1

    def _post_to_reactor(self, fn: Callable[..., object], *args: object) -> None:
        reactor = self._reactor
        if reactor is None:
            return
        try:
            reactor.post(fn, *args)
        except ReactorClosedError:
            log.debug("%s: the reactor is closed; %r not run", self._name, fn)

    def _flush(self) -> None:
        """Reactor: write what is queued (a sync client starts an exchange)."""
        with self._lock:
            self._flush_scheduled = False
        if self._state != LIVE:
            return
        if self._async:
            self._write_batches()
        else:
            self._sync_exchange()

    def _take_batch(self, now: float, force: bool, timing: bool) -> tuple[bytes, int] | None:
        """Under the lock: the next packet (queued messages, timing message in front when due), or None."""
        outbox = self._outbox
        if outbox:
            if self._outbox_bytes <= MAX_BATCH_BYTES:
                batch, self._outbox, self._outbox_bytes = outbox, [], 0
            else:
                size = count = 0
                while count < len(outbox) and (count == 0 or size + len(outbox[count]) <= MAX_BATCH_BYTES):
                    size += len(outbox[count])
                    count += 1
                batch = outbox[:count]
                del outbox[:count]
                self._outbox_bytes -= size
            if self._space_waiters:
                self._cond.notify_all()
        else:
            batch = []
        self._seq += 1
        parts = batch
        if self._async:
            skew_due = now - self._last_skew_timing >= TIMING_PERIOD_S
            if skew_due or timing or (batch and (self._closing or now - self._last_timing >= CONFIRM_INTERVAL_S)):
                self._last_timing = now
                if skew_due:
                    self._last_skew_timing = now
                    self._skew_token = self._seq
                stamp = MoosMessage(TIMING, DOUBLE, msg_id=self._seq, key=TIMING_KEY,
                                    msg_time=self._clock.local_time(), dval=0.0)
                parts = [encode_message(stamp), *batch]
        summary = self._summary_request(now, self._skew_token == self._seq)
        if summary is not None:
            parts = [*parts, summary]
        if not parts:
            if not force or self._async:
                return None
            parts = [encode_message(MoosMessage(NULL_MSG, DOUBLE, src=self._src))]
        if batch:
            self._unconfirmed.append((self._seq, batch))
        return frame_packet(parts), len(parts)

    def _write_batches(self, force: bool = False, timing: bool = False) -> None:
        """Write packets until the outbox is empty or the kernel takes no more (then the reactor finishes)."""
        while True:
            with self._lock:
                sock = self._sock
                if (self._writing or self._pending is not None or sock is None or not self._writable
                        or not self._async):
                    return
                now = _time.monotonic()
                if self._out_delay > 0.0 and now < self._last_write + self._out_delay:
                    if not self._flush_scheduled:  # the DB asked us to write no more often than that
                        self._flush_scheduled = True
                        self._post_to_reactor(self._delayed_flush, self._last_write + self._out_delay)
                    return
                taken = self._take_batch(now, force, timing)
                if taken is None:
                    return
                force = timing = False
                self._writing = True
                generation = self._generation
            if not self._send(sock, generation, *taken):
                return

    def _delayed_flush(self, when: float) -> None:
        self._reactor_().call_at(when, self._flush)

    def _send(self, sock: socket.socket, generation: int, data: bytes, count: int) -> bool:
        """Write one packet (the caller claimed ``_writing``); True when all of it went."""
        sent, failure = _try_send(sock, data)
        on_io = self._on_io_thread()
        with self._lock:
            self._writing = False
            self._last_write = _time.monotonic()
            self._bytes_sent += sent
            late = self._close_after_write
            if late is not None:
                self._close_after_write = None
            current = generation == self._generation
            if current and not failure:
                self._messages_sent += count
                if sent < len(data):
                    self._pending = memoryview(data)[sent:]
        if late is not None:
            close_socket(late)
        if not current:
            return False
        if failure:
            if on_io:
                self._lost(failure)
            else:
                self._post_to_reactor(self._lost_in_thread, generation, failure)
            return False
        if sent < len(data):
            if on_io:
                self._reactor_().add_writer(sock, self._on_writable)
            else:
                self._post_to_reactor(self._arm_writer, generation)
            return False
        return True

    def _arm_writer(self, generation: int) -> None:
        if generation == self._generation and self._pending is not None and self._sock is not None:
            self._reactor_().add_writer(self._sock, self._on_writable)

    def _on_writable(self) -> None:
        """Reactor: the kernel takes bytes again: finish the packet in progress, then what queued meanwhile."""
        sock = self._sock
        with self._lock:
            pending = self._pending
            if sock is None or pending is None or self._writing:
                if sock is not None and pending is None:
                    self._reactor_().remove_writer(sock)
                return
            self._writing = True
            generation = self._generation
        sent, failure = _try_send(sock, pending)
        with self._lock:
            self._writing = False
            self._bytes_sent += sent
            self._last_write = _time.monotonic()
            if generation != self._generation:
                return
            self._pending = pending[sent:] if sent < len(pending) else None
            done = self._pending is None
        if failure:
            self._lost(failure)
            return
        if done:
            self._reactor_().remove_writer(sock)
            if self._state == HANDSHAKE:
                return
            if self._async:
                self._write_batches()
            else:
                self._sync_exchange()

    def _send_raw(self, data: bytes) -> None:
        """Reactor: bytes that must go before anything else (the handshake); the tail goes via the writer."""
        sock = self._sock
        assert sock is not None
        with self._lock:
            self._writing = True
            generation = self._generation
        self._send(sock, generation, data, 0)

    def _write_blocking(self, done: Callable[[], bool], deadline: float | None) -> None:
        """Reactor thread: write synchronously, waiting for the socket to take bytes, until ``done()`` or the
        link fails (or ``deadline`` passes). How a sender on the reactor's own thread feels back-pressure."""
        poller = select.poll()
        watched: socket.socket | None = None
        while not done():
            sock = self._sock
            if sock is None or self._state != LIVE or not self._writable:
                return
            if self._pending is None:
                if not self._async:
                    self._sync_exchange()
                    return  # a sync client waits for its reply (read by this thread): the outbox may grow
                before = len(self._outbox)
                self._write_batches()
                if not self._has_pending() and self._outbox and len(self._outbox) >= before:
                    _time.sleep(0.001)  # another thread holds the socket, or the DB asked for a delay
                    if deadline is not None and _time.monotonic() >= deadline:
                        return
                continue
            if watched is not sock:
                if watched is not None:
                    poller.unregister(watched)
                poller.register(sock, select.POLLOUT)
                watched = sock
            wait_ms = None if deadline is None else max(0.0, (deadline - _time.monotonic()) * 1000)
            if wait_ms == 0.0:
                return
            if poller.poll(wait_ms):
                self._on_writable()

    def _has_pending(self) -> bool:
        return self._pending is not None

    def _tick(self) -> None:
        """Reactor, async: the timing message once a second (keeps the link alive, measures the skew)."""
        self._tick_timer = None
        if self._state != LIVE:
            return
        if _time.monotonic() - self._last_skew_timing >= TIMING_PERIOD_S * 0.99 and self._pending is None:
            self._write_batches(force=True, timing=True)
        next_at = max(self._last_skew_timing + TIMING_PERIOD_S, _time.monotonic() + 0.05)
        self._tick_timer = self._reactor_().call_at(next_at, self._tick)

    def _sync_period(self) -> float:
        return 1.0 / (self._comms_tick * self._clock.warp)

    def _sync_exchange(self) -> None:
        """Reactor, sync: one packet out (a NULL when idle) unless a reply is awaited; exactly one reply back."""
        with self._lock:
            sock = self._sock
            if (self._state != LIVE or sock is None or not self._writable or self._sync_awaiting or self._writing
                    or self._pending is not None):
                return
            taken = self._take_batch(_time.monotonic(), True, False)
            assert taken is not None
            self._sync_awaiting = True
            self._writing = True
            generation = self._generation
        self._sync_tx = self._clock.local_time()
        self._send(sock, generation, *taken)

    def _poll_subscribers(self) -> None:
        """Reactor, after a reconnection: ask the DB often whether our subscribers are back (until they are)."""
        if not self._watch.missing:
            if self._watch_timer is not None:
                self._watch_timer.cancel()
                self._watch_timer = None
            return
        if self._async:
            self._write_batches(force=True)
        else:
            self._sync_exchange()

    # ---- incoming path -------------------------------------------------------------------------------------
    def _on_readable(self, callbacks: bool = True) -> None:
        """Reactor: read what arrived; the handshake's reply, then packets of mail."""
        sock = self._sock
        if sock is None:
            return
        try:
            n = sock.recv_into(self._rbuf)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as exc:
            self._lost(f"connection lost: {exc}")
            return
        if n == 0:
            self._lost("the peer closed the connection")
            return
        self._bytes_read += n
        try:
            packets = self._reader.feed(self._rview[:n])
        except ProtocolError as exc:
            if self._state == HANDSHAKE:
                self._abandon(f"the DB's handshake reply is malformed: {exc}")
            else:
                self._lost(f"malformed data from the DB: {exc}", logging.ERROR)
            return
        if not packets:
            return
        self._in_handler = True
        try:
            if self._state == HANDSHAKE:
                first = packets.pop(0)
                try:
                    welcome = parse_welcome(first, self._name)
                except PoisonedError as exc:
                    self._fatal = exc
                    self._abandon(str(exc), fatal=True)
                    return
                except HandshakeError as exc:
                    self._abandon(str(exc))
                    return
                self._on_welcome(welcome)
            if packets and self._state == LIVE:
                self._handle_packets(packets, callbacks)
        finally:
            self._in_handler = False
            if self._flush_after_handler:
                self._flush_after_handler = False
                self._flush()

    def _handle_packets(self, packets: list[list[MoosMessage]], callbacks: bool) -> None:
        mail: list[MoosMessage] = []
        replied = False
        for packet in packets:
            self._packets_read += 1
            if not packet:
                continue
            first = packet[0]
            if first.msg_type == TIMING:
                self._confirm(first.msg_id)
                if self._packets_read > 1 and self._correct_time and first.msg_id == self._skew_token:
                    self._clock.update_skew(first.msg_time, first.dval, self._clock.local_time())
                self._out_delay = max(0.0, first.dval2)
                start = 1
            elif first.msg_type == NULL_MSG:
                now = self._clock.local_time()
                if not self._async and self._sync_awaiting:
                    replied = True
                    with self._lock:
                        self._sync_awaiting = False
                    self._confirm(None)  # one reply per packet: the DB has processed what we wrote
                    if self._correct_time:
                        self._clock.update_skew(self._sync_tx, first.dval, now)
                elif self._correct_time:
                    self._clock.update_skew(now, first.dval, now)
                start = 1
            else:
                start = 0
            for msg in packet[start:] if start else packet:
                if msg.msg_type != NULL_MSG:
                    mail.append(msg)
        if mail:
            self._deliver(mail, callbacks)
        if replied and self._outbox and self._state == LIVE:
            self._sync_exchange()

    def _deliver(self, mail: list[MoosMessage], callbacks: bool = True) -> None:
        """Route to active queues, append the rest to the inbox in order, then run the on-mail callback."""
        if self._watch.pending:
            summary = [m for m in mail if is_summary_reply(m)]
            if summary:
                self._on_summary(summary)
                mail = [m for m in mail if not is_summary_reply(m)]
                if not mail:
                    return
        self._messages_read += len(mail)
        if self._queues and callbacks:
            dispatch = self._queues.dispatch
            mail = [m for m in mail if not (m.msg_type == NOTIFY and dispatch(m))]
            if not mail:
                return
        with self._inbox_cond:
            self._inbox.extend(mail)
            self._inbox_cond.notify_all()
            full = len(self._inbox) >= self._inbox_limit
        if full and not self._paused and self._sock is not None:
            log.warning("%s: %d unfetched messages; pausing reads until fetch() catches up",
                        self._name, len(self._inbox))
            self._paused = True
            self._reactor_().remove_reader(self._sock)
        if callbacks and self._on_mail is not None:
            self._run_callback(self._on_mail, "on-mail")

    def _resume_reading(self) -> None:
        """Reactor: fetch() made room in the inbox: read again."""
        if self._paused and len(self._inbox) < self._inbox_limit:
            self._paused = False
            if self._sock is not None:
                self._reactor_().add_reader(self._sock, self._on_readable)

    def _fetch_all(self) -> list[MoosMessage]:
        with self._inbox_cond:
            if not self._inbox:
                return []
            mail, self._inbox = self._inbox, []
            self._inbox_cond.notify_all()
        if self._paused:
            if self._on_io_thread():
                self._resume_reading()
            else:
                self._post_to_reactor(self._resume_reading)
        return mail

    # ---- subscribers of what we publish (subscriber_watch.py decides) --------------------------------
    def _summary_request(self, now: float, timed: bool) -> bytes | None:
        """Under the lock: a ``PROC_SUMMARY`` request when one is due (we publish something), else None; gives up
        waiting for subscribers that have not come back within ``RESUBSCRIBE_WAIT_S``. An async client asks in the
        packet of its once-a-second timing message (``timed``), in the first packet that publishes a variable it has
        not asked about (so that a drop within the first second of publishing still finds its subscribers known), or
        while it waits for subscribers."""
        first_publication = len(self._published) != self._asked_about
        if not self._published or (self._async and not timed and not first_publication and not self._watch.missing):
            return None
        poll = self._watch.poll(now, True, first_publication)
        if poll.ask:
            self._asked_about = len(self._published)
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
            self._outbox_bytes += sum(map(len, held))
            self._cond.notify_all()
            if not self._flush_scheduled:
                self._flush_scheduled = True
                self._post_to_reactor(self._flush)

    def _on_summary(self, replies: list[MoosMessage]) -> None:
        """The DB's answer to our ``PROC_SUMMARY``; releases the variables whose subscribers are all back. Runs on
        the reactor thread. An answer like the last one is not parsed again."""
        raw = tuple(reply.raw_sval for reply in replies)
        published = list(self._published)
        cached = self._last_summary
        if cached is not None and cached[0] == raw and cached[1] == len(published):
            subscribers = cached[2]
        else:
            subscribers = parse_proc_summary(raw, self._src, [to_bytes(name) for name in published])
            self._last_summary = (raw, len(published), subscribers)
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
            if self._closing:
                self._cond.notify_all()

    def _report_undelivered(self, batches: Iterable[list[bytes]]) -> None:
        """Count and hand over messages that were accepted but may not have reached the DB."""
        wire = [m for batch in batches for m in batch]
        if not wire:
            return
        messages = PacketReader(2**31 - 1).feed(frame_packet(wire))[0]
        self._undelivered += len(messages)
        func = self._on_undelivered
        if func is not None:
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

    # ---- reactor helpers -----------------------------------------------------------------------------------
    def _reactor_(self) -> Reactor:
        reactor = self._reactor
        assert reactor is not None, "the client is not running"
        return reactor

    def _reactor_call_later(self, delay: float, fn: Callable[[], object]) -> Timer:
        return self._reactor_().call_later(delay, fn)
