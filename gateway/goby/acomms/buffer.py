"""Goby3's ``DynamicBuffer``: per-destination, per-(group, DCCL id) priority queues for the intervehicle links.

Pure logic: every method takes ``now`` (warped seconds, Goby's SteadyClock under warp), so tests drive time by
hand and the broker's intervehicle thread passes its warped clock. Rules follow Goby3
``src/acomms/buffer/dynamic_buffer.h``:

- config merge over all subscriber and publisher configs: ``ack_required`` and ``newest_first`` true wins,
  smallest ``blackout_time``, largest ``max_queue``, mean ``ttl`` and ``value_base``, proto defaults otherwise;
- ``push`` puts data at the front (newest_first) or the back and pops from the back past ``max_queue``
  (FIFO therefore drops the value just pushed); those come back as overflowed values;
- priority ``value_base * (now - last_access) / ttl``; empty, in blackout, all awaiting an ack (sent less than
  ``ack_timeout`` ago) or too large for the room left: ``-inf``;
- ``top`` runs the contest over one destination (or all, ``dest=None``); the strictly greatest wins.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Hashable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

from gateway.goby.acomms.errors import AcommsError
from gateway.goby.acomms.protobuf.buffer_pb2 import DynamicBufferConfig

#: ``last_sent`` of a value never sent (Goby's ``zero_point_``).
NEVER_SENT = -math.inf


class BufferNoDataError(AcommsError):
    """No sub-buffer has a value that can be sent now (Goby's ``DynamicBufferNoDataException``)."""


def merge_configs(cfgs: Iterable[DynamicBufferConfig]) -> DynamicBufferConfig:
    """One config from several, by Goby's rules; only fields that are set take part."""
    cfgs = list(cfgs)
    if not cfgs:
        raise ValueError("merge_configs needs at least one DynamicBufferConfig")
    out = DynamicBufferConfig()
    ttls: list[float] = []
    bases: list[float] = []
    for cfg in cfgs:
        if cfg.HasField("ack_required") and (not out.HasField("ack_required") or cfg.ack_required):
            out.ack_required = cfg.ack_required
        if cfg.HasField("blackout_time") and (
                not out.HasField("blackout_time") or cfg.blackout_time < out.blackout_time):
            out.blackout_time = cfg.blackout_time
        if cfg.HasField("max_queue") and (not out.HasField("max_queue") or cfg.max_queue > out.max_queue):
            out.max_queue = cfg.max_queue
        if cfg.HasField("newest_first") and (not out.HasField("newest_first") or cfg.newest_first):
            out.newest_first = cfg.newest_first
        if cfg.HasField("ttl"):
            ttls.append(cfg.ttl)
        if cfg.HasField("value_base"):
            bases.append(cfg.value_base)
    if ttls:
        out.ttl = sum(ttls) / len(ttls)
    if bases:
        out.value_base = sum(bases) / len(bases)
    return out


@dataclass(eq=False)
class Value:
    """One buffered datum: when it was pushed (warped s) and the data (any object; ``len(data)`` is its size)."""

    push_time: float
    data: Any
    last_sent: float = field(default=NEVER_SENT)


class DynamicSubBuffer:
    """The queue of one (destination, buffer id); see the module docstring for the rules."""

    def __init__(self, cfgs: Iterable[DynamicBufferConfig], now: float) -> None:
        self.cfg = DynamicBufferConfig()
        self._values: deque[Value] = deque()
        self.last_access = now
        self.update(cfgs)

    def update(self, cfgs: Iterable[DynamicBufferConfig]) -> None:
        """Replace the merged config, keeping the data (Goby also moves ``last_access`` back by the blackout)."""
        self.cfg = merge_configs(cfgs)
        self.last_access -= self.cfg.blackout_time

    def __len__(self) -> int:
        return len(self._values)

    def __iter__(self) -> Iterator[Value]:
        return iter(self._values)

    def _eligible(self, now: float, ack_timeout: float) -> Value | None:
        for value in self._values:
            if value.last_sent == NEVER_SENT or value.last_sent + ack_timeout < now:
                return value
        return None

    def top_value(self, now: float, max_bytes: float = math.inf, ack_timeout: float = 0.0) -> float:
        """This sub-buffer's priority now (``-inf``: nothing it may send)."""
        if not self._values:
            return -math.inf
        if now <= self.last_access + self.cfg.blackout_time:
            return -math.inf
        value = self._eligible(now, ack_timeout)
        if value is None or len(value.data) > max_bytes:
            return -math.inf
        return self.cfg.value_base * (now - self.last_access) / self.cfg.ttl

    def top(self, now: float, ack_timeout: float = 0.0) -> Value:
        """The first value not awaiting an ack; marks it (and this sub-buffer) as sent now."""
        value = self._eligible(now, ack_timeout)
        if value is None:
            raise BufferNoDataError("DynamicSubBuffer.top() found no data")
        self.last_access = now
        value.last_sent = now
        return value

    def push(self, data: Any, now: float) -> list[Value]:
        """Queue ``data``; returns the values dropped by ``max_queue`` (the oldest, or for FIFO the new one)."""
        value = Value(now, data)
        if self.cfg.newest_first:
            self._values.appendleft(value)
        else:
            self._values.append(value)
        dropped = []
        while len(self._values) > self.cfg.max_queue:
            dropped.append(self._values.pop())
        return dropped

    def expire(self, now: float) -> list[Value]:
        """Remove and return the values older than ``ttl``, from the old end."""
        expired = []
        ttl = self.cfg.ttl
        if self.cfg.newest_first:
            while self._values and now > self._values[-1].push_time + ttl:
                expired.append(self._values.pop())
        else:
            while self._values and now > self._values[0].push_time + ttl:
                expired.append(self._values.popleft())
        return expired

    def next_expiry(self) -> float | None:
        """When ``expire`` next removes a value (the oldest one's ``push_time + ttl``; ``expire`` takes it once
        ``now`` is past that), or None when empty."""
        if not self._values:
            return None
        oldest = self._values[-1] if self.cfg.newest_first else self._values[0]
        return oldest.push_time + self.cfg.ttl

    def erase(self, value: Value) -> bool:
        """Remove ``value`` (by identity); False if it is no longer here."""
        for i, held in enumerate(self._values):
            if held is value:
                del self._values[i]
                return True
        return False


@dataclass(frozen=True)
class TopResult:
    """The winner of one contest: where it goes, which sub-buffer, the value, and that sub-buffer's config."""

    dest: int
    buffer_id: Hashable
    value: Value
    cfg: DynamicBufferConfig


class DynamicBuffer:
    """All sub-buffers of one link, keyed by (destination modem id, buffer id)."""

    def __init__(self) -> None:
        self._subs: dict[int, dict[Hashable, DynamicSubBuffer]] = {}

    def create(self, dest: int, buffer_id: Hashable, cfgs: Iterable[DynamicBufferConfig], now: float) -> None:
        """Create the sub-buffer, or update its config (keeping its data) if it exists."""
        subs = self._subs.setdefault(dest, {})
        if buffer_id in subs:
            subs[buffer_id].update(cfgs)
        else:
            subs[buffer_id] = DynamicSubBuffer(cfgs, now)

    def remove(self, dest: int, buffer_id: Hashable) -> None:
        subs = self._subs.get(dest)
        if subs is not None:
            subs.pop(buffer_id, None)
            if not subs:
                del self._subs[dest]

    def has(self, dest: int, buffer_id: Hashable) -> bool:
        return buffer_id in self._subs.get(dest, {})

    def sub(self, dest: int, buffer_id: Hashable) -> DynamicSubBuffer:
        return self._subs[dest][buffer_id]

    def destinations(self, buffer_id: Hashable) -> list[int]:
        """Every destination with a sub-buffer for ``buffer_id``."""
        return [dest for dest, subs in sorted(self._subs.items()) if buffer_id in subs]

    def push(self, dest: int, buffer_id: Hashable, data: Any, now: float) -> list[Value]:
        return self._subs[dest][buffer_id].push(data, now)

    def size(self) -> int:
        """Values held in every sub-buffer."""
        return sum(len(sub) for subs in self._subs.values() for sub in subs.values())

    def empty(self) -> bool:
        return self.size() == 0

    def top(self, now: float, dest: int | None = None, max_bytes: float = math.inf,
            ack_timeout: float = 0.0) -> TopResult:
        """Run the priority contest over ``dest``'s sub-buffers (all if ``None``) and take the winner's value.

        Raises ``BufferNoDataError`` when no sub-buffer has a finite value.
        """
        best: tuple[float, int, Hashable, DynamicSubBuffer] | None = None
        candidates = [(dest, self._subs.get(dest, {}))] if dest is not None else sorted(self._subs.items())
        for d, subs in candidates:
            for buffer_id, sub in subs.items():
                v = sub.top_value(now, max_bytes, ack_timeout)
                if v == -math.inf or math.isnan(v):
                    continue
                if best is None or v > best[0]:
                    best = (v, d, buffer_id, sub)
        if best is None:
            raise BufferNoDataError("no sub-buffer has data to send now")
        _, d, buffer_id, sub = best
        return TopResult(d, buffer_id, sub.top(now, ack_timeout), sub.cfg)

    def erase(self, dest: int, buffer_id: Hashable, value: Value) -> bool:
        """Remove ``value`` (acked, or sent without ack); False if it is gone already."""
        subs = self._subs.get(dest)
        if subs is None or buffer_id not in subs:
            return False
        return subs[buffer_id].erase(value)

    def next_expiry(self) -> float | None:
        """The earliest ``next_expiry`` of the sub-buffers (warped s), or None when every one is empty."""
        times = [t for subs in self._subs.values() for sub in subs.values() if (t := sub.next_expiry()) is not None]
        return min(times, default=None)

    def expire(self, now: float) -> list[tuple[int, Hashable, Value]]:
        """Remove every value past its ttl; returns (dest, buffer_id, value) for each."""
        out: list[tuple[int, Hashable, Value]] = []
        for d, subs in self._subs.items():
            for buffer_id, sub in subs.items():
                out.extend((d, buffer_id, value) for value in sub.expire(now))
        return out
