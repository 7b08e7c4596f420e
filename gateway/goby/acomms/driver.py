"""The modem driver ABC (Goby3's ``ModemDriverBase``) and the datagram logic shared by our drivers.

Goby's API: ``startup(cfg)``, ``shutdown()``, ``do_work()``, ``handle_initiate_transmission(msg)``, and signals
``signal_data_request`` (fill the frames of our transmission), ``signal_receive`` (every transmission heard, data
and acks), ``signal_transmit_result`` (what was sent). All run on the thread that calls ``do_work`` and
``handle_initiate_transmission`` (the link's thread).

:class:`DatagramDriver` owns the behaviour of Goby's UDP multicast driver (``udp_multicast_driver.cpp``): the
running frame counter, ``max_frame_bytes`` from the slot (else ``rate_to_bytes``, else ``max_frame_size``),
nothing sent for an empty slot, the serialized ``ModemTransmission`` as the whole datagram, own datagrams dropped
by ``src``, and an immediate ACK for unicast data addressed to us. Subclasses only move bytes.
"""

from __future__ import annotations

import abc
import logging
from collections.abc import Callable
from typing import Generic, TypeVar

from google.protobuf.message import DecodeError

from gateway.goby.acomms.protobuf.driver_base_pb2 import DriverConfig
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission

log = logging.getLogger(__name__)

T = TypeVar("T")


class Signal(Generic[T]):
    """A list of callbacks (Goby's boost::signals2 signal); ``emit`` calls them in connection order."""

    def __init__(self) -> None:
        self._slots: list[Callable[[T], None]] = []

    def connect(self, fn: Callable[[T], None]) -> None:
        self._slots.append(fn)

    def emit(self, value: T) -> None:
        for fn in list(self._slots):
            fn(value)


class ModemDriver(abc.ABC):
    """What every modem driver does; connect the signals before ``startup``."""

    def __init__(self) -> None:
        self.signal_data_request: Signal[ModemTransmission] = Signal()
        self.signal_receive: Signal[ModemTransmission] = Signal()
        self.signal_transmit_result: Signal[ModemTransmission] = Signal()

    @abc.abstractmethod
    def startup(self, cfg: DriverConfig) -> None:
        """Open the link (``cfg.modem_id`` is the id within the subnet); raises ``ModemDriverError``."""

    @abc.abstractmethod
    def shutdown(self) -> None:
        """Close the link; idempotent."""

    @abc.abstractmethod
    def do_work(self) -> None:
        """Handle what arrived (emits ``signal_receive``); called by the link loop (10 Hz warped)."""

    @abc.abstractmethod
    def handle_initiate_transmission(self, msg: ModemTransmission) -> None:
        """The MAC started our slot: ask for data (``signal_data_request``) and send it."""


class DatagramDriver(ModemDriver):
    """Goby's UDP multicast driver behaviour over any datagram transport (``_send``, ``_receive_all``)."""

    def __init__(self) -> None:
        super().__init__()
        self.cfg = DriverConfig()
        self.modem_id = 0
        self._next_frame = 0
        self.sent = 0  # datagrams sent (data and acks)
        self.received = 0  # datagrams received from others
        self.malformed = 0

    # -------------------------------------------------------------------------------------- transport
    @abc.abstractmethod
    def _send(self, datagram: bytes) -> None:
        """Deliver ``datagram`` to every node on the link (ourselves included is fine: dropped by src)."""

    @abc.abstractmethod
    def _receive_all(self) -> list[bytes]:
        """Every datagram that arrived since the last call, without blocking."""

    def _max_frame_size(self, msg: ModemTransmission) -> int:
        """The frame size when the slot gives none (Goby: rate_to_bytes[rate], else max_frame_size)."""
        return 1400

    # -------------------------------------------------------------------------------------------- API
    def startup(self, cfg: DriverConfig) -> None:
        self.cfg = cfg
        self.modem_id = cfg.modem_id

    def handle_initiate_transmission(self, msg: ModemTransmission) -> None:
        msg.src = self.modem_id
        msg.frame_start = self._next_frame
        if not msg.HasField("max_frame_bytes"):
            msg.max_frame_bytes = self._max_frame_size(msg)
        self.signal_data_request.emit(msg)
        self._next_frame += max(1, len(msg.frame))
        if msg.frame and msg.frame[0]:
            self._transmit(msg)

    def do_work(self) -> None:
        for datagram in self._receive_all():
            self._handle_datagram(datagram)

    # ------------------------------------------------------------------------------------------ logic
    def _transmit(self, msg: ModemTransmission) -> None:
        self._send(msg.SerializeToString())
        self.sent += 1
        self.signal_transmit_result.emit(msg)

    def _handle_datagram(self, datagram: bytes) -> None:
        msg = ModemTransmission()
        try:
            msg.ParseFromString(datagram)
        except DecodeError as exc:
            self.malformed += 1
            log.error("modem %d: dropping a datagram that is not a ModemTransmission (%d bytes): %s",
                      self.modem_id, len(datagram), exc)
            return
        if msg.src == self.modem_id:
            return  # our own multicast loopback
        self.received += 1
        if (msg.type == ModemTransmission.DATA and msg.ack_requested and msg.dest == self.modem_id):
            ack = ModemTransmission(src=self.modem_id, dest=msg.src, type=ModemTransmission.ACK)
            ack.acked_frame.extend(range(msg.frame_start, msg.frame_start + len(msg.frame)))
            self._transmit(ack)
        self.signal_receive.emit(msg)
