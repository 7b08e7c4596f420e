"""Interprocess publish/subscribe between real processes through a real goby-broker."""

from __future__ import annotations

import logging
import sys
import time
from pathlib import Path

import pytest

from gateway.goby.dccl import Codec as DcclCodec
from gateway.goby.portal import Scheme
from gateway.goby.portal.marshalling import parse_dynamic
from gateway.goby.portal.testing import BrokerProcess, PortalClient, app_process, broker_process
from tests.protobuf.sample_messages_pb2 import DCCLSample, Sample, Widget
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from util.process import ChildProcess

REPO = Path(__file__).resolve().parents[2]


def sample_app(broker: BrokerProcess, tmp_path: Path, role: str, *args: str, name: str | None = None) -> ChildProcess:
    name = name or f"sample_{role}"
    cmd = [sys.executable, "-m", "tests.portal.apps.sample_app", f"--role={role}", "-a", name, "-v", *args]
    return app_process(cmd, env=broker.env(), cwd=REPO, log_path=tmp_path / f"{name}.log")


def received(app: ChildProcess, group: str) -> list[int]:
    return [int(line.split()[2]) for line in app.lines() if line.startswith(f"RX {group} ")]


def test_two_apps_exchange_protobuf_on_several_groups(broker: BrokerProcess, tmp_path: Path) -> None:
    groups = ["nav", "widget1;1", "goby::middleware::frontseat::node_status"]
    group_args = [arg for g in groups for arg in ("--group", g)]
    # the hold makes the exchange lossless: tx publishes only after rx has subscribed and reported ready
    with sample_app(broker, tmp_path, "rx", *group_args, "--count", "20") as rx:
        assert rx.wait_for_output("RX DONE", 0.5) is None
        with sample_app(broker, tmp_path, "tx", *group_args, "--count", "20", "--publish_period", "0.01") as tx:
            assert rx.wait_for_output("RX DONE", 60), rx.stderr_text()
            assert tx.wait(30) == 0, tx.stderr_text()
        assert rx.wait(30) == 0
    for group in groups:
        assert received(rx, group) == list(range(1, 21)), group


def test_hold_buffers_publications_until_required_clients_are_ready(tmp_path: Path) -> None:
    hold = ["--hold", 'required_client: "hold_rx" required_client: "hold_tx"']
    with broker_process(tmp_path, platform="hold1", extra_args=hold) as broker, \
            PortalClient(broker.interprocess_config(), "hold_tx") as tx:
        for a in range(1, 6):  # published before anyone listens: buffered by the hold
            tx.publish("held", Sample(a=a))
        tx.poll(0.5)
        assert tx.portal.hold_state() is True
        with sample_app(broker, tmp_path, "rx", "--group", "held", "--count", "5", name="hold_rx") as rx:
            assert tx.poll_until(lambda: not tx.portal.hold_state(), 30)
            assert rx.wait_for_output("RX DONE", 30), rx.stderr_text()
        assert received(rx, "held") == [1, 2, 3, 4, 5]


def test_regex_subscription_full_match(broker: BrokerProcess, tmp_path: Path) -> None:
    with PortalClient(broker.interprocess_config(), "regex_rx") as rx, \
            PortalClient(broker.interprocess_config(), "regex_tx") as tx:
        hits: list[tuple[object, int, str, str]] = []
        rx.portal.subscribe_regex(lambda data, scheme, tname, group: hits.append(
            (parse_dynamic(data, scheme, tname), scheme, tname, group)),
            group_regex="Sample1|Sample2", type_regex=".*Sample", schemes=[Scheme.PROTOBUF])
        everything: list[str] = []
        rx.portal.subscribe_regex(lambda data, scheme, tname, group: everything.append(f"{group}:{tname}"))
        assert rx.wait_subscribed() and tx.wait_ready()
        for group in ("Sample1", "Sample2", "Sample3", "Sample12", "xSample1"):
            tx.publish(group, Sample(a=len(group)))
        tx.publish("Sample1", Widget(b=1))  # type does not fully match .*Sample
        tx.publish("Sample1", "text")  # CSTR: not in the scheme set
        tx.publish("end", Sample(a=0))
        assert rx.poll_until(lambda: "end:goby.test.zeromq.protobuf.Sample" in everything, 20)
    assert [(m.a, s, t, g) for m, s, t, g in hits] == [
        (7, Scheme.PROTOBUF, "goby.test.zeromq.protobuf.Sample", "Sample1"),
        (7, Scheme.PROTOBUF, "goby.test.zeromq.protobuf.Sample", "Sample2"),
    ]
    assert "Sample1:CSTR" in everything and "Sample1:goby.test.zeromq.protobuf.Widget" in everything


def test_regex_subscription_on_another_process(broker: BrokerProcess, tmp_path: Path) -> None:
    with PortalClient(broker.interprocess_config(), "regex_rx2") as rx:
        groups: list[str] = []
        rx.portal.subscribe_type_regex("[Sample]()", lambda d, s, t, g: groups.append(g), type_regex=".*Sample")
        assert rx.wait_subscribed()
        with sample_app(broker, tmp_path, "tx", "--group", "[Sample]()", "--group", "Sample", "--count", "3",
                        "--publish_period", "0.01") as tx:
            assert tx.wait(30) == 0, tx.stderr_text()
        assert rx.poll_until(lambda: len(groups) >= 3, 20)
    assert set(groups) == {"[Sample]()"}


def test_own_publications_echo_unless_disabled(broker: BrokerProcess) -> None:
    with PortalClient(broker.interprocess_config(), "echo_a") as a, \
            PortalClient(broker.interprocess_config(), "echo_b") as b:
        with_echo = a.collect("e", Sample)
        without_echo = a.collect("e", Sample, echo=False)
        assert a.wait_subscribed() and b.wait_ready()
        a.publish("e", Sample(a=1))  # same process (both clients live in this test process)
        assert a.poll_until(lambda: len(with_echo) == 1, 20)
        a.poll(0.2)
    assert [m.a for m in with_echo] == [1]
    assert without_echo == []


def test_unsubscribe_stops_delivery(broker: BrokerProcess) -> None:
    with PortalClient(broker.interprocess_config(), "unsub") as client:
        got = client.collect("u", Sample)
        marks = client.collect("mark", Sample)
        assert client.wait_subscribed()
        client.publish("u", Sample(a=1))
        assert client.poll_until(lambda: len(got) == 1, 20)
        client.portal.unsubscribe("u", Sample)
        client.publish("u", Sample(a=2))
        client.publish("mark", Sample(a=3))
        assert client.poll_until(lambda: len(marks) == 1, 20)
    assert [m.a for m in got] == [1]


def test_broker_killed_and_restarted_mid_stream(
    broker: BrokerProcess, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, logger="gateway.goby.portal.interprocess")
    with PortalClient(broker.interprocess_config(), "restart_rx") as rx:
        got = rx.collect("stream", Sample)
        assert rx.wait_subscribed()
        with sample_app(broker, tmp_path, "tx", "--group", "stream", "--count", "5000",
                        "--publish_period", "0.02") as tx:  # long enough to outlast a slow restart
            assert rx.poll_until(lambda: len(got) >= 20, 30), tx.stderr_text()
            broker.kill()  # a crash: the IPC files stay behind
            rx.poll(0.5)
            before = max(m.a for m in got)
            broker.start()
            assert rx.poll_until(lambda: any(m.a > before + 20 for m in got), 60), tx.stderr_text()
            assert rx.poll_until(lambda: "reconnected to the broker" in tx.stderr_text(), 20)
            tx.stop()
            tx_log = tx.stderr_text()
    assert "lost connection to the broker" in caplog.text
    assert "reconnected to the broker" in caplog.text
    assert "reconnected to the broker" in tx_log
    numbers = [m.a for m in got]
    assert numbers == sorted(numbers)  # in order, with a gap while the broker was down


def test_multithread_app_thread_gets_callbacks_and_relays_on_interthread(
    broker: BrokerProcess, tmp_path: Path
) -> None:
    with PortalClient(broker.interprocess_config(), "mt_tx") as tx, \
            sample_app(broker, tmp_path, "threads", "--group", "mt") as app:
        assert tx.wait_ready()
        a = 0

        def relayed() -> bool:
            nonlocal a
            a += 1
            tx.publish("mt", Sample(a=a))
            return app.wait_for_output("RX relay", 0.1) is not None

        assert tx.poll_until(relayed, 30), app.stderr_text()
        assert app.stop() == 0
    assert any(line.startswith("RX mt ") for line in app.lines())


def test_dccl_message_travels_as_protobuf(broker: BrokerProcess) -> None:
    with PortalClient(broker.interprocess_config(), "dccl_client") as client:
        typed = client.collect("dccl", DCCLSample)
        raw: list[tuple[int, str]] = []
        client.portal.subscribe_regex(lambda d, s, t, g: raw.append((s, t)), group_regex="dccl")
        assert client.wait_subscribed()
        client.publish("dccl", DCCLSample(a=12))
        assert client.poll_until(lambda: bool(typed) and bool(raw), 20)
    assert typed[0].a == 12
    assert raw == [(Scheme.PROTOBUF, "goby.test.zeromq.protobuf.DCCLSample")]


def test_dccl_scheme_carries_the_dccl_bytes_between_processes(broker: BrokerProcess, tmp_path: Path) -> None:
    """publish(..., scheme=DCCL): identifier ``/usv_command/DCCL/goby3_course.dccl.USVCommand/...`` and the DCCL
    bytes as payload; a DCCL-scheme subscriber in another process decodes them."""
    command = USVCommand(time=time.time() // 1, desired_state=USVCommand.POLYGON, polygon_sides=6,
                         polygon_radius=300)
    with PortalClient(broker.interprocess_config(), "dccl_scheme_rx") as rx:
        typed = rx.collect("usv_command", USVCommand, scheme=Scheme.DCCL)
        protobuf = rx.collect("usv_command", USVCommand)
        raw: list[tuple[bytes, int, str]] = []
        rx.portal.subscribe_regex(lambda d, s, t, g: raw.append((d, s, t)), group_regex="usv_command")
        assert rx.wait_subscribed()
        with PortalClient(broker.interprocess_config(), "dccl_scheme_tx") as tx:
            assert tx.wait_ready()
            tx.publish("usv_command", command, scheme=Scheme.DCCL)
            tx.poll(0.1)
        assert rx.poll_until(lambda: bool(typed) and bool(raw), 20)
    assert typed == [command] and protobuf == []
    payload, scheme, type_name = raw[0]
    assert (scheme, type_name) == (Scheme.DCCL, "goby3_course.dccl.USVCommand")
    codec = DcclCodec()
    codec.load(USVCommand)
    assert payload == codec.encode(command) and len(payload) == 5
