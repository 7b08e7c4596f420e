"""The modem driver ABC (Goby3's ``ModemDriverBase``) and the datagram logic shared by our drivers.

Goby's API: ``startup(cfg)``, ``shutdown()``, ``do_work()``, ``handle_initiate_transmission(msg)``, and signals
``signal_data_request`` (fill the frames of our transmission), ``signal_receive`` (every transmission heard, data
and acks), ``signal_transmit_result`` (what was sent). All run on the thread that calls ``do_work`` and
``handle_initiate_transmission`` (the broker's intervehicle thread). Ours adds ``fileno()``: a descriptor that is
readable whenever ``do_work`` has something to read, so the link calls ``do_work`` only then (Goby calls it at
10 Hz warped whether anything arrived or not).

:class:`DatagramDriver` owns the behaviour of Goby's UDP multicast driver (``udp_multicast_driver.cpp``): the
running frame counter, ``max_frame_bytes`` from the slot (else ``rate_to_bytes``, else ``max_frame_size``),
nothing sent for an empty slot, the serialized ``ModemTransmission`` as the whole datagram, own datagrams dropped
by ``src``, and an immediate ACK for unicast data addressed to us. Subclasses only move bytes.

A datagram is remote input: before anything is acked or emitted, its fields are range-checked (``src``, frame
numbers, no more frames or acked frames than a slot allows); a datagram that fails is dropped, counted in
``refused`` by cause and logged at a rate-limited cadence, and nothing a datagram makes the link code raise ends
the link's thread. Only data from the link's ``peers`` (set by the link from its slot plan) is acked.

A driver block with our ``channel_model`` extension impairs what this node receives (``gateway.goby.acomms.channel``:
loss, delay, outages; checked at ``startup``): after a datagram is parsed and known not to be our own, the channel
drops it (counted in ``channel.counters``, apart from ``refused``, and logged at a rate-limited cadence) or holds it
until its delivery time; only then is it acked and emitted (the range checks come first: bad input is refused as
such, never counted as a channel loss), so a delayed data frame is acked on
delivery and the ack crosses the sender's channel in turn. The link delivers held datagrams from its thread's timer
(``next_delivery`` / ``deliver_due``, on the link's clock), never by polling.
"""

from __future__ import annotations

import abc
import logging
import time
from collections import Counter
from collections.abc import Callable, Collection
from typing import Generic, TypeVar

from google.protobuf.message import DecodeError

from gateway.goby.acomms.channel import Channel, channel_model_of, describe
from gateway.goby.acomms.protobuf.driver_base_pb2 import DriverConfig
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission
from util.ratelimit import RateLimitedLog

log = logging.getLogger(__name__)

#: Frame numbers and acked frames travel as int32 (``acked_frame``): a frame number past this is out of range.
MAX_FRAME_NUMBER = 2**31 - 1
#: Seconds between two log lines of the same kind of refused datagram (the first is logged at once).
REFUSED_LOG_PERIOD_S = 10.0

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
        self.peers: frozenset[int] | None = None  # wire ids we ack data from (None: any)
        self.max_frames = 1  # frames (and acked frames) one transmission may carry on this link
        self.name = ""  # for log lines: which link this driver serves (default: "modem <id>")
        self.refusals = RateLimitedLog(log, REFUSED_LOG_PERIOD_S)  # what it refused; the link flushes held lines
        self.clock: Callable[[], float] = time.time  # the link's (warped) clock: channel delays and outages

    def expect(self, name: str, peers: Collection[int] | None, max_frames: int,
               clock: Callable[[], float] | None = None) -> None:
        """What the link allows (call before ``startup``): the wire ids of its peers (None: any) and the most
        frames a slot carries. Goby's driver acks and passes on anything; ours refuses the rest at the edge.
        ``clock`` is the link's clock (warped seconds since the epoch)."""
        self.name = name
        self.peers = None if peers is None else frozenset(peers)
        self.max_frames = max(1, max_frames)
        if clock is not None:
            self.clock = clock

    def next_delivery(self) -> float | None:
        """When a received transmission held back (a simulated channel's delay) is next due, on ``clock``."""
        return None

    def deliver_due(self) -> None:
        """Hand on (``signal_receive``) the held-back transmissions that are due; the link calls it at
        ``next_delivery``. A driver that holds nothing back has nothing to do."""
        return None

    @abc.abstractmethod
    def startup(self, cfg: DriverConfig) -> None:
        """Open the link (``cfg.modem_id`` is the id within the subnet); raises ``ModemDriverError``."""

    @abc.abstractmethod
    def shutdown(self) -> None:
        """Close the link; idempotent."""

    @abc.abstractmethod
    def fileno(self) -> int:
        """A descriptor that is readable while ``do_work`` has something to read (valid between ``startup`` and
        ``shutdown``); the link's thread waits on it."""

    @abc.abstractmethod
    def do_work(self) -> None:
        """Handle what arrived (emits ``signal_receive``); called by the link when ``fileno()`` is readable."""

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
        self.malformed = 0  # datagrams that are not a ModemTransmission
        self.refused: Counter[str] = Counter()  # datagrams dropped at the edge, by cause (malformed included)
        self.channel: Channel[ModemTransmission] | None = None  # the channel_model extension, if any

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
        """Subclasses call this first: a bad ``channel_model`` raises ``ModemConfigError`` before anything opens."""
        model = channel_model_of(cfg)
        self.cfg = cfg
        self.modem_id = cfg.modem_id
        self.name = self.name or f"modem {cfg.modem_id}"
        self.channel = None if model is None else Channel(model, cfg.modem_id)
        if model is not None:
            log.warning("%s: SIMULATED channel on receive (channel_model): %s", self.name, describe(model))

    def handle_initiate_transmission(self, msg: ModemTransmission) -> None:
        msg.src = self.modem_id
        msg.frame_start = self._next_frame
        if not msg.HasField("max_frame_bytes"):
            msg.max_frame_bytes = self._max_frame_size(msg)
        self.signal_data_request.emit(msg)
        self._next_frame += max(1, len(msg.frame))
        if self._next_frame + self.max_frames > MAX_FRAME_NUMBER:
            self._next_frame = 0  # after 2^31 frames: our frame numbers stay in the range peers accept
        if msg.frame and msg.frame[0]:
            self._transmit(msg)

    def do_work(self) -> None:
        for datagram in self._receive_all():
            try:
                self._handle_datagram(datagram)
            except Exception as exc:  # noqa: BLE001 - what a datagram makes us raise must not end the link
                self.refuse("failed", "handling it failed (%s: %s)", type(exc).__name__, exc, size=len(datagram))
                log.debug("%s: the datagram that failed: %r", self.name, datagram[:256], exc_info=True)
        self.refusals.flush()

    def next_delivery(self) -> float | None:
        return None if self.channel is None else self.channel.next_delivery()

    def deliver_due(self) -> None:
        if self.channel is None:
            return
        for msg in self.channel.due(self.clock()):
            try:
                self._accept(msg)
            except Exception as exc:  # noqa: BLE001 - what a datagram makes us raise must not end the link
                self.refuse("failed", "handling it failed (%s: %s)", type(exc).__name__, exc, size=msg.ByteSize())

    def refuse(self, cause: str, why: str, *args: object, size: int) -> None:
        """Count a dropped datagram under ``cause`` and log it (rate-limited per cause)."""
        self.refused[cause] += 1
        self.refusals.error(cause, "%s: dropping a datagram (%d bytes): " + why + " [%s: %d dropped so far]",
                            self.name, size, *args, cause, self.refused[cause])

    # ------------------------------------------------------------------------------------------ logic
    def _transmit(self, msg: ModemTransmission) -> None:
        self._send(msg.SerializeToString())
        self.sent += 1
        self.signal_transmit_result.emit(msg)

    def out_of_range(self, msg: ModemTransmission) -> tuple[str, str] | None:
        """The field of ``msg`` that is out of range and why, or None."""
        if msg.src < 0:
            return "src", f"src {msg.src} is not a modem id"
        if msg.dest < -1:
            return "dest", f"dest {msg.dest} is not a modem id"
        if len(msg.frame) > self.max_frames:
            return "frame", f"{len(msg.frame)} frames, more than the {self.max_frames} a slot of this link carries"
        if len(msg.acked_frame) > self.max_frames:
            return "acked_frame", (f"{len(msg.acked_frame)} acked frames, more than the {self.max_frames} a slot of "
                                   "this link carries")
        if msg.frame_start + max(0, len(msg.frame) - 1) > MAX_FRAME_NUMBER:
            return "frame_start", (f"frame_start {msg.frame_start} is out of range (frame numbers end at "
                                   f"{MAX_FRAME_NUMBER})")
        return None

    def _handle_datagram(self, datagram: bytes) -> None:
        msg = ModemTransmission()
        try:
            msg.ParseFromString(datagram)
        except DecodeError as exc:
            self.malformed += 1
            self.refuse("malformed", "not a ModemTransmission: %s", exc, size=len(datagram))
            return
        if msg.src == self.modem_id:
            return  # our own multicast loopback
        bad = self.out_of_range(msg)
        if bad is not None:
            self.refuse(f"{bad[0]} out of range", "from modem %d: %s", msg.src, bad[1], size=len(datagram))
            return
        if self.channel is not None:
            fate, _ = self.channel.admit(msg, self.clock())
            if fate != "deliver":
                if fate != "delay":
                    self._channel_drop(fate, msg)
                return
        self._accept(msg)

    def _channel_drop(self, fate: str, msg: ModemTransmission) -> None:
        assert self.channel is not None
        c = self.channel.counters
        why = {"lost": "lost (loss draw)", "outage": "lost in an outage window",
               "overflow": f"dropped: {self.channel.held} transmissions already held back"}[fate]
        kind = "ACK" if msg.type == ModemTransmission.ACK else "DATA" if msg.type == ModemTransmission.DATA else "other"
        self.refusals.log(logging.INFO, ("channel", fate), "%s: simulated channel: %s transmission from modem %d %s "
                          "[channel so far: %d received, %d lost, %d in outages, %d overflowed]", self.name, kind,
                          msg.src, why, c.received, c.lost, c.outage, c.overflow)

    def _accept(self, msg: ModemTransmission) -> None:
        """A well-formed transmission from another modem that crossed the channel: ack it if asked, emit it."""
        self.received += 1
        if (msg.type == ModemTransmission.DATA and msg.ack_requested and msg.dest == self.modem_id
                and (self.peers is None or msg.src in self.peers)):
            ack = ModemTransmission(src=self.modem_id, dest=msg.src, type=ModemTransmission.ACK)
            ack.acked_frame.extend(range(msg.frame_start, msg.frame_start + len(msg.frame)))
            self._transmit(ack)
        self.signal_receive.emit(msg)
