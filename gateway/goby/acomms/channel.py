"""A simulated channel's loss, delay and outages, as one receiving node hears it (our ``channel_model`` extension).

Where Linux ``tc netem`` cannot be used (no ``sch_netem`` module, no root, an in-process ether), a datagram modem
driver applies this model to every transmission it receives from another modem, data and acks alike: it is lost
with probability ``loss``, lost when it arrives inside an outage window (``outage_duration`` every
``outage_period`` seconds from ``outage_phase``, on the link's clock, so every node shares the windows), and
otherwise delivered after a delay drawn uniformly in ``[delay_min, delay_max]``. Each receiving node draws on its
own (its seed is ``seed`` combined with its modem id), as each receiver of an acoustic transmission does; a later
transmission whose draw is shorter overtakes an earlier one, as in water. With a seed, the drop pattern of a node
depends only on the sequence of transmissions it receives (a loss and a delay are drawn for each, whatever the
delay and outage settings). Times are the link's (warped) seconds.

:class:`Channel` only decides and holds; it has no thread and no timer: the driver asks it what is due and when
the next delivery is, and the link's thread arms its timer there (``Link.next_deadline``).
"""

from __future__ import annotations

import heapq
import itertools
import math
import random
from dataclasses import dataclass
from typing import Generic, TypeVar

from gateway.goby.acomms.errors import ModemConfigError
from gateway.goby.acomms.protobuf.channel_model_pb2 import ChannelModel, channel_model
from gateway.goby.acomms.protobuf.driver_base_pb2 import DriverConfig

__all__ = ["MAX_DELAY_S", "MAX_HELD", "Channel", "ChannelCounters", "ChannelModel", "channel_model_of",
           "check_channel_model", "describe"]

#: The longest delay (and outage) the model accepts, seconds: past an hour it is a typo, not a channel.
MAX_DELAY_S = 3600.0
#: Transmissions held for delayed delivery at most; past it a received one is dropped (counted as ``overflow``).
MAX_HELD = 10_000

T = TypeVar("T")


def channel_model_of(cfg: DriverConfig) -> ChannelModel | None:
    """The driver block's ``channel_model`` extension, checked (``ModemConfigError`` names a bad field), or None."""
    if not cfg.HasExtension(channel_model):
        return None
    model = ChannelModel()
    model.CopyFrom(cfg.Extensions[channel_model])
    check_channel_model(model)
    return model


def _check(name: str, value: float, low: float, high: float, what: str) -> None:
    if not (math.isfinite(value) and low <= value <= high):
        raise ModemConfigError(f"channel_model.{name} {value!r} is out of range: {what}")


def check_channel_model(model: ChannelModel) -> None:
    """Raise ``ModemConfigError`` naming the first field out of range."""
    _check("loss", model.loss, 0.0, 1.0, "a probability, 0 to 1")
    _check("delay_min", model.delay_min, 0.0, MAX_DELAY_S, f"seconds, 0 to {MAX_DELAY_S:g}")
    if model.HasField("delay_max"):
        _check("delay_max", model.delay_max, model.delay_min, MAX_DELAY_S,
               f"seconds, from delay_min ({model.delay_min:g}) to {MAX_DELAY_S:g}")
    _check("outage_period", model.outage_period, 0.0, math.inf, "seconds, >= 0 (0: no outages)")
    if model.outage_period > 0:
        _check("outage_duration", model.outage_duration, 0.0, model.outage_period,
               f"seconds, 0 to outage_period ({model.outage_period:g})")
    elif model.outage_duration != 0:
        raise ModemConfigError(f"channel_model.outage_duration {model.outage_duration!r} needs an outage_period > 0")
    _check("outage_phase", model.outage_phase, -math.inf, math.inf, "a finite time in seconds")


def describe(model: ChannelModel) -> str:
    """One line: what the model does (for logs and the demo's summary)."""
    parts = [f"loss {100 * model.loss:g}%"]
    high = model.delay_max if model.HasField("delay_max") else model.delay_min
    if high > 0:
        parts.append(f"delay {model.delay_min:g}-{high:g} s" if high > model.delay_min else f"delay {high:g} s")
    if model.outage_period > 0 and model.outage_duration > 0:
        parts.append(f"outage {model.outage_duration:g} s every {model.outage_period:g} s"
                     + (f" from {model.outage_phase:g}" if model.outage_phase else ""))
    parts.append(f"seed {model.seed}" if model.HasField("seed") else "unseeded")
    return ", ".join(parts)


@dataclass
class ChannelCounters:
    """What the channel did to the transmissions it was given."""

    received: int = 0  # transmissions given to the channel
    lost: int = 0  # lost by the loss draw
    outage: int = 0  # lost in an outage window
    overflow: int = 0  # dropped because MAX_HELD were already held
    delayed: int = 0  # held for a later delivery
    delivered: int = 0  # handed on (at once or after their delay)

    @property
    def dropped(self) -> int:
        return self.lost + self.outage + self.overflow


class Channel(Generic[T]):
    """One receiving node's channel: ``admit`` decides the fate of a received item, ``due`` hands over delayed
    items whose time has come, ``next_delivery`` says when the next one is. One thread (the link's)."""

    def __init__(self, model: ChannelModel, modem_id: int) -> None:
        check_channel_model(model)
        self.model = model
        self.loss = model.loss
        self.delay_min = model.delay_min
        self.delay_max = model.delay_max if model.HasField("delay_max") else model.delay_min
        self.period = model.outage_period
        self.duration = model.outage_duration if model.outage_period > 0 else 0.0
        self.phase = model.outage_phase
        self.rng = random.Random(f"{model.seed}/{modem_id}") if model.HasField("seed") else random.Random()
        self.counters = ChannelCounters()
        self._held: list[tuple[float, int, T]] = []
        self._sequence = itertools.count()

    def in_outage(self, now: float) -> bool:
        return self.duration > 0 and (now - self.phase) % self.period < self.duration

    def admit(self, item: T, now: float) -> tuple[str, T | None]:
        """The fate of ``item`` received at ``now``: ``("deliver", item)`` to hand it on now, ``("delay", None)``
        when it is held for ``due``, or ``("lost" | "outage" | "overflow", None)`` when the channel dropped it."""
        c = self.counters
        c.received += 1
        lost = self.rng.random() < self.loss  # both drawn for every item: the pattern depends on the seed alone
        delay = self.rng.uniform(self.delay_min, self.delay_max)
        if self.in_outage(now):
            c.outage += 1
            return "outage", None
        if lost:
            c.lost += 1
            return "lost", None
        if delay <= 0:
            c.delivered += 1
            return "deliver", item
        if len(self._held) >= MAX_HELD:
            c.overflow += 1
            return "overflow", None
        c.delayed += 1
        heapq.heappush(self._held, (now + delay, next(self._sequence), item))
        return "delay", None

    def due(self, now: float) -> list[T]:
        """The held items whose delivery time is ``now`` or earlier, in delivery order."""
        out: list[T] = []
        while self._held and self._held[0][0] <= now:
            out.append(heapq.heappop(self._held)[2])
        self.counters.delivered += len(out)
        return out

    def next_delivery(self) -> float | None:
        """When the next held item is due (the link's clock), or None."""
        return self._held[0][0] if self._held else None

    @property
    def held(self) -> int:
        return len(self._held)
