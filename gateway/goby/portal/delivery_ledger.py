"""Which publications a portal has not yet seen confirmed through the broker, and when to send a delivery probe.

ZeroMQ gives no acknowledgements, so a portal publishes, to itself only, a numbered probe; one PUB → XSUB → XPUB
path keeps order, so a probe that comes back confirms everything sent before it (docs/portal.md "Delivery probes").
What is unconfirmed when the connection drops is in doubt and reported.

Pure logic, no sockets: the interprocess portal records what it sent, asks for probe payloads and hands back the
probes it receives, all with the ``now`` of its own clock.  It runs on the portal's owning thread only.
"""

from __future__ import annotations

from collections import deque

#: A delivery probe goes out once this many publications are unconfirmed, or the oldest is this old.
PROBE_BATCH = 8
PROBE_AGE_S = 0.1
PROBE_RETRY_S = 0.5  # a probe not back by then is sent again (it may have been dropped with a full queue)
MAX_UNCONFIRMED = 100_000  # beyond this the oldest unconfirmed publications are assumed delivered


class DeliveryLedger:
    """Unconfirmed publications in the order sent, the probes in flight and what each covers."""

    def __init__(self, max_unconfirmed: int = MAX_UNCONFIRMED) -> None:
        self._max = max_unconfirmed
        self._unconfirmed: deque[tuple[int, float, str, bytes]] = deque()  # (seq, sent at, group, payload)
        self._seq = 0
        self._probes: dict[int, int] = {}  # probe number -> the last publication seq it covers
        self._probe_n = 0
        self._probe_out_at: float | None = None  # when the outstanding probe was sent (or last tried)
        #: Publications dropped from the ledger unconfirmed because it held ``max_unconfirmed`` (never reported).
        self.assumed_delivered = 0

    def __len__(self) -> int:
        return len(self._unconfirmed)

    def record(self, group: str, payload: bytes, now: float) -> bool:
        """Note a publication sent to a topic with a subscriber; True when a probe should go out now."""
        self._seq += 1
        self._unconfirmed.append((self._seq, now, group, payload))
        if len(self._unconfirmed) > self._max:
            self._unconfirmed.popleft()
            self.assumed_delivered += 1
        return len(self._unconfirmed) >= PROBE_BATCH and self._probe_out_at is None

    def probe_due(self, now: float) -> bool:
        """True when a probe should go out: a batch or an old publication unconfirmed, or the last probe overdue."""
        if not self._unconfirmed:
            return False
        if self._probe_out_at is not None:
            return now - self._probe_out_at >= PROBE_RETRY_S
        return len(self._unconfirmed) >= PROBE_BATCH or now - self._unconfirmed[0][1] >= PROBE_AGE_S

    def next_probe(self) -> bytes:
        """The payload of a new probe (its number as CSTR); call :meth:`probe_sent` or :meth:`probe_not_sent`."""
        self._probe_n += 1
        return f"{self._probe_n}".encode() + b"\0"

    def probe_sent(self, now: float) -> None:
        """The probe of the last :meth:`next_probe` went out: it covers everything recorded so far."""
        self._probes[self._probe_n] = self._seq
        self._probe_out_at = now

    def probe_not_sent(self, now: float) -> None:
        """No probe could go out (not connected, our probe subscription not through, full queue): retry later."""
        self._probe_out_at = now

    def confirm(self, payload: bytes, now: float) -> bool:
        """A probe of ours came back: what it covers is delivered.  True when another probe should go out now."""
        try:
            number = int(payload.rstrip(b"\0"))
        except ValueError:
            return False
        covered = self._probes.get(number)
        if covered is None:
            return False
        for older in [n for n in self._probes if n <= number]:
            del self._probes[older]
        unconfirmed = self._unconfirmed
        while unconfirmed and unconfirmed[0][0] <= covered:
            unconfirmed.popleft()
        self._probe_out_at = None
        return self.probe_due(now)

    def deadline(self) -> float | None:
        """The time :meth:`probe_due` next becomes true, if anything is unconfirmed."""
        if not self._unconfirmed:
            return None
        if self._probe_out_at is not None:
            return self._probe_out_at + PROBE_RETRY_S
        return self._unconfirmed[0][1] + PROBE_AGE_S

    def in_doubt(self) -> list[tuple[str, bytes]]:
        """The connection dropped: every unconfirmed publication as (group, payload), oldest first; the ledger and
        the probes in flight are cleared."""
        lost = [(group, payload) for _, _, group, payload in self._unconfirmed]
        self._unconfirmed.clear()
        self._probes.clear()
        self._probe_out_at = None
        return lost
