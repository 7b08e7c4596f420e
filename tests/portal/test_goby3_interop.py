"""Interoperability with the real Goby3 3.1 interprocess layer: our portal clients through a real ``gobyd``, and
the real ``goby zeromq publish``/``subscribe`` tools (src/apps/zeromq/zeromq_tool/zeromq_tool.cpp) with our client,
both ways, on our goby-broker and on a real gobyd. Skipped with the reason unless the binaries are on PATH inside a private network namespace
(tests/goby3_real.py)."""

from __future__ import annotations

import contextlib
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from frontseat.protobuf.frontseat_pb2 import HELM_DRIVE, INTERFACE_COMMAND, HelmStateReport, InterfaceStatus
from gateway.goby.portal import Scheme
from gateway.goby.portal.testing import BrokerProcess, PortalClient, app_process
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from tests.goby3_real import interprocess_text, real_goby_skip_reason, short_ipc_dir
from tests.protobuf.sample_messages_pb2 import Sample

pytestmark = pytest.mark.interop


def _ping_until_received(sender: PortalClient, receiver: PortalClient, group: str, got: list, value: int) -> bool:
    def arrived() -> bool:
        sender.publish(group, Sample(a=value))
        sender.poll(0.05)
        return receiver.poll_until(lambda: bool(got), 0.1)

    return receiver.poll_until(arrived, 20)


@contextlib.contextmanager
def _real_gobyd(tmp_path: Path) -> Iterator[InterProcessPortalConfig]:
    """A real gobyd on an IPC socket (``gobyd CFG``, CFG an ``interprocess { }`` block); yields the portal config."""
    ipc_dir = short_ipc_dir()
    ipc = InterProcessPortalConfig(platform="interop", transport=InterProcessPortalConfig.IPC,
                                   socket_name=str(ipc_dir / "goby_interop"))
    cfg = tmp_path / "gobyd.pb.cfg"
    cfg.write_text(f"interprocess {{ {interprocess_text(ipc)} }}\n")
    gobyd = app_process(["gobyd", str(cfg)], log_path=tmp_path / "gobyd.log")
    try:
        yield ipc
    finally:
        gobyd.stop()
        shutil.rmtree(ipc_dir, ignore_errors=True)


@contextlib.contextmanager
def _our_broker(tmp_path: Path) -> Iterator[InterProcessPortalConfig]:
    ipc_dir = short_ipc_dir()
    broker = BrokerProcess(ipc_dir, platform="interop", log_path=tmp_path / "broker.log")
    broker.start()
    try:
        yield broker.interprocess_config()
    finally:
        broker.stop()
        shutil.rmtree(ipc_dir, ignore_errors=True)


def test_our_clients_talk_both_ways_through_a_real_gobyd(tmp_path: Path) -> None:
    reason = real_goby_skip_reason("gobyd")
    if reason:
        pytest.skip(reason)
    with _real_gobyd(tmp_path) as ipc, PortalClient(ipc, "ours_a") as a, PortalClient(ipc, "ours_b") as b:
        at_b = b.collect("interop::a_to_b", Sample)
        at_a = a.collect("interop::b_to_a", Sample)
        assert a.wait_subscribed() and b.wait_subscribed()  # the manager handshake with gobyd worked
        assert _ping_until_received(a, b, "interop::a_to_b", at_b, 7), (tmp_path / "gobyd.log").read_text()
        assert _ping_until_received(b, a, "interop::b_to_a", at_a, 8)
    assert at_b[0].a == 7 and at_a[0].a == 8


@pytest.mark.parametrize("broker", ["goby-broker", "gobyd"])
def test_real_goby_zeromq_publish_and_subscribe_with_our_client(tmp_path: Path, broker: str) -> None:
    """The real tools and our client, both ways, on our broker and on a real gobyd."""
    reason = real_goby_skip_reason("goby", *(["gobyd"] if broker == "gobyd" else []))
    if reason:
        pytest.skip(reason)
    with (_real_gobyd if broker == "gobyd" else _our_broker)(tmp_path) as ipc:
        # Goby -> us: `goby zeromq publish GROUP TYPE VALUE` (a type containing "protobuf." implies PROTOBUF)
        with PortalClient(ipc, "ours_sub") as ours:
            got = ours.collect("interop::helm", HelmStateReport)
            assert ours.wait_subscribed()
            publisher = app_process(["goby", "zeromq", "publish", "interop::helm",
                                    "goby.middleware.frontseat.protobuf.HelmStateReport", "state: HELM_DRIVE",
                                    "--interprocess", interprocess_text(ipc)], log_path=tmp_path / "pub.log")
            try:
                assert ours.poll_until(lambda: bool(got), 30), (tmp_path / "pub.log").read_text()
            finally:
                publisher.stop()
        assert got[0].state == HELM_DRIVE
        # us -> Goby: `goby zeromq subscribe GROUP_REGEX` prints "scheme | group | type | time | debug text"
        subscriber = app_process(["goby", "zeromq", "subscribe", "interop::.*", "--interprocess", interprocess_text(ipc)],
                                log_path=tmp_path / "sub.log")
        try:
            with PortalClient(ipc, "ours_pub") as ours:
                assert ours.wait_ready()
                line = None
                for _ in range(100):
                    ours.publish("interop::status", InterfaceStatus(state=INTERFACE_COMMAND))
                    ours.poll(0.05)
                    found = subscriber.wait_for_output(r"^.*interop::status.*$", 0.2)
                    line = found.group(0) if found else None
                    if line:
                        break
            assert line is not None, (tmp_path / "sub.log").read_text()
        finally:
            subscriber.stop()
    fields = [f.strip() for f in line.split(" | ")]
    assert fields[0] == str(int(Scheme.PROTOBUF))
    assert fields[1] == "interop::status"
    assert fields[2] == "goby.middleware.frontseat.protobuf.InterfaceStatus"
    assert "INTERFACE_COMMAND" in fields[-1]
