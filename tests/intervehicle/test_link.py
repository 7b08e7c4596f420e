"""The link logic (Goby3's ModemDriverThread) on an in-process ether with a hand-driven warped clock: subscription
forwarding, frames within max_frame_bytes, one destination per transmission, acks, retries, expiry, bad frames."""

from __future__ import annotations

import logging

import pytest

from gateway.goby.acomms.ether import Ether, EtherDriver
from gateway.goby.acomms.protobuf.amac_config_pb2 import MAC_FIXED_DECENTRALIZED
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission
from gateway.goby.dccl import Codec
from gateway.goby.intervehicle import groups
from gateway.goby.intervehicle.link import Link, LinkConfig, LinkOutputs
from gateway.goby.intervehicle.protobuf.intervehicle_pb2 import ExpireData, Subscription
from gateway.goby.intervehicle.protobuf.transporter_config_pb2 import TransporterConfig
from gateway.goby.intervehicle.serialization import metadata_for, serialize_publication
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

T0 = 1_700_000_000.0  # a fixed warped "now"


class Clock:
    def __init__(self) -> None:
        self.t = T0

    def __call__(self) -> float:
        return self.t


class Node:
    """A link plus what it reported."""

    def __init__(self, cfg: LinkConfig, ether: Ether, clock: Clock) -> None:
        self.data: list = []
        self.acks: list = []
        self.expires: list = []
        self.sent: list[ModemTransmission] = []
        outputs = LinkOutputs(data_in=self.data.append, ack_in=self.acks.append, expire_in=self.expires.append,
                              subscription_rx=lambda s: self.link.accept_subscription(s),
                              transmitted=lambda m: self.sent.append(ModemTransmission.FromString(
                                  m.SerializeToString())))
        self.link = Link(cfg, EtherDriver(ether), clock, outputs)
        self.link.start()


def link_cfg(modem_id: int, slots: list[tuple[int, float, int]], mask: int = 0xFF00) -> LinkConfig:
    cfg = LinkConfig(modem_id=modem_id, subnet_mask=mask)
    cfg.driver.driver_name = "ether"
    cfg.mac.type = MAC_FIXED_DECENTRALIZED
    for src, seconds, max_bytes in slots:
        cfg.mac.slot.add(src=src, slot_seconds=seconds, max_frame_bytes=max_bytes)
    return cfg


def nav(x: float) -> NavigationReport:
    return NavigationReport(vehicle=2, time=T0, x=x, y=0, z=0, speed_over_ground=1, heading=0,
                            type=NavigationReport.USV)


SAT = [(1, 5.0, 64), (2, 5.0, 64)]


def run(clock: Clock, nodes: list[Node], seconds: float, step: float = 0.1) -> None:
    end = clock.t + seconds
    while clock.t < end:
        clock.t += step
        for node in nodes:
            node.link.loop()


def subscribe(node: Node, codec: Codec, msg_type: type, group: int, publisher: int,
              tcfg: TransporterConfig | None = None) -> Subscription:
    codec.load(msg_type)
    sub = Subscription(api_version=1, action=Subscription.SUBSCRIBE, dccl_id=codec.id(msg_type), group=group,
                       time=int(node.link.now() * 1e6))
    sub.header.src = 0
    sub.header.dest.append(publisher)
    sub.metadata.CopyFrom(metadata_for(msg_type))
    if tcfg is not None:
        sub.intervehicle.CopyFrom(tcfg.intervehicle)
    node.link.forward_subscription(sub)
    return sub


def publish(node: Node, codec: Codec, msg, group: int, tcfg: TransporterConfig | None = None) -> None:
    codec.load(type(msg))
    stm = serialize_publication(codec.encode(msg), msg, f"g;{group}", group, int(node.link.now() * 1e6),
                                tcfg or TransporterConfig())
    node.link.buffer_message(stm)


@pytest.fixture
def sat() -> tuple[Clock, Node, Node, Codec]:
    clock, ether = Clock(), Ether()
    topside, usv = Node(link_cfg(1, SAT), ether, clock), Node(link_cfg(2, SAT), ether, clock)
    yield clock, topside, usv, Codec()
    topside.link.stop()
    usv.link.stop()


def test_no_subscriber_expires_at_once(sat) -> None:
    clock, topside, usv, codec = sat
    publish(topside, codec, USVCommand(time=T0, desired_state=USVCommand.WAYPOINTS), 0)
    assert [e.data.reason for e in topside.expires] == [ExpireData.EXPIRED_NO_SUBSCRIBERS]
    assert topside.link.counters.expired_no_subscribers == 1


def test_subscription_then_acked_command(sat) -> None:
    clock, topside, usv, codec = sat
    subscribe(usv, codec, USVCommand, 0, publisher=1)
    run(clock, [topside, usv], 12)  # the USV's slot carries the Subscription; topside acks it
    assert [a.serializer.key.type for a in usv.acks] == [Subscription.DESCRIPTOR.full_name]
    tcfg = TransporterConfig()
    tcfg.intervehicle.buffer.ack_required = True
    publish(topside, codec, USVCommand(time=T0, desired_state=USVCommand.POLYGON, polygon_sides=5,
                                       polygon_radius=200), 0, tcfg)
    run(clock, [topside, usv], 12)
    got = [p for d in usv.data for p in d.frame if p.dccl_id == 126]
    assert len(got) == 1
    assert codec.decode(got[0].data).polygon_sides == 5
    assert len(topside.acks) == 1 and topside.acks[0].data.header.src == 2
    assert 0 < topside.acks[0].data.latency <= 10_100_000  # at most one satellite cycle (warped µs)
    assert topside.link.buffer.empty()


def test_frames_never_exceed_max_frame_bytes_and_one_destination(sat) -> None:
    clock, topside, usv, codec = sat
    nav_cfg = TransporterConfig()
    nav_cfg.intervehicle.buffer.max_queue = 100
    nav_cfg.intervehicle.buffer.newest_first = False
    subscribe(topside, codec, NavigationReport, 1, publisher=2, tcfg=nav_cfg)
    run(clock, [topside, usv], 12)
    for i in range(30):
        publish(usv, codec, nav(float(i)), 1)
    run(clock, [topside, usv], 30)
    data_frames = [m for m in usv.sent if m.frame and m.frame[0] and m.type == ModemTransmission.DATA]
    assert data_frames
    assert max(len(f) for m in data_frames for f in m.frame) <= 64
    assert all(m.dest == 1 for m in data_frames)
    received = [codec.decode(p.data).x for d in topside.data for p in d.frame if p.dccl_id == 124]
    assert received[:4] == [0.0, 1.0, 2.0, 3.0]  # FIFO, 4 x 13 B per 64 B frame
    assert len(received) == 4 * len(data_frames)


def test_unacked_message_is_retried_then_expires_once(sat) -> None:
    clock, topside, usv, codec = sat
    subscribe(usv, codec, USVCommand, 0, publisher=1)
    run(clock, [topside, usv], 12)
    usv.link.stop()  # the USV goes silent: no more acks
    tcfg = TransporterConfig()
    tcfg.intervehicle.buffer.ack_required = True
    tcfg.intervehicle.buffer.ttl = 25
    publish(topside, codec, USVCommand(time=T0, desired_state=USVCommand.WAYPOINTS), 0, tcfg)
    run(clock, [topside], 40)
    sends = [m for m in topside.sent if m.frame and m.frame[0]]
    assert len(sends) >= 2  # retried in later slots after ack_timeout
    reasons = [e.data.reason for e in topside.expires]
    assert reasons == [ExpireData.EXPIRED_TIME_TO_LIVE_EXCEEDED]


def test_max_queue_one_newest_first_keeps_the_latest(sat) -> None:
    clock, topside, usv, codec = sat
    nav_cfg = TransporterConfig()
    nav_cfg.intervehicle.buffer.max_queue = 1
    subscribe(topside, codec, NavigationReport, 1, publisher=2, tcfg=nav_cfg)
    run(clock, [topside, usv], 12)
    for i in range(5):
        publish(usv, codec, nav(float(i)), 1)
    assert usv.link.counters.expired_overflow == 4
    run(clock, [topside, usv], 12)
    received = [codec.decode(p.data).x for d in topside.data for p in d.frame if p.dccl_id == 124]
    assert received == [4.0]


def test_bad_frames_are_dropped_with_one_line_and_the_link_keeps_running(sat, caplog) -> None:
    clock, topside, usv, codec = sat
    caplog.set_level(logging.ERROR)
    ether = topside.link.driver.ether
    ether.send(b"\xff\xff garbage")
    bad = ModemTransmission(src=2, dest=1, type=ModemTransmission.DATA, ack_requested=False)
    bad.frame.append(bytes([0x80 | 0x7F, 0x50, 1, 2, 3]))  # a two-byte DCCL id nobody loaded
    ether.send(bad.SerializeToString())
    truncated = ModemTransmission(src=2, dest=1, type=ModemTransmission.DATA, ack_requested=False)
    truncated.frame.append(b"\x06\x00\x00")  # the start of a Subscription (id 3), cut short
    ether.send(truncated.SerializeToString())
    stranger = ModemTransmission(src=9, dest=1, type=ModemTransmission.DATA, ack_requested=False)
    stranger.frame.append(b"\x06\x00")
    ether.send(stranger.SerializeToString())
    run(clock, [topside], 0.2)
    text = caplog.text
    assert "not a ModemTransmission" in text
    assert "is not loaded here" in text
    assert "unknown modem 9" in text
    assert "frame from modem 2: cannot decode" in text
    assert topside.link.counters.dropped_frames == 3
    subscribe(usv, codec, USVCommand, 0, publisher=1)
    run(clock, [topside, usv], 12)
    assert usv.acks  # still working


def test_subscription_wire_bytes_match_goby_worked_example() -> None:
    codec = Codec()
    codec.load(Subscription)
    sub = Subscription(api_version=1, action=Subscription.SUBSCRIBE, dccl_id=124, group=1)
    sub.header.src = 256
    sub.header.dest.append(258)
    buf = sub.intervehicle.buffer
    buf.ack_required, buf.max_queue, buf.newest_first = False, 1, True
    sub.intervehicle.broadcast = True
    assert codec.encode(sub).hex() == "0600000111088" "01f00000010060001080000" "0001"
    assert groups.SUBSCRIPTION_DCCL_ID == codec.id(Subscription)
