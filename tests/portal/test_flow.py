"""Flow under stress: a slow subscriber does not block publishers; a TCP broker restart is rejoined."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

from gateway.goby.portal.testing import BrokerProcess, PortalClient, broker_process
from tests.protobuf.sample_messages_pb2 import Sample


def test_slow_subscriber_does_not_block_publisher_or_fast_subscriber(broker: BrokerProcess) -> None:
    cfg = broker.interprocess_config()
    with PortalClient(cfg, "slow") as slow, PortalClient(cfg, "fast") as fast, PortalClient(cfg, "pub") as pub:
        slow_got = slow.collect("flood", Sample)
        fast_got = fast.collect("flood", Sample)
        assert slow.wait_subscribed() and fast.wait_subscribed() and pub.wait_ready()
        total = 6000
        for a in range(total):  # the slow client is never polled while this runs
            pub.publish("flood", Sample(a=a))
            if a % 100 == 99:
                fast.poll_until(lambda a=a: len(fast_got) >= a - 200, 20)
        assert fast.poll_until(lambda: len(fast_got) == total, 30)
        assert pub.portal.dropped == 0
        slow.poll_until(lambda: len(slow_got) == total, 1.0)
        assert [m.a for m in fast_got] == list(range(total))
    # past its queues (broker SNDHWM + client RCVHWM) the slow subscriber lost messages; what it got is in order
    assert 0 < len(slow_got) < total
    assert [m.a for m in slow_got] == sorted(m.a for m in slow_got)


def test_tcp_broker_restart_is_rejoined_on_new_ports(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="gateway.goby.portal.interprocess")
    with broker_process(tmp_path, platform="tcp_restart", tcp=True) as broker:
        cfg = broker.interprocess_config()
        with PortalClient(cfg, "tcp_rx") as rx, PortalClient(cfg, "tcp_tx") as tx:
            got = rx.collect("t", Sample)
            assert rx.wait_subscribed() and tx.wait_ready()
            old_ports = (broker.endpoints["xpub"], broker.endpoints["xsub"])
            broker.kill()
            broker.start()
            assert (broker.endpoints["xpub"], broker.endpoints["xsub"]) != old_ports
            a = 0

            def delivered() -> bool:
                nonlocal a
                a += 1
                tx.publish("t", Sample(a=a))
                tx.poll(0)
                return rx.poll_until(lambda: bool(got), 0.1)

            assert rx.poll_until(delivered, 40)
    assert "broker moved to publish" in caplog.text
