"""The shore end of the satellite link: publish a USVCommand on intervehicle with an ack, as the course's topside
does, and report the ack (or the expiry) with the slot wait and the ack time.

Used by ``usv-command`` and the mission's shore script. The vehicle end is usv-manager's intervehicle subscription
(publisher id :data:`TOPSIDE_MODEM_ID`, ack required). Everything runs on the owning thread.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass

from gateway.goby.intervehicle import AckData, ExpireData, Publisher, Subscriber, TransporterConfig
from gateway.goby.intervehicle import groups as iv_groups
from gateway.goby.intervehicle.protobuf.intervehicle_pb2 import ModemTransmissionWithLinkID
from gateway.goby.portal import SimpleThread
from translators.usv import groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

log = logging.getLogger(__name__)

#: The course's satellite modem ids (hard-coded in the course's USV manager for the topside).
TOPSIDE_MODEM_ID = 1
USV_MODEM_ID = 2


def usv_subscriber() -> Subscriber:
    """usv-manager's intervehicle subscription: from the topside's modem, acked; not republished (the manager
    republishes each command itself after checking it)."""
    cfg = TransporterConfig()
    cfg.intervehicle.publisher_id.append(TOPSIDE_MODEM_ID)
    cfg.intervehicle.buffer.ack_required = True
    return Subscriber(cfg=cfg, republish=False)


@dataclass
class _Sent:
    command: USVCommand
    published: float  # warped s
    slot_start: float | None = None  # warped s, the slot whose frame first carried it


class SatelliteCommander:
    """Sends commands over the owning thread's intervehicle layer; ``report(ack)`` gets one USVCommandAck
    (LINK_ACKED or LINK_EXPIRED) per command, with ``slot_wait`` (publish to the start of the slot that carried it)
    and ``link_latency`` (publish to the ack or expiry) in sim seconds of this application's clock."""

    def __init__(self, thread: SimpleThread, report: Callable[[USVCommandAck], None]) -> None:
        self._thread = thread
        self._report = report
        self._sent: dict[bytes, _Sent] = {}
        self._queue: list[USVCommand] = []
        thread.context.dccl.load(USVCommand)
        thread.interprocess().subscribe(iv_groups.modem_transmit_result, ModemTransmissionWithLinkID,
                                        self._on_transmit)

    def send(self, command: USVCommand) -> None:
        """Publish ``command`` (its ``time`` identifies it) on the course's usv_command group, once the start-up
        hold is released (call :meth:`service` from the thread's loop): a held publication would count the hold
        as slot wait."""
        self._queue.append(command)
        self.service()

    def service(self) -> None:
        """Send what waited for the hold; call it from the owning thread's ``loop()``."""
        if self._thread.interprocess().hold_state():
            return
        while self._queue:
            self._send_now(self._queue.pop(0))

    def _send_now(self, command: USVCommand) -> None:
        data = self._thread.context.dccl.encode(command)
        self._sent[data] = _Sent(command, self._thread.context.clock.now())
        self._thread.intervehicle().publish(
            groups.usv_command, command, Publisher(on_ack=self._on_ack, on_expire=self._on_expire))

    def _entry(self, command: USVCommand) -> _Sent | None:
        return self._sent.get(self._thread.context.dccl.encode(command))

    def _on_transmit(self, result: ModemTransmissionWithLinkID) -> None:
        for entry_data, entry in self._sent.items():
            if entry.slot_start is None and any(entry_data in frame for frame in result.data.frame):
                entry.slot_start = result.data.time / 1e6

    def _ack(self, command: USVCommand, stage: int, latency_us: int) -> USVCommandAck:
        """The report; times from our publish (the link's own latency counts from its buffer, later)."""
        ack = USVCommandAck(stage=stage, command_time=command.time, link_latency=latency_us / 1e6)  # type: ignore[arg-type]
        entry = self._entry(command)
        if entry is not None:
            ack.link_latency = self._thread.context.clock.now() - entry.published
            if entry.slot_start is not None:
                ack.slot_wait = max(0.0, entry.slot_start - entry.published)
        return ack

    def _on_ack(self, command: USVCommand, data: AckData) -> None:
        ack = self._ack(command, USVCommandAck.LINK_ACKED, data.latency)
        ack.responder = f"satellite modem {data.header.src}"
        self._report(ack)

    def _on_expire(self, command: USVCommand, data: ExpireData) -> None:
        ack = self._ack(command, USVCommandAck.LINK_EXPIRED, data.latency)
        ack.responder = f"satellite modem {data.header.dest[0] if data.header.dest else '?'}"
        ack.error = ExpireData.ExpireReason.Name(data.reason)
        self._report(ack)


def describe_link_ack(ack: USVCommandAck) -> str:
    """One line for the user about a LINK_ACKED / LINK_EXPIRED acknowledgement."""
    wait = f"slot wait {ack.slot_wait:.1f} s, " if ack.HasField("slot_wait") else ""
    if ack.stage == USVCommandAck.LINK_ACKED:
        return f"acked over the satellite link by {ack.responder}: {wait}ack after {ack.link_latency:.1f} s (sim)"
    return f"NOT delivered: expired on the satellite link ({ack.error}) after {ack.link_latency:.1f} s (sim)"
