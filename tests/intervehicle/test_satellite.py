"""The course's satellite link (topside modem 1, USV modem 2; 5 s / 64 B slots) between two goby-broker processes:
USVCommand acked, a silent USV makes the command expire once (ttl), and a restarted USV broker gets the
subscription again so traffic resumes."""

from __future__ import annotations

import time

from gateway.goby.intervehicle import ExpireData, Publisher, Subscriber, TransporterConfig
from gateway.goby.intervehicle.testing import IntervehicleClient, LoopbackLink, link_brokers
from gateway.goby.portal import Group
from gateway.goby.portal.testing import poll_all
from tests.markers import needs_loopback_multicast
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

pytestmark = needs_loopback_multicast

WARP = 20
SAT = [(1, 5, 64), (2, 5, 64)]
usv_command = Group("usv_command", 0)


def test_usv_command_ack_expiry_and_broker_restart(tmp_path) -> None:
    sat = LoopbackLink(SAT)
    links = {"topside": [sat.block(1)], "usv": [sat.block(2)]}
    with link_brokers(tmp_path, links, "sat", warp=WARP) as brokers:
        topside = IntervehicleClient(brokers["topside"].interprocess_config(), "topside_app")
        usv = IntervehicleClient(brokers["usv"].interprocess_config(), "usv_app")
        try:
            assert topside.wait_subscribed() and usv.wait_subscribed()
            received: list[USVCommand] = []
            sub_cfg = TransporterConfig()
            sub_cfg.intervehicle.publisher_id.append(1)
            sub_cfg.intervehicle.buffer.ack_required = True
            subscribed: list[int] = []
            usv.intervehicle().subscribe(usv_command, USVCommand, received.append,
                                         Subscriber(cfg=sub_cfg, on_subscribed=lambda s, a: subscribed.append(1)))
            assert poll_all([topside, usv], lambda: subscribed, 20)
            acks: list[int] = []
            expires: list[int] = []
            pub_cfg = TransporterConfig()
            pub_cfg.intervehicle.buffer.ttl = 30  # warped seconds
            publisher = Publisher(cfg=pub_cfg, on_ack=lambda m, a: acks.append(a.latency),
                                  on_expire=lambda m, e: expires.append(e.reason))
            topside.intervehicle().publish(usv_command, USVCommand(time=time.time(), desired_state=USVCommand.WAYPOINTS),
                                           publisher)
            assert poll_all([topside, usv], lambda: acks and received, 10)
            assert 0 < acks[0] <= 10_500_000  # within one 10 s (warped) cycle, in µs
            # The USV's broker goes away: the next command is retried, then expires once (ttl 30 s warped = 1.5 s).
            brokers["usv"].stop()
            topside.intervehicle().publish(usv_command, USVCommand(time=time.time(), desired_state=USVCommand.POLYGON,
                                                                   polygon_sides=4, polygon_radius=200), publisher)
            assert poll_all([topside], lambda: expires, 10)
            poll_all([topside], lambda: False, 1.0)
            assert expires == [ExpireData.EXPIRED_TIME_TO_LIVE_EXCEEDED] and len(acks) == 1
            # Restarted, the USV's link announces itself; the app resends its subscription and commands flow again.
            brokers["usv"].start()
            assert usv.wait_subscribed()
            before = len(received)
            deadline = time.monotonic() + 25
            while len(received) == before and time.monotonic() < deadline:
                topside.intervehicle().publish(
                    usv_command, USVCommand(time=time.time(), desired_state=USVCommand.WAYPOINTS), publisher)
                poll_all([topside, usv], lambda: len(received) > before, 2)
            assert len(received) > before
        finally:
            topside.close()
            usv.close()
