"""``MOOSInterface``: the MOOS side of one Translator -- its client, triggers, buffers and time variable.

Why a separate object: it mirrors Goby's ``TranslatorBase::MOOSInterface`` (``moos().add_trigger(...)``) and
keeps the MOOS bookkeeping apart from the Goby thread.  Threading contract: every method here is called on the
owning translator's thread, and every trigger runs there.  With our client on the translator's reactor
(``comms(reactor=...)``, the default) the client's on-connect and on-mail callbacks already run on that thread:
mail is dispatched inside the on-mail callback as it arrives.  With a client that has an I/O thread of its own (the
real pymoos), that thread only *wakes* the owner through ``call_soon`` (:class:`ThreadHandOver`); it never touches
the triggers, buffers or translator state.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

from gateway.moos.wildcard import wild_match
from translators.techniques import Technique, TechniqueError, is_binary, parse, serialize

log = logging.getLogger(__name__)

TIME_VAR = "GOBY_MOOS_TRANSLATOR_TIME"
TIME_PUBLISH_PERIOD_S = 1.0

MoosCallback = Callable[[Any], None]


def time_string(moos_time: float, goby_time: float) -> str:
    """The ``GOBY_MOOS_TRANSLATOR_TIME`` value: ``moostime=<%.15g>,gobytime=<%.15g>`` and a newline, as Goby."""
    return f"moostime={moos_time:.15g},gobytime={goby_time:.15g}\n"


class ThreadHandOver:
    """For a client whose callbacks run on its own I/O thread (the real pymoos): they only schedule the owner's
    work with ``call_soon``, one pending mail wake-up per burst (the owner then fetches the whole burst at once)."""

    def __init__(self, call_soon: Callable[[Callable[[], Any]], None], on_connect: Callable[[], Any],
                 on_mail: Callable[[], Any]) -> None:
        self._call_soon = call_soon
        self._on_connect = on_connect
        self._on_mail = on_mail
        self._lock = threading.Lock()
        self._mail_pending = False
        self.closed = False

    def connected(self) -> bool:
        """The client's on-connect callback (its I/O thread): schedules ``on_connect`` on the owner."""
        if not self.closed:
            self._schedule(self._on_connect)
        return True

    def mail(self) -> bool:
        """The client's on-mail callback (its I/O thread): wakes the owner once per burst, never dispatches."""
        with self._lock:
            if self._mail_pending or self.closed:
                return True
            self._mail_pending = True
        self._schedule(self._mail_on_owner)
        return True

    def _mail_on_owner(self) -> None:
        with self._lock:
            self._mail_pending = False  # cleared *before* fetching, so later mail schedules another call
        self._on_mail()

    def _schedule(self, fn: Callable[[], Any]) -> None:
        try:
            self._call_soon(fn)
        except Exception:  # the owner is shutting down
            log.debug("could not schedule %s on the translator thread", getattr(fn, "__qualname__", fn))


class MOOSInterface:
    """Triggers, buffers and the client of one translator (Goby's ``MOOSInterface``).

    ``call_soon``: None when the client's callbacks run on the owner's thread (our client on the owner's reactor);
    else the owner thread's thread-safe scheduler, through which a client with an I/O thread of its own hands over
    (:class:`ThreadHandOver`).  ``moos_time``/``goby_time`` return MOOS time and (warped) Goby time in seconds.
    Nothing is unregistered: as in Goby there is no unsubscribe.
    """

    def __init__(
        self,
        comms: Any,
        call_soon: Callable[[Callable[[], Any]], None] | None,
        moos_time: Callable[[], float],
        goby_time: Callable[[], float],
        technique: int = Technique.PREFIXED_PROTOBUF_TEXT_FORMAT,
    ) -> None:
        self._comms = comms
        self._moos_time = moos_time
        self._goby_time = goby_time
        self.technique = Technique(technique)
        self._triggers: dict[str, MoosCallback] = {}
        self._wildcards: dict[tuple[str, str], MoosCallback] = {}
        self._buffer_vars: set[str] = set()
        self._buffer: dict[str, Any] = {}
        self._next_time_publish = goby_time()
        self._closed = False
        self._started = False
        self.mail_batches = 0  # how many fetch batches were handled (for tests and benchmarks)
        self._hand_over: ThreadHandOver | None = None
        if call_soon is None:  # the callbacks run on this thread: register and dispatch right there
            comms.set_on_connect_callback(self._on_connect)
            comms.set_on_mail_callback(self._on_mail)
        else:
            self._hand_over = ThreadHandOver(call_soon, self._on_connect, self.handle_mail)
            comms.set_on_connect_callback(self._hand_over.connected)
            comms.set_on_mail_callback(self._hand_over.mail)

    # ------------------------------------------------------------------------------ translator API
    def comms(self) -> Any:
        """The pymoos-compatible client (``notify``, ``notify_binary``, ``register``, ...); thread-safe."""
        return self._comms

    def moos_time(self) -> float:
        """``MOOSTime`` of this translator's client (its own clock: configured warp plus learned skew)."""
        return self._moos_time()

    def add_trigger(self, var: str, func: MoosCallback) -> None:
        """Call ``func(msg)`` for every ``var`` mail, on the translator's thread.

        A second trigger for the same variable is ignored (Goby keeps the first); we log a warning.
        """
        if var in self._triggers:
            log.warning("a trigger for MOOS variable %s exists already; keeping the first (as Goby)", var)
            return
        self._triggers[var] = func
        self._comms.register(var, 0)
        log.debug("Subscribed for MOOS variable: %s", var)

    def add_wildcard_trigger(self, var_wildcard: str, app_wildcard: str, func: MoosCallback) -> None:
        """Call ``func(msg)`` on the translator's thread for mail whose name and source match the MOOS globs
        (``*``, ``?``).  Wildcard triggers fire after the exact trigger of the same message, in the order added."""
        key = (var_wildcard, app_wildcard)
        if key in self._wildcards:
            log.warning("wildcard trigger %s/%s exists already; keeping the first (as Goby)", *key)
            return
        self._wildcards[key] = func
        self._comms.register(var_wildcard, app_wildcard, 0)
        log.debug("Subscribed for MOOS wildcard: variable: %s, app: %s", var_wildcard, app_wildcard)

    def add_buffer(self, var: str) -> None:
        """Keep the latest ``var`` message in :meth:`buffer` (filled for a whole batch before any trigger runs)."""
        self._buffer_vars.add(var)
        self._comms.register(var, 0)

    def buffer(self) -> dict[str, Any]:
        """Latest message per buffered variable; translator code may read and delete entries (same thread)."""
        return self._buffer

    def notify_protobuf(self, var: str, msg: Any, technique: int | None = None) -> bool:
        """Publish ``msg`` on ``var`` in the gateway's technique (``moos.moos_parser_technique``) or ``technique``.

        Binary techniques go out with ``notify_binary``.  Goby refuses the key=value and format techniques here
        (they need a format/algorithm set); so do we (TechniqueError).
        """
        chosen = self._protobuf_technique(technique)
        value = serialize(msg, chosen)
        if is_binary(chosen):
            return self._comms.notify_binary(var, value)
        return self._comms.notify(var, value)

    def parse_protobuf(self, moos_msg: Any, msg: Any, technique: int | None = None) -> Any:
        """Parse a MOOS message's value into ``msg`` with the gateway's technique; returns ``msg``."""
        chosen = self._protobuf_technique(technique)
        value = moos_msg.binary_data() if moos_msg.is_binary() else moos_msg.string()
        return parse(value, msg, chosen)

    def _protobuf_technique(self, technique: int | None) -> Technique:
        chosen = self.technique if technique is None else Technique(technique)
        if chosen in (Technique.COMMA_SEPARATED_KEY_EQUALS_VALUE_PAIRS, Technique.FORMAT):
            raise TechniqueError(f"Non-PROTOBUF techniques are not supported for 'moos_parser_technique': "
                                 f"{chosen.proto_name}")
        return chosen

    # ------------------------------------------------------------------------------ owner thread
    def loop(self) -> None:
        """The translator's tick: post the time variable when a (Goby-clock) second has passed since the last.

        Mail is not fetched here: it is dispatched as it arrives (:meth:`handle_mail`)."""
        now = self._goby_time()
        if now > self._next_time_publish:
            self._comms.notify(TIME_VAR, time_string(self._moos_time(), now))
            self._next_time_publish += TIME_PUBLISH_PERIOD_S
            if self._next_time_publish < now - TIME_PUBLISH_PERIOD_S:  # e.g. after a long stall: do not burst
                self._next_time_publish = now

    def handle_mail(self) -> int:
        """Fetch everything received and dispatch it: buffers for the whole batch first, then per message the
        exact trigger and the wildcard triggers.  Returns the number of messages handled."""
        mail = self._comms.fetch()
        if not mail:
            return 0
        self.mail_batches += 1
        buffer_vars, buffer = self._buffer_vars, self._buffer
        for msg in mail:
            key = msg.key()
            if key in buffer_vars:
                buffer[key] = msg
        triggers, wildcards = self._triggers, self._wildcards
        for msg in mail:
            func = triggers.get(msg.key())
            if func is not None:
                self._run(func, msg)
            if wildcards:
                self._run_wildcards(msg)
        return len(mail)

    def _run_wildcards(self, msg: Any) -> None:
        key, source = msg.key().encode("utf-8", "surrogateescape"), msg.source().encode("utf-8", "surrogateescape")
        for (var_wildcard, app_wildcard), func in list(self._wildcards.items()):
            if wild_match(var_wildcard.encode(), key) and wild_match(app_wildcard.encode(), source):
                self._run(func, msg)

    def _run(self, func: MoosCallback, msg: Any) -> None:
        try:
            func(msg)
        except Exception:
            log.exception("MOOS trigger for %s raised; carrying on with the next message", msg.key())

    def register_all(self) -> None:
        """(Re-)register every trigger, buffer and wildcard; runs on the owner thread after each connect."""
        for var in self._triggers:
            self._comms.register(var, 0)
        for var in self._buffer_vars:
            self._comms.register(var, 0)
        for var_wildcard, app_wildcard in self._wildcards:
            self._comms.register(var_wildcard, app_wildcard, 0)
        log.info("MOOS connected; registered %d trigger(s), %d buffer(s), %d wildcard(s)",
                 len(self._triggers), len(self._buffer_vars), len(self._wildcards))

    def start(self, server: str, port: int, name: str) -> None:
        """Connect the client (asynchronously; it reconnects by itself) as ``name``; on the owner thread."""
        self._started = True
        self._comms.run(server, port, name)

    def close(self) -> None:
        """Close the client (flushing queued notifies); idempotent."""
        if self._closed:
            return
        self._closed = True
        if self._hand_over is not None:
            self._hand_over.closed = True
        if self._started:
            self._comms.close(True)

    # ------------------------------------------------------------------------------ client callbacks
    def _on_connect(self) -> bool:
        """After every (re)connect, on the owner thread (directly, or handed over): register everything."""
        if not self._closed:
            self.register_all()
        return True

    def _on_mail(self) -> bool:
        """Our client on the owner's reactor: mail has arrived; dispatch it now (posts made by the triggers leave
        as one packet when this returns)."""
        self.handle_mail()
        return True
