"""Who else subscribes to what a client publishes, and what waits for them after a reconnection (pure logic).

A confirmed message reaches the clients registered for it *when the DB processed it*, so after a DB restart a post
written before its subscribers have registered again is lost to them. A publishing client therefore asks the DB
every ``SUMMARY_PERIOD_S`` which clients subscribe to what (``PROC_SUMMARY``, as uMS does; an asynchronous client
asks in the packet of its once-a-second timing message, so the question costs no packet or wake-up of its own).
When the link goes down, each variable we publish that others subscribed to becomes *missing*; after the reconnection its posts are
refused and its queued mail is held until the DB lists those subscribers again (asked every
``RESUBSCRIBE_POLL_S``), or until ``RESUBSCRIBE_WAIT_S`` has passed: then they are taken to be gone.

:class:`SubscriberWatch` only decides: it is given ``now``, the encoded outbox and the parsed summaries, and returns
what to send, hold or release; the engine does the I/O and logging. Not thread-safe: ``ClientEngine`` calls it
under its lock, from whichever thread is writing (its reactor thread, or an application thread writing directly)
and, for replies, from its reactor thread.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from .codec import PacketReader, encode_message, frame_packet
from .message import NOTIFY, SERVER_REQUEST, STRING, MoosMessage

SUMMARY_PERIOD_S = 1.0  # how often a publishing client asks who subscribes to what
RESUBSCRIBE_POLL_S = 0.05  # after a reconnection, how often it asks until its variables' subscribers are back
RESUBSCRIBE_WAIT_S = 5.0  # past this, subscribers that have not registered again are taken to be gone
SUMMARY_REQUEST_ID = -3  # our PROC_SUMMARY requests (the DB echoes the id); server_request() uses -2
PROC_SUMMARY = b"PROC_SUMMARY"


def summary_request(src: bytes, msg_time: float) -> bytes:
    """Our encoded ``PROC_SUMMARY`` request."""
    return encode_message(MoosMessage(SERVER_REQUEST, STRING, msg_id=SUMMARY_REQUEST_ID, src=src, key=PROC_SUMMARY,
                                      msg_time=msg_time))


def is_summary_reply(msg: MoosMessage) -> bool:
    """Whether ``msg`` answers one of our ``PROC_SUMMARY`` requests (not an application's ``server_request``)."""
    return msg.msg_id == SUMMARY_REQUEST_ID and msg.raw_key == PROC_SUMMARY


def parse_proc_summary(lines: Iterable[bytes], own_name: bytes, published: Iterable[bytes]
                       ) -> dict[bytes, frozenset[bytes]]:
    """Variable -> the other clients subscribed to it, for the ``published`` variables, from the DB's
    ``PROC_SUMMARY`` lines (``client:SUBSCRIBED=,A,B,PUBLISHED=,X``). Our own line is skipped."""
    wanted = set(published)
    subscribers: dict[bytes, set[bytes]] = {}
    for line in lines:
        client, _, rest = line.partition(b":")
        if client == own_name:
            continue
        subscribed = rest.split(b",PUBLISHED=", 1)[0].removeprefix(b"SUBSCRIBED=")
        for key in subscribed.split(b","):
            if key in wanted:
                subscribers.setdefault(key, set()).add(client)
    return {key: frozenset(clients) for key, clients in subscribers.items()}


@dataclass
class Poll:
    """What :meth:`SubscriberWatch.poll` decided."""

    ask: bool = False  # send a PROC_SUMMARY request now
    gave_up: frozenset[bytes] = frozenset()  # variables whose subscribers did not come back in time
    release: list[bytes] = field(default_factory=list)  # held mail to send before anything queued since


class SubscriberWatch:
    """The subscribers of what we publish, as last listed by the DB, and what waits for them after a reconnection."""

    def __init__(self) -> None:
        self.subscribers: dict[bytes, frozenset[bytes]] = {}  # the DB's last PROC_SUMMARY, our variables only
        self.expected: dict[bytes, frozenset[bytes]] = {}  # who we wait for, per missing variable
        self.missing: set[bytes] = set()  # variables whose posts are refused and whose mail is held
        self.missing_until = 0.0  # when we stop waiting (monotonic; inf until reconnected)
        self.held: list[bytes] = []  # encoded mail of missing variables, in post order
        self.last_request = 0.0
        self.pending = False  # a request is out: its replies are ours, not the application's

    def lost(self) -> None:
        """The link went down: every variable with other subscribers will wait for them after reconnecting."""
        expected = {key: subs for key, subs in self.subscribers.items() if subs}
        for key in self.missing:  # lost again while still waiting: keep waiting for those too
            expected[key] = expected.get(key, frozenset()) | self.expected.get(key, frozenset())
        self.expected = expected
        self.missing = set(expected)
        self.missing_until = float("inf")
        self.subscribers = {}
        self.pending = False
        self.last_request = 0.0

    def reconnected(self, now: float, outbox: list[bytes]) -> list[bytes]:
        """Start the wait; returns ``outbox`` (encoded messages) less the mail of missing variables, now held."""
        if not self.missing:
            return outbox
        self.missing_until = now + RESUBSCRIBE_WAIT_S
        if not outbox:
            return outbox
        messages = PacketReader(2**31 - 1).feed(frame_packet(outbox))[0]
        keep: list[bytes] = []
        for encoded, msg in zip(outbox, messages, strict=True):
            if msg.msg_type == NOTIFY and msg.raw_key in self.missing:
                self.held.append(encoded)
            else:
                keep.append(encoded)
        return keep

    def poll(self, now: float, publishing: bool, first_publication: bool = False) -> Poll:
        """Whether a request is due (only while we publish something): every period, and at once when we publish a
        variable the DB has not been asked about (its subscribers must be known before a drop can come); gives up
        waiting past ``missing_until``."""
        decision = Poll()
        if self.missing and now >= self.missing_until:
            decision.gave_up = frozenset(self.missing)
            self.missing.clear()
            decision.release = self._take_held()
        period = RESUBSCRIBE_POLL_S if self.missing else SUMMARY_PERIOD_S
        if publishing and (first_publication or now - self.last_request >= period):
            self.last_request = now
            self.pending = True
            decision.ask = True
        return decision

    def next_poll_in(self, now: float) -> float:
        """Seconds until the next quick request while waiting for subscribers, else inf."""
        return self.last_request + RESUBSCRIBE_POLL_S - now if self.missing else float("inf")

    def summary(self, subscribers: dict[bytes, frozenset[bytes]]) -> list[bytes] | None:
        """Take the DB's answer (see :func:`parse_proc_summary`). When the last missing variable's subscribers
        are all back, returns the held mail to send (maybe empty); else None."""
        self.pending = False
        self.subscribers = subscribers
        if not self.missing:
            return None
        empty: frozenset[bytes] = frozenset()
        for key in [k for k in self.missing if self.expected.get(k, empty) <= subscribers.get(k, empty)]:
            self.missing.discard(key)
        if self.missing:
            return None
        return self._take_held()

    def _take_held(self) -> list[bytes]:
        held, self.held = self.held, []
        return held
