"""One intervehicle link (Goby3's ``ModemDriverThread`` logic, ``intervehicle/driver_thread.cpp``), free of sockets.

It owns the link's DynamicBuffer, its TDMA MAC and its modem driver, and talks to the rest of the vehicle through
:class:`LinkOutputs` callbacks (the broker's intervehicle thread publishes them on interprocess). Every method runs
on one thread (in the broker, its intervehicle thread). Goby runs the link in a 10 Hz loop; here the work is split
so that a thread waits for it instead: ``receive()`` when the driver's ``fileno()`` is readable, ``run_due()`` at
``next_deadline()`` (the next slot start, ttl expiry or delivery of a transmission a simulated channel held back),
``flush_logs()`` once held-back log lines are due.
``loop()`` does all of it, for a link driven by hand (tests, benchmarks).

- ``buffer_message(stm)``: a local publication; buffered for every remote subscriber of its (group, DCCL id) in this
  subnet, else expired at once with EXPIRED_NO_SUBSCRIBERS.
- ``forward_subscription(sub)``: a local subscription; queued (value +inf, acked, retried) to each publisher id in
  this subnet.
- ``accept_subscription(sub)``: a remote subscription; creates/updates the sub-buffer for that subscriber once a
  local publisher is known too (configs merged, DynamicBuffer rules).
- The MAC starts our slots; ``_data_request`` fills one frame per slot (first winner fixes the destination, plain
  concatenation of DCCL messages, never above ``max_frame_bytes``); acks erase values, unacked ones are resent after
  ``ack_timeout``; received frames are split into DCCL packets (an unknown id drops the rest of the frame, logged).
- Peers: the modems with a slot in the MAC plan. Data and acks from any other modem are dropped; the driver is
  told them (and the most frames a slot carries) so it acks only peers and refuses oversized transmissions.
  Drops caused by what arrives are counted and logged at a rate-limited cadence (``util.ratelimit``).
- ``take_over(old)``: a restarted link (new thread, driver and MAC) keeps the queues, subscriptions and loaded
  types of the one that failed.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field

from gateway.goby.acomms.buffer import BufferNoDataError, DynamicBuffer, Value
from gateway.goby.acomms.driver import ModemDriver
from gateway.goby.acomms.mac import ALLOWED_SKEW_S, MacManager
from gateway.goby.acomms.protobuf.buffer_pb2 import DynamicBufferConfig
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission
from gateway.goby.dccl import Codec, DcclError, UnknownIdError
from gateway.goby.dccl.ids import decode_id
from gateway.goby.intervehicle import groups
from gateway.goby.intervehicle.protobuf.intervehicle_pb2 import (
    AckData,
    AckMessagePair,
    DCCLForwardedData,
    ExpireData,
    ExpireMessagePair,
    PortalConfig,
    Subscription,
    SubscriptionReport,
)
from gateway.goby.intervehicle.protobuf.intervehicle_transporter_config_pb2 import TransporterConfig
from gateway.goby.intervehicle.protobuf.serializer_transporter_pb2 import SerializerTransporterMessage
from gateway.goby.intervehicle.serialization import message_class
from gateway.goby.portal.marshalling import Scheme
from util.ratelimit import RateLimitedLog

log = logging.getLogger(__name__)

#: Seconds between two log lines of the same kind of dropped frame (the first is logged at once).
DROP_LOG_PERIOD_S = 10.0
#: Full modem ids travel as int32 (``header.src``); an id past this cannot be a modem of ours.
MAX_MODEM_ID = 2**31 - 1

LinkConfig = PortalConfig.LinkConfig
BufferId = str


def buffer_id(dccl_id: int, group_numeric: int) -> BufferId:
    """Goby's sub-buffer id ``/group:<N>/id:<dccl id>/``."""
    return f"/group:{group_numeric}/id:{dccl_id}/"


SUBSCRIPTION_BUFFER_ID = buffer_id(groups.SUBSCRIPTION_DCCL_ID, groups.API_VERSION)


@dataclass(eq=False)
class Buffered:
    """What a sub-buffer holds: the publication; its size is that of its DCCL bytes."""

    stm: SerializerTransporterMessage

    def __len__(self) -> int:
        return len(self.stm.data)


@dataclass
class LinkOutputs:
    """Where the link's results go (each defaults to nothing; what a callback returns is ignored)."""

    data_in: Callable[[DCCLForwardedData], object] = lambda _m: None
    ack_in: Callable[[AckMessagePair], object] = lambda _m: None
    expire_in: Callable[[ExpireMessagePair], object] = lambda _m: None
    subscription_rx: Callable[[Subscription], object] = lambda _m: None
    subscription_report: Callable[[SubscriptionReport], object] = lambda _m: None
    transmitted: Callable[[ModemTransmission], object] = lambda _m: None  # a data transmission we sent
    initiated: Callable[[ModemTransmission], object] = lambda _m: None  # the MAC started one of our slots


@dataclass
class LinkCounters:
    """What happened on the link (for logs, tests and the bench)."""

    frames_sent: int = 0
    bytes_sent: int = 0  # DCCL bytes in sent data frames
    packets_received: int = 0
    acks: int = 0
    expired_no_subscribers: int = 0
    expired_ttl: int = 0
    expired_overflow: int = 0
    dropped_frames: int = 0  # received frames (or their rest) dropped: unknown id, bad bytes, unknown modem
    dropped_acks: int = 0  # acks from a modem that is not a peer
    unexpected_acks: int = 0
    max_frame_seen: int = 0  # largest data frame we sent
    slot_starts: list[float] = field(default_factory=list)  # warped start time of each of our transmissions


class Link:
    """The logic of one link; ``now`` is the warped clock in seconds since the epoch."""

    def __init__(self, cfg: LinkConfig, driver: ModemDriver, now: Callable[[], float],
                 outputs: LinkOutputs | None = None, codec: Codec | None = None,
                 allowed_skew_s: float = ALLOWED_SKEW_S) -> None:
        self.cfg = cfg
        self.driver = driver
        self.now = now
        self.out = outputs if outputs is not None else LinkOutputs()
        self.codec = codec if codec is not None else Codec()
        self.codec.load(Subscription)
        self.modem_id = cfg.modem_id
        self.broadcast_id = cfg.modem_id & cfg.subnet_mask
        self.name = f"link {cfg.modem_id}"
        self.counters = LinkCounters()
        self.buffer = DynamicBuffer()
        self._publisher_cfgs: dict[BufferId, list[DynamicBufferConfig]] = {}
        self._subscriber_cfgs: dict[tuple[int, BufferId], list[TransporterConfig]] = {}
        self._subscriptions: dict[tuple[int, BufferId], Subscription] = {}
        self._forwarded: dict[tuple[int, int, bytes, tuple[int, ...]], int] = {}
        self._pending_ack: dict[int, list[tuple[int, Hashable, Value]]] = {}  # ids as the buffer keeps them
        self._slot_srcs = {slot.src for slot in cfg.mac.slot}
        self.drops = RateLimitedLog(log, DROP_LOG_PERIOD_S)
        peers = {self.within_subnet(src) for src in self._slot_srcs if self.in_subnet(src) and src != self.modem_id}
        driver.expect(self.name, sorted(peers) if self._slot_srcs else None,
                      max((slot.max_num_frames for slot in cfg.mac.slot), default=1), clock=now)
        mac_cfg = type(cfg.mac)()
        mac_cfg.CopyFrom(cfg.mac)
        mac_cfg.modem_id = cfg.modem_id
        self.mac = MacManager(mac_cfg, self._initiate, allowed_skew_s=allowed_skew_s)
        driver.signal_data_request.connect(self._data_request)
        driver.signal_receive.connect(self._receive)
        self._started = False

    # ------------------------------------------------------------------------------------------- ids
    def in_subnet(self, full_id: int) -> bool:
        return (full_id & self.cfg.subnet_mask) == self.broadcast_id

    def within_subnet(self, full_id: int) -> int:
        return full_id - self.broadcast_id

    def full_id(self, wire_id: int) -> int:
        return wire_id + self.broadcast_id

    def is_peer(self, full_id: int) -> bool:
        """A modem we take data and acks from: one with a slot in the MAC plan (any in the subnet if none)."""
        if self._slot_srcs:
            return full_id in self._slot_srcs
        return 0 <= full_id <= MAX_MODEM_ID and self.in_subnet(full_id)

    def take_over(self, old: Link) -> None:
        """Carry on from ``old`` (a failed link): its queues, subscriptions, loaded types and counters. Values that
        awaited an ack are sent again after ``ack_timeout`` (the new driver numbers frames afresh)."""
        self.codec = old.codec
        self.buffer = old.buffer
        self.counters = old.counters
        self._publisher_cfgs = old._publisher_cfgs
        self._subscriber_cfgs = old._subscriber_cfgs
        self._subscriptions = old._subscriptions
        self._forwarded = old._forwarded

    # ------------------------------------------------------------------------------------- lifecycle
    def start(self) -> None:
        driver_cfg = type(self.cfg.driver)()
        driver_cfg.CopyFrom(self.cfg.driver)
        driver_cfg.modem_id = self.within_subnet(self.modem_id)
        self.driver.startup(driver_cfg)
        self._started = True

    def stop(self) -> None:
        if self._started:
            self._started = False
            self.drops.flush(final=True)
            self.driver.shutdown()

    def loop(self) -> None:
        """Expire, let the driver read (and deliver what a simulated channel held back), let the MAC start a slot,
        flush due log lines (Goby's 10 Hz loop)."""
        now = self.now()
        self._expire_due(now)
        self.driver.do_work()
        self.driver.deliver_due()
        self.mac.do_work(now)
        self.flush_logs()

    def receive(self) -> None:
        """Handle what the driver has (call when its ``fileno()`` is readable)."""
        self.driver.do_work()

    def run_due(self) -> None:
        """The timed part of Goby's loop: expire values past their ttl, deliver the received transmissions a
        simulated channel held back until now, start the slot whose time has come."""
        now = self.now()
        self._expire_due(now)
        self.driver.deliver_due()
        self.mac.do_work(now)

    def next_deadline(self) -> float | None:
        """When ``run_due`` next has work (warped s since the epoch): the next slot start, ttl expiry or delayed
        delivery."""
        times = [t for t in (self.mac.next_slot_time(self.now()), self.buffer.next_expiry(),
                             self.driver.next_delivery()) if t is not None]
        return min(times, default=None)

    @property
    def held_log_lines(self) -> int:
        """Log lines held back so far (rate-limited drops and refusals); a rise means a ``flush_logs`` is due later."""
        return self.drops.held_back + self.driver.refusals.held_back

    def flush_logs(self) -> None:
        """Write the summary lines of held-back drops and refusals whose quiet period is over."""
        self.drops.flush()
        self.driver.refusals.flush()

    def _expire_due(self, now: float) -> None:
        for dest, _bid, value in self.buffer.expire(now):
            self.counters.expired_ttl += 1
            self._expire(value, dest, ExpireData.EXPIRED_TIME_TO_LIVE_EXCEEDED, now)

    def _initiate(self, slot: ModemTransmission) -> None:
        self.counters.slot_starts.append(slot.time / 1e6)
        self.out.initiated(slot)
        self.driver.handle_initiate_transmission(slot)

    # ------------------------------------------------------------------------------------- publishing
    def _load(self, type_name: str, metadata: object | None) -> int | None:
        """Load a DCCL type (from the default pool or the metadata); its DCCL id, or None (logged)."""
        cls = message_class(type_name, metadata)  # type: ignore[arg-type]
        if cls is None:
            log.error("%s: unknown type %s and no usable metadata; cannot use it", self.name, type_name)
            return None
        try:
            return self.codec.load(cls).dccl_id
        except DcclError as exc:
            log.error("%s: %s is not a usable DCCL message: %s", self.name, type_name, exc)
            return None

    def buffer_message(self, stm: SerializerTransporterMessage) -> None:
        """A local publication from ``modem_data_out`` (Goby's ``_buffer_message``)."""
        key = stm.key
        if key.marshalling_scheme != Scheme.DCCL:
            log.error("%s: publication of %s on %s is not DCCL (scheme %d); dropped", self.name, key.type,
                      key.group, key.marshalling_scheme)
            return
        dccl_id = self._load(key.type, key.metadata if key.HasField("metadata") else None)
        if dccl_id is None:
            return
        bid = buffer_id(dccl_id, key.group_numeric)
        now = self.now()
        pub_cfg = key.cfg.intervehicle.buffer
        known = self._publisher_cfgs.setdefault(bid, [])
        if all(c.SerializeToString() != pub_cfg.SerializeToString() for c in known):
            copy = DynamicBufferConfig()
            copy.CopyFrom(pub_cfg)
            known.append(copy)
            for dest, sub_bid in list(self._subscriber_cfgs):
                if sub_bid == bid:
                    self._try_create_or_update_buffer(dest, bid)
        dests = [d for d in self.buffer.destinations(bid) if self.in_subnet(d)]
        if not dests:
            self.counters.expired_no_subscribers += 1
            self._expire_stm(stm, self.modem_id, ExpireData.EXPIRED_NO_SUBSCRIBERS, 0)
            return
        for dest in dests:
            for dropped in self.buffer.push(dest, bid, Buffered(stm), now):
                self.counters.expired_overflow += 1
                self._expire(dropped, dest, ExpireData.EXPIRED_BUFFER_OVERFLOW, now)

    def forward_subscription(self, sub: Subscription) -> None:
        """A local subscription from ``modem_subscription_forward_tx`` (Goby's ``_forward_subscription``).

        One already forwarded by this link (same type, group, config and action) is not sent again: applications
        resend theirs when a link announces itself, and only a restarted link needs them.
        """
        if sub.HasField("metadata"):
            self._load(sub.metadata.protobuf_name, sub.metadata)
        key = (sub.dccl_id, sub.group, sub.intervehicle.SerializeToString(), tuple(sub.header.dest))
        if self._forwarded.get(key) == sub.action:
            return
        self._forwarded[key] = sub.action
        outgoing = Subscription()
        outgoing.CopyFrom(sub)
        outgoing.header.src = self.broadcast_id if sub.intervehicle.broadcast else self.modem_id
        outgoing.ClearField("metadata")
        try:
            data = self.codec.encode(outgoing)
        except DcclError as exc:
            log.error("%s: cannot encode the Subscription to id %d group %d: %s", self.name, sub.dccl_id,
                      sub.group, exc)
            return
        stm = SerializerTransporterMessage(data=data)
        stm.key.marshalling_scheme = Scheme.DCCL
        stm.key.type = Subscription.DESCRIPTOR.full_name
        stm.key.group = str(groups.subscription_forward)
        stm.key.group_numeric = groups.API_VERSION
        stm.key.serialize_time = sub.time
        now = self.now()
        for dest in sub.header.dest:
            if not self.in_subnet(dest):
                continue
            if not self.buffer.has(dest, SUBSCRIPTION_BUFFER_ID):
                cfg = DynamicBufferConfig()
                cfg.CopyFrom(self.cfg.subscription_buffer)
                if not cfg.HasField("ack_required"):
                    cfg.ack_required = True
                if not cfg.HasField("value_base"):
                    cfg.value_base = math.inf
                self.buffer.create(dest, SUBSCRIPTION_BUFFER_ID, [cfg], now)
            for dropped in self.buffer.push(dest, SUBSCRIPTION_BUFFER_ID, Buffered(stm), now):
                self.counters.expired_overflow += 1
                self._expire(dropped, dest, ExpireData.EXPIRED_BUFFER_OVERFLOW, now)

    def accept_subscription(self, sub: Subscription) -> None:
        """A remote subscription, received by this link or another of the vehicle (Goby's ``_accept_subscription``)."""
        dest = sub.header.src
        if not self.in_subnet(dest) or sub.api_version != groups.API_VERSION:
            return
        bid = buffer_id(sub.dccl_id, sub.group)
        configs = self._subscriber_cfgs.setdefault((dest, bid), [])
        wire = sub.intervehicle.SerializeToString()
        if sub.action == Subscription.SUBSCRIBE:
            if all(c.SerializeToString() != wire for c in configs):
                copy = TransporterConfig()
                copy.CopyFrom(sub.intervehicle)
                configs.append(copy)
                self._subscriptions[(dest, bid)] = sub
                log.info("%s: modem %d subscribed to DCCL id %d group %d", self.name, dest, sub.dccl_id, sub.group)
                self._try_create_or_update_buffer(dest, bid)
        else:
            configs[:] = [c for c in configs if c.SerializeToString() != wire]
            if not configs:
                del self._subscriber_cfgs[(dest, bid)]
                self._subscriptions.pop((dest, bid), None)
                self.buffer.remove(dest, bid)
        report = SubscriptionReport(link_modem_id=self.modem_id)
        report.subscription.extend(self._subscriptions.values())
        report.changed.CopyFrom(sub)
        self.out.subscription_report(report)

    def _try_create_or_update_buffer(self, dest: int, bid: BufferId) -> None:
        subs = self._subscriber_cfgs.get((dest, bid))
        pubs = self._publisher_cfgs.get(bid)
        if not subs or not pubs:
            return
        self.buffer.create(dest, bid, [c.buffer for c in subs] + list(pubs), self.now())

    # ------------------------------------------------------------------------------------------ frames
    def _data_request(self, msg: ModemTransmission) -> None:
        """Fill our transmission: one destination, DCCL messages concatenated up to max_frame_bytes."""
        for frame_number in [n for n in self._pending_ack if n >= msg.frame_start]:
            del self._pending_ack[frame_number]
        now = self.now()
        dest: int | None = None if msg.dest == -1 else self.full_id(msg.dest)
        ack_timeout = self.cfg.ack_timeout
        max_bytes = msg.max_frame_bytes
        ack_requested = False
        for i in range(max(1, msg.max_num_frames)):
            frame = bytearray()
            frame_number = msg.frame_start + i
            while len(frame) < max_bytes:
                # Goby reads the clock at each call: a sub-buffer that just supplied a value is then not "in
                # blackout" for the next one (blackout 0), so one sub-buffer can fill a frame.
                now = max(self.now(), now + 1e-6)
                try:
                    top = self.buffer.top(now, dest, max_bytes - len(frame), ack_timeout)
                except BufferNoDataError:
                    break
                dest = top.dest
                frame += top.value.data.stm.data
                if top.cfg.ack_required:
                    ack_requested = True
                    self._pending_ack.setdefault(frame_number, []).append((top.dest, top.buffer_id, top.value))
                else:
                    self.buffer.erase(top.dest, top.buffer_id, top.value)
            msg.frame.append(bytes(frame))
            if not frame:
                break
        msg.ack_requested = ack_requested
        if dest is not None:
            msg.dest = self.within_subnet(dest)
        msg.src = self.within_subnet(self.modem_id)
        if msg.frame and msg.frame[0]:
            self.counters.frames_sent += 1
            self.counters.bytes_sent += sum(len(f) for f in msg.frame)
            self.counters.max_frame_seen = max(self.counters.max_frame_seen, max(len(f) for f in msg.frame))
            self.out.transmitted(msg)

    def _receive(self, msg: ModemTransmission) -> None:
        """Every transmission the driver heard (Goby's ``_receive``)."""
        full_src = self.full_id(msg.src)
        full_dest = self.full_id(msg.dest)
        if msg.type == ModemTransmission.ACK:
            if full_dest != self.modem_id:
                return
            if not self.is_peer(full_src):
                self.counters.dropped_acks += 1
                self.drops.error("ack from unknown modem", "%s: dropping an ack from unknown modem %d (wire id %d): "
                                 "it has no slot in the MAC plan [%d so far]", self.name, full_src, msg.src,
                                 self.counters.dropped_acks)
                return
            self._handle_ack(msg, full_src)
            return
        if msg.type != ModemTransmission.DATA:
            return
        if full_dest not in (self.broadcast_id, self.modem_id):
            return
        if not self.is_peer(full_src):
            self.counters.dropped_frames += 1
            self.drops.error("unknown modem", "%s: dropping a frame from unknown modem %d (wire id %d): it has no "
                             "slot in the MAC plan [%d frames dropped so far]", self.name, full_src, msg.src,
                             self.counters.dropped_frames)
            return
        forwarded = DCCLForwardedData()
        forwarded.header.src = full_src
        forwarded.header.dest.append(full_dest)
        for frame in msg.frame:
            self._unpack(frame, full_src, forwarded)
        if forwarded.frame:
            self.counters.packets_received += len(forwarded.frame)
            self.out.data_in(forwarded)
        for packet in forwarded.frame:
            if packet.dccl_id == groups.SUBSCRIPTION_DCCL_ID:
                try:
                    sub = self.codec.decode(packet.data, Subscription)
                except DcclError as exc:
                    self.drops.error("bad subscription", "%s: bad Subscription from modem %d: %s", self.name,
                                     full_src, exc)
                    continue
                self.out.subscription_rx(sub)

    def _unpack(self, frame: bytes, full_src: int, out: DCCLForwardedData) -> None:
        """Split one frame into DCCL packets; on an unknown id or bad bytes the rest is dropped (logged)."""
        pos = 0
        while pos < len(frame):
            try:
                dccl_id = decode_id(frame, pos)[0]
                _, rest = self.codec.decode_prefix(frame[pos:])
            except UnknownIdError as exc:
                self._drop(frame, pos, full_src, "unknown id", f"DCCL id {exc.dccl_id} is not loaded here")
                return
            except DcclError as exc:
                self._drop(frame, pos, full_src, "cannot decode", f"cannot decode: {exc}")
                return
            end = len(frame) - len(rest)
            packet = out.frame.add()
            packet.dccl_id = dccl_id
            packet.data = frame[pos:end]
            pos = end

    def _drop(self, frame: bytes, pos: int, full_src: int, kind: str, why: str) -> None:
        self.counters.dropped_frames += 1
        self.drops.error(kind, "%s: frame from modem %d: %s; dropping the rest of the frame (%d of %d bytes, from "
                         "byte %d) [%d frames dropped so far]", self.name, full_src, why, len(frame) - pos,
                         len(frame), pos, self.counters.dropped_frames)

    def _handle_ack(self, msg: ModemTransmission, full_src: int) -> None:
        now = self.now()
        for frame_number in msg.acked_frame:
            entries = self._pending_ack.pop(frame_number, None)
            if entries is None:
                self.counters.unexpected_acks += 1
                self.drops.warning("unexpected ack", "%s: ack from modem %d for frame %d that we are not waiting "
                                   "for; ignored", self.name, full_src, frame_number)
                continue
            for dest, bid, value in entries:
                if not self.buffer.erase(dest, bid, value):
                    continue  # acked already, or expired meanwhile
                self.counters.acks += 1
                pair = AckMessagePair()
                pair.serializer.CopyFrom(value.data.stm)
                pair.data.header.src = full_src
                pair.data.header.dest.append(self.modem_id)
                pair.data.latency = int(round((now - value.push_time) * 1e6))
                self.out.ack_in(pair)

    # ------------------------------------------------------------------------------------------ expiry
    def _expire(self, value: Value, dest: int, reason: int, now: float) -> None:
        self._expire_stm(value.data.stm, dest, reason, int(round((now - value.push_time) * 1e6)))

    def _expire_stm(self, stm: SerializerTransporterMessage, dest: int, reason: int, latency_us: int) -> None:
        pair = ExpireMessagePair()
        pair.serializer.CopyFrom(stm)
        pair.data.header.src = dest
        pair.data.header.dest.append(self.modem_id)
        pair.data.latency = latency_us
        pair.data.reason = reason  # type: ignore[assignment]
        self.out.expire_in(pair)


__all__ = ["AckData", "Buffered", "Link", "LinkConfig", "LinkCounters", "LinkOutputs", "buffer_id"]
