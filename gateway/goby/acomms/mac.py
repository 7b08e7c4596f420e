"""Goby3's TDMA MAC (``goby::acomms::MACManager``, MAC_FIXED_DECENTRALIZED): slots by src / seconds, on warped time.

Pure logic: ``do_work(now)`` takes warped seconds since the epoch and calls ``on_initiate(slot)`` at the start of
each of our slots; ``next_slot_time(now)`` says when it next has something to do (the link's thread puts a timer
there instead of calling ``do_work`` at Goby's 10 Hz). Every node with the same slot list and the same warped
clock computes the same boundaries from the reference (UTC midnight of the warped day, or ``fixed_ref_time``): no
messages are exchanged.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable

from gateway.goby.acomms.errors import ModemConfigError
from gateway.goby.acomms.protobuf.amac_config_pb2 import (
    MAC_FIXED_DECENTRALIZED,
    MAC_NONE,
    MAC_POLLED,
    MACConfig,
)
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission

log = logging.getLogger(__name__)

#: A slot started later than this (warped seconds) is skipped and the schedule recomputed (Goby's allowed_skew).
ALLOWED_SKEW_S = 2.0
SECONDS_PER_DAY = 86400


class MacManager:
    """Starts our slots; ``on_initiate`` receives a copy of the slot with ``time`` = slot start (µs)."""

    def __init__(self, cfg: MACConfig, on_initiate: Callable[[ModemTransmission], None],
                 on_slot_start: Callable[[ModemTransmission], None] | None = None,
                 allowed_skew_s: float = ALLOWED_SKEW_S) -> None:
        if cfg.type not in (MAC_NONE, MAC_FIXED_DECENTRALIZED):
            name = "MAC_POLLED" if cfg.type == MAC_POLLED else str(cfg.type)
            raise ModemConfigError(f"mac.type {name} is not supported (use MAC_FIXED_DECENTRALIZED or MAC_NONE)")
        for i, slot in enumerate(cfg.slot):
            if slot.slot_seconds <= 0:
                raise ModemConfigError(f"mac.slot[{i}].slot_seconds must be > 0, got {slot.slot_seconds:g}")
        self.cfg = cfg
        self.allowed_skew_s = allowed_skew_s
        self._on_initiate = on_initiate
        self._on_slot_start = on_slot_start
        self._index = 0
        self.next_slot_t: float | None = None
        self.started = 0  # slots started (ours or not)
        self.initiated = 0  # transmissions initiated (our slots)
        self.skipped = 0  # slots skipped because we were more than ALLOWED_SKEW_S late
        self._warned_empty = False

    @property
    def cycle_seconds(self) -> float:
        return sum(slot.slot_seconds for slot in self.cfg.slot)

    def reference(self, now: float) -> float:
        """The schedule's time origin (s since the epoch): UTC midnight of ``now``'s day, or fixed_ref_time."""
        if self.cfg.ref_time_type == MACConfig.REFERENCE_FIXED:
            return float(self.cfg.fixed_ref_time)
        return math.floor(now / SECONDS_PER_DAY) * SECONDS_PER_DAY

    def _restart(self, now: float) -> None:
        """Recompute the next slot from the clock (start of the next cycle, or the next slot boundary)."""
        cycle = self.cycle_seconds
        ref = self.reference(now)
        next_cycle = ref + (math.floor((now - ref) / cycle) + 1) * cycle
        if not self.cfg.start_cycle_in_middle:
            self.next_slot_t, self._index = next_cycle, 0
            return
        t, index = next_cycle - cycle, 0
        while t <= now:
            t += self.cfg.slot[index].slot_seconds
            index = (index + 1) % len(self.cfg.slot)
        self.next_slot_t, self._index = t, index

    def next_slot_time(self, now: float) -> float | None:
        """When ``do_work`` next starts a slot (warped s since the epoch; it must be called once that time has
        passed), computing the schedule from ``now`` if it has none yet; None when it never will (MAC_NONE, no
        slots)."""
        if self.cfg.type == MAC_NONE or not self.cfg.slot:
            return None
        if self.next_slot_t is None:
            self._restart(now)
        return self.next_slot_t

    def do_work(self, now: float) -> None:
        """Start the slot whose time has come (call it once ``next_slot_time`` has passed)."""
        if self.cfg.type == MAC_NONE:
            return
        if not self.cfg.slot:
            if not self._warned_empty:
                log.warning("MAC for modem %d: the cycle is empty (no slots); nothing will be sent", self.cfg.modem_id)
                self._warned_empty = True
            return
        if self.next_slot_t is None:
            self._restart(now)
            return
        if now <= self.next_slot_t:
            return
        if now - self.next_slot_t > self.allowed_skew_s:
            self.skipped += 1
            log.warning("MAC for modem %d: slot at %.3f started %.3f s late; skipping it and restarting the cycle",
                        self.cfg.modem_id, self.next_slot_t, now - self.next_slot_t)
            self._restart(now)
            return
        slot = self.cfg.slot[self._index]
        started = ModemTransmission()
        started.CopyFrom(slot)
        started.time = int(round(self.next_slot_t * 1e6))
        started.slot_index = self._index
        self.started += 1
        if slot.src == self.cfg.modem_id or slot.always_initiate:
            self.initiated += 1
            self._on_initiate(started)
        if self._on_slot_start is not None:
            self._on_slot_start(started)
        self.next_slot_t += slot.slot_seconds
        self._index = (self._index + 1) % len(self.cfg.slot)
