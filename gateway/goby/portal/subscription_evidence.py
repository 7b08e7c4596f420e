"""What one publishing XPUB socket knows of subscriptions: which topics have a subscriber, and which had one when the
broker connection dropped and have not subscribed again (docs/portal.md "Broker restart").

Pure logic, no sockets: the interprocess portal feeds it the messages its XPUB reads and the connection events, and
asks it how to treat a publication.  It runs on the portal's owning thread only.
"""

from __future__ import annotations

#: After a reconnection, how long publications on a topic that had a subscriber are refused while waiting for that
#: subscription to come back; past it the subscriber is taken to be gone.
RESUBSCRIBE_WAIT_S = 5.0

# What a publication's topic is, as seen by the publishing XPUB: no subscriber (ZeroMQ drops it, as any publication
# nobody subscribes to), a subscriber, or a subscriber when the connection dropped that has not come back yet.
UNTRACKED, LIVE, MISSING = 0, 1, 2


class SubscriptionEvidence:
    """Live and missing topics (ZeroMQ prefixes) and the class of each publication identifier, cached."""

    def __init__(self) -> None:
        self.live: set[bytes] = set()
        self.missing: set[bytes] = set()
        self.missing_until = 0.0
        self._classes: dict[str, int] = {}  # identifier -> class, cleared whenever the topics change
        self._published: set[bytes] = set()  # every identifier published through this socket (only these wait)

    def classify(self, ident: str) -> int:
        """Whether publications under ``ident`` reach a subscriber, wait for one to come back, or have none."""
        kind = self._classes.get(ident)
        if kind is None:
            head = ident.encode()
            self._published.add(head)
            kind = self._classes[ident] = self._match(head)
        return kind

    def _match(self, head: bytes) -> int:
        for topics, kind in ((self.missing, MISSING), (self.live, LIVE)):
            if any(head.startswith(topic) or topic.startswith(head) for topic in topics):
                return kind
        return UNTRACKED

    def on_subscription_message(self, msg: bytes) -> bool:
        """Apply one message read from the XPUB (``\\x01`` + topic subscribes, ``\\x00`` + topic unsubscribes).

        Returns True when it brings back the last missing topic."""
        if not msg:
            return False
        topic = msg[1:]
        self._classes.clear()
        if msg[0] == 1:
            self.live.add(topic)
            if topic in self.missing:
                self.missing.discard(topic)
                return not self.missing
        elif msg[0] == 0:
            self.live.discard(topic)
        return False

    def connection_lost(self) -> None:
        """Every topic with a subscriber that we publish to must come back before it is published to again (the
        subscriptions of topics we never published, e.g. other threads' probes, are not waited for)."""
        self.missing |= {topic for topic in self.live
                         if any(head.startswith(topic) or topic.startswith(head) for head in self._published)}
        self._classes.clear()

    def reconnected(self, now: float) -> None:
        """Start the wait of ``RESUBSCRIBE_WAIT_S`` for the missing topics."""
        self.missing_until = now + RESUBSCRIBE_WAIT_S
        self._classes.clear()

    def deadline(self) -> float | None:
        """When :meth:`give_up` will have topics to give up on, if any are missing."""
        return self.missing_until if self.missing else None

    def give_up(self, now: float) -> list[bytes]:
        """The missing topics (sorted) once their wait is over; they then count as having no subscriber."""
        if not self.missing or now < self.missing_until:
            return []
        gone = sorted(self.missing)
        self.missing.clear()
        self._classes.clear()
        return gone
