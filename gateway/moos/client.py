"""``comms``: a pure-Python MOOS v10 client with pymoos's API (asynchronous by default, synchronous on request).

This module is the API; the reactor work (connection, outgoing queue, incoming path) lives in ``engine.py``.
Callbacks (on-connect, on-disconnect, on-mail, active queues, on-undelivered) run on the client's I/O thread: the
thread of its reactor, its own ``moos-comms-<name>`` thread, or with ``comms(reactor=r)`` the thread that runs ``r``.
"""

from __future__ import annotations

import logging
import time as _time

from util.reactor import Reactor

from .active_queue import MessageCallback
from .clock import DEFAULT_CLOCK, MoosClock
from .engine import Callback, ClientEngine, UndeliveredCallback
from .errors import MoosError
from .message import (
    BINARY,
    DOUBLE,
    NOTIFY,
    REGISTER,
    SERVER_REQUEST,
    SERVER_REQUEST_ID,
    STRING,
    UNREGISTER,
    WILDCARD_REGISTER,
    WILDCARD_UNREGISTER,
    MoosMessage,
    to_bytes,
)

log = logging.getLogger(__name__)


def wildcard_sval(var_pattern: str, app_pattern: str, interval: float) -> bytes:
    """The ``*``/``/`` payload exactly as C++ builds it (``MOOSAddValToString``; ``%g``-style interval)."""
    return to_bytes(f"AppPattern={app_pattern},VarPattern={var_pattern},Interval={float(interval):g}")


class comms(ClientEngine):  # noqa: N801 - pymoos's class name
    """A MOOS client. Method names, signatures and semantics follow pymoos's ``comms``.

    ``comms()`` is asynchronous like pymoos; ``comms(asynchronous=False)`` speaks the synchronous protocol;
    ``clock=`` gives it its own :class:`MoosClock` (warp, and the skew learned from the DB); without it the client
    shares the process-wide ``DEFAULT_CLOCK`` with ``gateway.moos.time()``, as libMOOS clients do.

    ``reactor=r`` (our extension; pymoos has no such argument): the client lives on a :class:`util.reactor.Reactor`
    its user already runs and has no thread of its own. Its socket and timers are registered on ``r``; every
    callback runs on ``r``'s thread; ``run()`` starts connecting and returns at once; ``r``'s thread never blocks
    waiting for the DB (``wait_until_connected`` and ``server_request`` raise MoosError there instead of waiting,
    see their docstrings). Without it the client runs its own reactor on a ``moos-comms-<name>`` thread.
    """

    def __init__(self, asynchronous: bool = True, clock: MoosClock | None = None, *,
                 reactor: Reactor | None = None) -> None:
        super().__init__(asynchronous, clock if clock is not None else DEFAULT_CLOCK, reactor)

    # ---- lifecycle ---------------------------------------------------------------------------------
    def run(self, server: str, port: int, name: str, comms_tick: float = 5) -> bool:
        """Start connecting to the DB at ``server:port`` as ``name``; returns at once (False if running).

        May be called on any thread; with ``comms(reactor=r)`` the connection is made by ``r``'s thread."""
        with self._lock:
            if self._running:
                return False
            self._running = True
        self._host, self._port, self._name = server, int(port), name
        self._src = to_bytes(name)
        if comms_tick:
            self.set_comms_tick(comms_tick)
        self._start()
        return True

    def close(self, nice: bool = True) -> bool:
        """Stop the client: with ``nice`` first wait (up to 2 s) until what is queued is written and confirmed by the
        DB; anything not confirmed is reported undelivered (docs/moos.md "Restarts"). Idempotent; from any thread
        (on the client's own reactor thread the wait is done there, reading only the DB's confirmations)."""
        self._stop(nice)
        self._registered.clear()
        self._wildcards.clear()
        return True

    def __enter__(self) -> comms:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close(True)

    # ---- callbacks ---------------------------------------------------------------------------------
    def set_on_connect_callback(self, func: Callback) -> bool:
        """``func()`` runs on the client's I/O (reactor) thread after every (re)connection; register there."""
        self._on_connect = func
        return True

    def set_on_disconnect_callback(self, func: Callback) -> bool:
        """``func()`` runs on the client's I/O (reactor) thread when the connection is lost (and at ``close``)."""
        self._on_disconnect = func
        return True

    def set_on_mail_callback(self, func: Callback) -> bool:
        """``func()`` runs on the client's I/O (reactor) thread after mail arrives (once per read, however many
        packets it held); it should only wake its owner, which then calls :meth:`fetch` on its own thread (or call
        ``fetch`` right there, as pymoos scripts do: posts made in the callback leave as one packet when it
        returns)."""
        self._on_mail = func
        return True

    def set_on_undelivered_callback(self, func: UndeliveredCallback) -> bool:
        """Extension (pymoos has none): ``func(messages)`` gets the messages ``notify`` accepted that may not
        have reached the DB: written but unconfirmed when the connection was lost, or discarded by ``close``.
        Runs on the client's I/O (reactor) thread (or the thread calling ``close`` once the reactor is gone).
        See docs/moos.md "Restarts"."""
        self._on_undelivered = func
        return True

    def has_mail_callback(self) -> bool:
        return self._on_mail is not None

    # ---- active queues -----------------------------------------------------------------------------
    def add_active_queue(self, queue_name: str, func: MessageCallback) -> bool:
        """Create a queue whose ``func(msg)`` runs once per routed message, in order, on the client's I/O (reactor)
        thread as the packet is delivered (libMOOS gives each queue a thread; post to one if you need it)."""
        return self._queues.add_queue(queue_name, func)

    def add_message_route_to_active_queue(self, queue_name: str, msg_name: str) -> bool:
        """Send notifications of ``msg_name`` to the queue instead of the inbox (False if no such queue)."""
        return self._queues.add_route(queue_name, to_bytes(msg_name))

    def add_wildcard_active_queue(self, queue_name: str, pattern: str, func: MessageCallback) -> bool:
        """Route every notification whose name matches the MOOS wildcard ``pattern`` to queue ``queue_name``
        (created if needed); ``func(msg)`` runs on the client's I/O (reactor) thread."""
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
        aux = b""
        if args:
            if len(args) == 1:
                if isinstance(args[0], str):
                    aux = to_bytes(args[0])
                else:
                    time = float(args[0])  # type: ignore[arg-type]
            elif len(args) == 2:
                aux, time = to_bytes(str(args[0])), float(args[1])  # type: ignore[arg-type]
            else:
                raise TypeError("notify(name, value[, aux_src][, time])")
        if time == -1.0:
            time = self._clock.time()
        self._published.add(name)
        key = self._keys.get(name) or self._key(name)
        kind = type(value)
        if kind is float or kind is int:
            return self._post_fields(NOTIFY, DOUBLE, key, aux, time, float(value), b"")
        if isinstance(value, str | bytes | bytearray):
            raw = to_bytes(value) if isinstance(value, str) else bytes(value)
            cut = raw.find(b"\0")
            if cut >= 0:
                log.warning("notify %s: string value truncated at its first NUL byte, as MOOS does; "
                            "use notify_binary for arbitrary bytes", name)
                raw = raw[:cut]
            return self._post_fields(NOTIFY, STRING, key, aux, time, -1.0, raw)
        return self._post_fields(NOTIFY, DOUBLE, key, aux, time, float(value), b"")  # bool, numpy, Decimal...

    def post(self, msg: MoosMessage, keep_source: bool = False) -> bool:
        """Publish a whole message (name, value, time, aux source); with ``keep_source`` under its own source, not
        ours. Our extension, libMOOS's ``Post(msg, bKeepMsgSourceName)``: what pShare does with what it receives."""
        self._published.add(msg.key())
        return self._post_fields(msg.msg_type, msg.data_type, msg.raw_key, msg.raw_aux, msg.msg_time, msg.dval,
                                 msg.raw_sval, src=msg.raw_src if keep_source else None)

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
            if not name or not args[0]:
                log.warning("wildcard register needs a variable pattern and an app pattern")
                return False
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
        if self._on_io_thread():
            raise MoosError("server_request() waits for the client's reactor thread, so it cannot run on it (in a "
                            "comms callback, or on the reactor given with comms(reactor=...))")
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
        return self._fetch_all()

    # ---- state -------------------------------------------------------------------------------------
    def is_connected(self) -> bool:
        return self._live

    def wait_until_connected(self, n_ms: float) -> bool:
        """Block until connected or ``n_ms`` milliseconds pass.

        On the client's own reactor thread (a callback, or the reactor given with ``comms(reactor=r)``), which is
        the thread that would connect it, it never blocks: True when connected, False when ``n_ms <= 0``, else
        MoosError (use the on-connect callback there instead)."""
        if self._on_io_thread():
            if self._live or n_ms <= 0:
                return self._live
            raise MoosError("wait_until_connected() on the client's own reactor thread would block the thread that "
                            "connects it; use set_on_connect_callback() (or is_connected()) there")
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
        return self._bytes_sent

    def get_number_bytes_read(self) -> int:
        return self._bytes_read

    def get_number_of_refused_messages(self) -> int:
        """Extension: posts that returned False because the client was not connected (pymoos drops them)."""
        return self._refused

    def get_number_of_undelivered_messages(self) -> int:
        """Extension: accepted posts reported through the on-undelivered callback."""
        return self._undelivered

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
        """Unfetched messages before the client stops reading (back-pressure instead of a silent purge)."""
        self._inbox_limit = max(1, int(limit))

    def _reregister(self) -> None:
        self._reregistered = set()
        for name, interval in list(self._registered.items()):
            self._post(MoosMessage(REGISTER, DOUBLE, key=to_bytes(name), msg_time=self._clock.time(), dval=interval))
            self._reregistered.add((name, interval))
        for (var_pattern, app_pattern), interval in list(self._wildcards.items()):
            self._wildcard(WILDCARD_REGISTER, var_pattern, app_pattern, interval)
