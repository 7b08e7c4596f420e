"""The simulated channel (our ``channel_model`` extension of the driver block) on real links: goby-broker processes
over UDP multicast on loopback, each node's channel losing, delaying and blacking out what it receives.

Under loss and delay every command published with ack required is acked or reported expired to its publisher,
once (sent = acked + expired); a seed gives the same drop pattern; an outage window expires what was sent into it;
bad settings are errors that name the field."""

from __future__ import annotations

import select
import socket
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pytest
from google.protobuf import text_format

from gateway.goby.acomms.channel import Channel, ChannelModel, check_channel_model, describe
from gateway.goby.acomms.errors import ModemConfigError
from gateway.goby.acomms.ether import Ether, EtherDriver
from gateway.goby.acomms.protobuf.channel_model_pb2 import channel_model
from gateway.goby.acomms.protobuf.driver_base_pb2 import DRIVER_UDP_MULTICAST, DriverConfig
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission
from gateway.goby.acomms.protobuf.udp_multicast_driver_pb2 import config as udp_config
from gateway.goby.acomms.udp_multicast import UDPMulticastDriver, random_multicast
from gateway.goby.intervehicle import ExpireData, Publisher, Subscriber, TransporterConfig
from gateway.goby.intervehicle.testing import IntervehicleClient, LoopbackLink, link_brokers
from gateway.goby.portal import Group
from gateway.goby.portal.testing import poll_all
from gateway.goby.portal.timeutil import SystemClock
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from tests.markers import needs_loopback_multicast
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

usv_command = Group("usv_command", 0)
EXTENSION = "[goby_moos_py.acomms.protobuf.channel_model]"


def with_channel(block: str, model: str) -> str:
    """A ``link {}`` block of ``LoopbackLink`` with ``model`` (text format) as its driver's channel_model."""
    head, sep, tail = block.partition("} } mac {")
    assert sep, block
    return f"{head}}} {EXTENSION} {{ {model} }} }} mac {{{tail}"


class CommandLink:
    """Topside (modem 1) publishes USVCommands with ack required to the USV (modem 2); outcomes by radius."""

    def __init__(self, topside: IntervehicleClient, usv: IntervehicleClient) -> None:
        self.topside, self.usv = topside, usv
        self.received: list[int] = []
        self.acks: list[tuple[int, int]] = []  # (radius, latency µs)
        self.expires: list[tuple[int, int]] = []  # (radius, reason)
        self.sent: list[int] = []

    def subscribe(self, timeout_s: float) -> bool:
        cfg = TransporterConfig()
        cfg.intervehicle.publisher_id.append(1)
        cfg.intervehicle.buffer.ack_required = True
        cfg.intervehicle.buffer.max_queue = 100
        subscribed: list[int] = []
        self.usv.intervehicle().subscribe(usv_command, USVCommand, lambda m: self.received.append(m.polygon_radius),
                                          Subscriber(cfg=cfg, on_subscribed=lambda s, a: subscribed.append(1)))
        return poll_all([self.topside, self.usv], lambda: subscribed, timeout_s)

    def publish(self, radius: int, ttl: float) -> None:
        cfg = TransporterConfig()
        cfg.intervehicle.buffer.ttl = ttl
        cfg.intervehicle.buffer.ack_required = True
        cfg.intervehicle.buffer.max_queue = 100
        publisher = Publisher(cfg=cfg, on_ack=lambda m, a: self.acks.append((m.polygon_radius, a.latency)),
                              on_expire=lambda m, e: self.expires.append((m.polygon_radius, e.reason)))
        command = USVCommand(time=time.time(), desired_state=USVCommand.POLYGON, polygon_sides=4,
                             polygon_radius=radius)
        self.topside.intervehicle().publish(usv_command, command, publisher)
        self.sent.append(radius)

    def settled(self) -> bool:
        return len(self.acks) + len(self.expires) >= len(self.sent)

    def poll(self, seconds: float) -> None:
        poll_all([self.topside, self.usv], lambda: False, seconds)


# -- 1. loss and delay: every command acked or reported expired ------------------------------------------------


@needs_loopback_multicast
def test_lossy_delayed_link_acks_or_expires_every_command(tmp_path: Path) -> None:
    warp, n = 4, 24
    sat = LoopbackLink([(1, 1, 32), (2, 1, 32)])  # 32 B frames: three or four commands per frame
    model = "loss: 0.2 delay_min: 0.2 delay_max: 0.6 seed: 25"
    links = {"topside": [with_channel(sat.block(1), model)], "usv": [with_channel(sat.block(2), model)]}
    with link_brokers(tmp_path, links, "lossy", warp=warp) as brokers:
        topside = IntervehicleClient(brokers["topside"].interprocess_config(), "topside_app")
        usv = IntervehicleClient(brokers["usv"].interprocess_config(), "usv_app")
        try:
            assert topside.wait_subscribed() and usv.wait_subscribed()
            link = CommandLink(topside, usv)
            assert link.subscribe(15), brokers["usv"].stderr_text()
            for i in range(n):  # spread over ~12 topside slots (1 s real each side... 0.5 s real per cycle)
                link.publish(100 + 10 * i, ttl=12)
                link.poll(0.12)
            assert poll_all([topside, usv], link.settled, 12), (link.sent, link.acks, link.expires)
            link.poll(1.0)  # and nothing settles twice
        finally:
            topside.close()
            usv.close()
        texts = {name: broker.stderr_text() for name, broker in brokers.items()}
    acked = [r for r, _ in link.acks]
    expired = [r for r, _ in link.expires]
    assert len(link.sent) == n == len(acked) + len(expired), (acked, expired)
    assert sorted(acked + expired) == sorted(link.sent)  # each command settled exactly once
    assert set(expired) <= {r for r in link.sent if r not in acked}
    assert all(reason == ExpireData.EXPIRED_TIME_TO_LIVE_EXCEEDED for _, reason in link.expires)
    assert len(acked) >= n // 2, (acked, expired)  # retries within the ttl carry most through 20 % loss each way
    assert set(acked) <= set(link.received)  # an acked command reached the USV's application
    # The data frame and its ack each cross a channel that delays by 0.2-0.6 s (warped): latency >= 0.4 s.
    assert min(latency for _, latency in link.acks) >= 400_000, link.acks
    for name, text in texts.items():
        assert "SIMULATED channel on receive (channel_model): loss 20%, delay 0.2-0.6 s, seed 25" in text, text
        assert "simulated channel:" in text and "lost (loss draw)" in text, (name, text)  # drops logged (rate-limited)
        assert "dropping a datagram" not in text, text  # nothing counted as bad input


# -- 2. a seed gives the same drop pattern ---------------------------------------------------------------------


def driver_cfg(group: str, port: int, modem_id: int, model: str | None) -> DriverConfig:
    cfg = DriverConfig(modem_id=modem_id, driver_type=DRIVER_UDP_MULTICAST)
    mc = cfg.Extensions[udp_config]
    mc.listen_address, mc.multicast_address, mc.multicast_port = "127.0.0.1", group, port
    if model is not None:
        text_format.Parse(model, cfg.Extensions[channel_model])
    return cfg


def heard_over_multicast(model: str, count: int = 200) -> tuple[list[int], UDPMulticastDriver]:
    """Modem 1 sends ``count`` DATA transmissions (and one garbage datagram) over real multicast to modem 2, whose
    channel is ``model``; the frame numbers modem 2 heard, and its driver."""
    group, port = random_multicast()
    rx, tx = UDPMulticastDriver(), UDPMulticastDriver()
    heard: list[int] = []
    rx.signal_receive.connect(lambda m: heard.append(m.frame_start))
    rx.startup(driver_cfg(group, port, 2, model))
    tx.startup(driver_cfg(group, port, 1, None))
    try:
        garbage = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        garbage.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
        garbage.sendto(b"\xff\xff not a transmission", (group, port))
        garbage.close()
        def fill(msg: ModemTransmission) -> None:
            msg.dest, msg.type = 2, ModemTransmission.DATA
            msg.frame.append(b"x")

        tx.signal_data_request.connect(fill)
        for _ in range(count):  # frame numbers 0, 1, 2, ...
            tx.handle_initiate_transmission(ModemTransmission())
        deadline = time.monotonic() + 10
        assert rx.channel is not None
        while rx.channel.counters.received < count and time.monotonic() < deadline:
            if select.select([rx.fileno()], [], [], 0.5)[0]:
                rx.do_work()
        rx.deliver_due()
    finally:
        rx.shutdown()
        tx.shutdown()
    return heard, rx


@needs_loopback_multicast
def test_a_seed_gives_the_same_drop_pattern() -> None:
    first, rx = heard_over_multicast("loss: 0.3 seed: 7")
    again, _ = heard_over_multicast("loss: 0.3 seed: 7")
    other, _ = heard_over_multicast("loss: 0.3 seed: 8")
    assert rx.channel is not None
    c = rx.channel.counters
    assert (c.received, c.lost + len(first), c.outage, c.overflow) == (200, 200, 0, 0)
    assert 30 <= c.lost <= 90, c  # about 30 %
    assert first == again  # same seed, same frames lost
    assert first != other
    assert rx.refused == Counter({"malformed": 1})  # bad input is counted apart from the channel's losses
    assert rx.received == len(first)


def test_delays_hold_frames_until_due_and_a_later_frame_may_overtake() -> None:
    model = ChannelModel(delay_min=0.1, delay_max=5.0, seed=3)
    channel: Channel[int] = Channel(model, modem_id=2)
    t0 = 1_700_000_000.0
    fates = [channel.admit(i, t0 + 0.01 * i)[0] for i in range(50)]
    assert fates == ["delay"] * 50 and channel.held == 50
    assert channel.due(t0 + 0.09) == []  # nothing before delay_min
    first = channel.next_delivery()
    assert first is not None and t0 + 0.1 <= first <= t0 + 5.5
    delivered = channel.due(t0 + 6.0)
    assert sorted(delivered) == list(range(50)) and delivered != list(range(50))  # all, some overtaken
    assert channel.next_delivery() is None and channel.counters.delivered == 50


# -- 3. an outage window expires what was sent into it -------------------------------------------------------


@needs_loopback_multicast
def test_outage_window_expires_what_was_sent_into_it(tmp_path: Path) -> None:
    warp, period, duration = 20, 80.0, 40.0  # warped s: dead 40 s (2 s real) of every 80 s
    sat = LoopbackLink([(1, 5, 64), (2, 5, 64)])
    model = f"outage_period: {period} outage_duration: {duration} outage_phase: 0"
    links = {"topside": [with_channel(sat.block(1), model)], "usv": [with_channel(sat.block(2), model)]}
    clock = SystemClock(use_sim_time=True, warp_factor=warp)  # the brokers' warped clock

    def wait_for_phase(link: CommandLink, start: float, end: float) -> float:
        """Poll until the warped clock is within [start, end) of the outage cycle; return the cycle position."""
        assert poll_all([link.topside, link.usv], lambda: start <= clock.now() % period < end, 2 * period / warp)
        return clock.now() % period

    with link_brokers(tmp_path, links, "outage", warp=warp) as brokers:
        topside = IntervehicleClient(brokers["topside"].interprocess_config(), "topside_app")
        usv = IntervehicleClient(brokers["usv"].interprocess_config(), "usv_app")
        try:
            assert topside.wait_subscribed() and usv.wait_subscribed()
            link = CommandLink(topside, usv)
            assert link.subscribe(15), brokers["usv"].stderr_text()
            wait_for_phase(link, 0.0, 2.0)  # an outage just began: 38 s of it left
            link.publish(100, ttl=20)  # sent in the topside's slots (every 10 s), all of them inside the outage
            assert poll_all([topside, usv], lambda: link.expires, 3), brokers["topside"].stderr_text()
            wait_for_phase(link, duration, duration + 2.0)  # the channel is back: 38 s until the next outage
            link.publish(110, ttl=30)
            assert poll_all([topside, usv], lambda: link.acks, 3), brokers["topside"].stderr_text()
            link.poll(0.5)
        finally:
            topside.close()
            usv.close()
        text = brokers["usv"].stderr_text()
    assert link.expires == [(100, ExpireData.EXPIRED_TIME_TO_LIVE_EXCEEDED)]
    assert [r for r, _ in link.acks] == [110] and link.received == [110]
    assert "lost in an outage window" in text, text


# -- 4. bad settings name the field ----------------------------------------------------------------------------


@pytest.mark.parametrize(("model", "field"), [
    ("loss: 1.5", "channel_model.loss"),
    ("loss: -0.1", "channel_model.loss"),
    ("loss: nan", "channel_model.loss"),
    ("delay_min: -1", "channel_model.delay_min"),
    ("delay_min: 2 delay_max: 1", "channel_model.delay_max"),
    ("delay_max: inf", "channel_model.delay_max"),
    ("delay_min: 7200", "channel_model.delay_min"),
    ("outage_period: -5", "channel_model.outage_period"),
    ("outage_period: 10 outage_duration: 11", "channel_model.outage_duration"),
    ("outage_duration: 3", "channel_model.outage_duration"),
    ("outage_period: 10 outage_duration: 1 outage_phase: inf", "channel_model.outage_phase"),
])
def test_bad_channel_settings_name_the_field(model: str, field: str) -> None:
    parsed = ChannelModel()
    text_format.Parse(model, parsed)
    with pytest.raises(ModemConfigError, match=rf"^{field} "):
        check_channel_model(parsed)
    cfg = DriverConfig(modem_id=1, driver_name="ether")
    cfg.Extensions[channel_model].CopyFrom(parsed)
    driver = EtherDriver(Ether())
    with pytest.raises(ModemConfigError, match=rf"^{field} "):
        driver.startup(cfg)  # refused before the driver opens anything
    with pytest.raises(ValueError, match="not started"):
        driver.fileno()


def test_good_settings_are_described() -> None:
    model = ChannelModel(loss=0.05, outage_period=300, outage_duration=30)
    check_channel_model(model)
    assert describe(model) == "loss 5%, outage 30 s every 300 s, unseeded"
    assert describe(ChannelModel(loss=0.2, delay_min=1, delay_max=3, seed=1)) == "loss 20%, delay 1-3 s, seed 1"


def test_broker_with_a_bad_channel_setting_fails_naming_it(tmp_path: Path) -> None:
    cfg = tmp_path / "gobyd.pb.cfg"
    block = with_channel(LoopbackLink([(1, 5, 64), (2, 5, 64)]).block(2), "loss: 0.2 delay_min: 3 delay_max: 1")
    cfg.write_text("intervehicle {\n" + block + "\n}\n")
    ipc = InterProcessPortalConfig(platform="chan", socket_name=str(tmp_path / "goby_chan"))
    result = subprocess.run([sys.executable, "-m", "gateway.apps.goby_broker", "--interprocess",
                             text_format.MessageToString(ipc, as_one_line=True), str(cfg)],
                            capture_output=True, text=True, timeout=60)
    out = result.stdout + result.stderr
    assert result.returncode not in (0, None) and "Traceback" not in out, out
    assert "intervehicle link 2: channel_model.delay_max 1.0 is out of range" in out, out
