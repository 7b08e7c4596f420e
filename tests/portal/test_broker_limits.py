"""Issue #19 item 2 for goby-broker: a frame larger than ``max_message_bytes`` is not buffered; ZeroMQ drops the
sender's connection at the frame header, and everyone else carries on."""

from __future__ import annotations

from pathlib import Path

from gateway.goby.portal.broker import Broker
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.goby.portal.testing import PortalClient


def test_oversized_frame_is_refused_and_others_carry_on(tmp_path: Path) -> None:
    cfg = GobyDaemonConfig()
    cfg.interprocess.platform = "limits"
    cfg.interprocess.socket_name = str(tmp_path / "b")
    with Broker(cfg, max_message_bytes=1024 * 1024):
        with PortalClient(cfg.interprocess, "reader") as reader, PortalClient(cfg.interprocess, "good") as good, \
                PortalClient(cfg.interprocess, "huge") as huge:
            small = reader.collect("small", str)
            big = reader.collect("big", str)
            assert reader.wait_subscribed() and good.wait_ready() and huge.wait_ready()
            huge.publish("big", "x" * (4 * 1024 * 1024))  # over the broker's 1 MiB limit
            for i in range(200):
                good.publish("small", str(i))
                huge.poll(0.0)
                reader.poll(0.002)
            assert reader.poll_until(lambda: len(small) == 200, 20)
            assert small == [str(i) for i in range(200)]
            reader.poll_until(lambda: False, 0.5)
            assert big == []
