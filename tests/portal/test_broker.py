"""goby-broker: manager protocol, raw wire bytes, malformed input, TCP, refusing a second broker."""

from __future__ import annotations

import logging
import os
from pathlib import Path

import pytest
import zmq

from gateway.goby.portal import BrokerUnavailableError
from gateway.goby.portal.broker import Broker, BrokerError
from gateway.goby.portal.identifier import thread_id
from gateway.goby.portal.manager_client import request_endpoints
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.goby.portal.testing import BrokerProcess, PortalClient, broker_process
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.goby.protobuf.interprocess_zeromq_pb2 import (
    PROVIDE_HOLD_STATE,
    PROVIDE_PUB_SUB_SOCKETS,
    ManagerRequest,
    Socket,
)
from tests.protobuf.sample_messages_pb2 import Sample

SAMPLE = "goby.test.zeromq.protobuf.Sample"


def test_manager_answers_like_gobyd() -> None:
    cfg = GobyDaemonConfig()
    cfg.interprocess.platform = "p"
    cfg.hold.required_client.extend(["rx", "tx"])
    broker = Broker(cfg)  # not started: respond() is pure
    sockets = broker.respond(ManagerRequest(request=PROVIDE_PUB_SUB_SOCKETS, client_name="c", client_pid=7))
    assert (sockets.client_name, sockets.client_pid) == ("c", 7)
    assert sockets.publish_socket.socket_type == Socket.PUBLISH
    assert sockets.publish_socket.transport == Socket.IPC
    assert sockets.publish_socket.socket_name == "/tmp/goby_p.xsub"
    assert sockets.subscribe_socket.socket_name == "/tmp/goby_p.xpub"
    assert sockets.subscribe_socket.connect_or_bind == Socket.CONNECT
    assert not sockets.HasField("hold")

    def hold(name: str, ready: bool) -> bool:
        req = ManagerRequest(request=PROVIDE_HOLD_STATE, client_name=name, client_pid=1, ready=ready)
        return broker.respond(req).hold

    assert hold("rx", False) is True
    assert hold("rx", True) is True
    assert hold("other", True) is True  # not a required client: does not count
    assert hold("tx", True) is False
    assert hold("late", False) is False  # once released, stays released


def test_no_required_clients_means_no_hold() -> None:
    broker = Broker(GobyDaemonConfig())
    assert broker.respond(ManagerRequest(request=PROVIDE_HOLD_STATE, client_name="x", client_pid=1)).hold is False


def test_broker_process_hands_out_ipc_endpoints(broker: BrokerProcess) -> None:
    with zmq.Context() as zctx:
        pub, sub, response = request_endpoints(zctx, broker.interprocess_config(), "probe", timeout_s=10)
    assert pub == f"ipc://{broker.socket_base}.xsub"
    assert sub == f"ipc://{broker.socket_base}.xpub"
    assert response.client_pid == os.getpid()


def test_raw_subscriber_sees_goby_identifier_bytes(broker: BrokerProcess) -> None:
    with zmq.Context() as zctx, PortalClient(broker.interprocess_config(), "raw_test") as client:
        raw = zctx.socket(zmq.SUB)
        raw.setsockopt(zmq.LINGER, 0)
        raw.connect(f"ipc://{broker.socket_base}.xpub")
        raw.setsockopt(zmq.SUBSCRIBE, b"/widget1;1/")
        assert client.wait_ready()
        expected_head = f"/widget1;1/PROTOBUF/{SAMPLE}/{os.getpid()}/{thread_id()}/".encode() + b"\0"
        msg = Sample(a=5, temperature=1.5)
        frame = None
        for _ in range(200):  # until the raw subscription has reached the publisher
            client.publish("widget1;1", msg)
            if raw.poll(50):
                frame = raw.recv()
                break
        raw.close()
    assert frame is not None
    assert frame == expected_head + msg.SerializeToString()


def test_malformed_frames_are_logged_and_the_client_keeps_serving(
    broker: BrokerProcess, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.ERROR, logger="gateway.goby.portal.interprocess")
    with zmq.Context() as zctx, PortalClient(broker.interprocess_config(), "victim") as client:
        got = client.collect("bad", Sample)
        assert client.wait_subscribed()
        raw = zctx.socket(zmq.PUB)
        raw.setsockopt(zmq.LINGER, 0)
        raw.connect(f"ipc://{broker.socket_base}.xsub")
        prefix = f"/bad/PROTOBUF/{SAMPLE}/".encode()
        bad_frames = [prefix + b"notapid/ab/\0x", prefix + b"1/ab/\0\xff\xff\xff", prefix + b"1/ab/"]
        good = prefix + b"1/ab/\0" + Sample(a=99).SerializeToString()

        def sent_and_received() -> bool:
            for frame in (*bad_frames, good):
                raw.send(frame)
            return client.poll_until(lambda: bool(got), 0.1)

        assert client.poll_until(sent_and_received, 20)
        raw.close()
    assert got[0].a == 99
    text = caplog.text
    assert "malformed identifier" in text
    assert "cannot decode publication on bad (goby.test.zeromq.protobuf.Sample)" in text
    assert "identifier followed by NUL" in text


def test_second_broker_for_the_same_platform_is_refused(broker: BrokerProcess) -> None:
    cfg = GobyDaemonConfig()
    cfg.interprocess.CopyFrom(broker.interprocess_config())
    with pytest.raises(BrokerError, match="another broker already serves"):
        Broker(cfg).start()


def test_no_broker_is_a_named_error(tmp_path: Path) -> None:
    cfg = InterProcessPortalConfig(platform="nobody", socket_name=str(tmp_path / "nobody"), manager_timeout_seconds=1)
    with pytest.raises(BrokerUnavailableError, match=f"No response from goby-broker at ipc://{tmp_path}/nobody.manager"):
        PortalClient(cfg, "lonely")


def test_unusable_socket_path_is_a_named_error(tmp_path: Path) -> None:
    cfg = InterProcessPortalConfig(socket_name="/tmp/" + "x" * 200, manager_timeout_seconds=1)
    with pytest.raises(BrokerUnavailableError, match="cannot connect to the broker's manager at ipc:///tmp/xxx"):
        PortalClient(cfg, "long_path")


def test_tcp_transport_end_to_end(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="tcp1", tcp=True) as tcp_broker:
        cfg = tcp_broker.interprocess_config()
        assert cfg.transport == InterProcessPortalConfig.TCP and cfg.tcp_port > 0
        with PortalClient(cfg, "tcp_rx") as rx, PortalClient(cfg, "tcp_tx") as tx:
            got = rx.collect("tcp_group", Sample)
            assert rx.wait_subscribed() and tx.wait_ready()

            def exchange() -> bool:
                tx.publish("tcp_group", Sample(a=1))
                return rx.poll_until(lambda: bool(got), 0.1)

            assert rx.poll_until(exchange, 20)
        assert got[0].a == 1


def test_tcp_over_ipv6_loopback(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="tcp6", tcp=True, address="::1") as tcp_broker:
        cfg = tcp_broker.interprocess_config()  # ip_address is preferred over ipv4_address, bracketed in endpoints
        with PortalClient(cfg, "v6_client") as client:
            assert client.portal._pub_endpoint.startswith("tcp://[::1]:")
            got = client.collect("v6", Sample)
            assert client.wait_subscribed()
            client.publish("v6", Sample(a=6))
            assert client.poll_until(lambda: bool(got), 20)


def test_in_process_broker_start_stop_is_idempotent(tmp_path: Path) -> None:
    cfg = GobyDaemonConfig()
    cfg.interprocess.platform = "inproc"
    cfg.interprocess.socket_name = str(tmp_path / "b")
    cfg.router_threads = 1
    with Broker(cfg) as broker:
        assert broker.endpoints()["manager"] == f"ipc://{tmp_path}/b.manager"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["b.manager", "b.xpub", "b.xsub"]
        with zmq.Context() as zctx:
            request_endpoints(zctx, cfg.interprocess, "c", timeout_s=10)
    broker.stop()
    assert list(tmp_path.iterdir()) == []  # the socket files are removed on a clean stop
    assert BrokerProcess(tmp_path, "x").stop() is None


def test_manager_survives_malformed_requests(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="garbage", log_path=tmp_path / "broker.log") as broker:
        _garbage_then_valid(broker)
        broker.stop()
        err = broker.stderr_text()
    assert "malformed ManagerRequest" in err and "missing client_name, client_pid" in err


def _garbage_then_valid(broker: BrokerProcess) -> None:
    endpoint = f"ipc://{broker.socket_base}.manager"
    with zmq.Context() as zctx:
        req = zctx.socket(zmq.REQ)
        req.setsockopt(zmq.LINGER, 0)
        req.connect(endpoint)
        req.send(b"\xff\x00garbage")
        assert req.poll(10_000)
        assert req.recv() == b""  # REP must answer; the error is logged by the broker
        req.send(ManagerRequest(request=PROVIDE_HOLD_STATE).SerializePartialToString())  # required fields missing
        assert req.poll(10_000)
        assert req.recv() == b""
        req.close()
        pub, _, _ = request_endpoints(zctx, broker.interprocess_config(), "after_garbage", timeout_s=10)
    assert pub.endswith(".xsub")


def test_a_goby_style_raw_client_completes_the_hold_handshake(tmp_path: Path) -> None:
    """What a C++ Goby3 client does (spec §4.7), in raw ZeroMQ: sockets over REQ, hold over pub/sub."""
    from gateway.goby.protobuf.interprocess_zeromq_pb2 import ManagerResponse

    hold = ["--hold", 'required_client: "goby_app"']
    with broker_process(tmp_path, platform="raw_goby", extra_args=hold) as broker, zmq.Context() as zctx:
        req = zctx.socket(zmq.REQ)
        req.setsockopt(zmq.LINGER, 0)
        req.connect(f"ipc://{broker.socket_base}.manager")
        req.send(ManagerRequest(request=PROVIDE_PUB_SUB_SOCKETS, client_name="goby_app", client_pid=4242)
                 .SerializeToString())
        assert req.poll(10_000)
        sockets = ManagerResponse.FromString(req.recv())
        req.close()
        sub = zctx.socket(zmq.SUB)
        pub = zctx.socket(zmq.PUB)
        for sock in (sub, pub):
            sock.setsockopt(zmq.LINGER, 0)
        sub.connect(f"ipc://{sockets.subscribe_socket.socket_name}")
        pub.connect(f"ipc://{sockets.publish_socket.socket_name}")
        response_prefix = b"/goby::zeromq::_internal_manager_response/PROTOBUF/goby.zeromq.protobuf.ManagerResponse/"
        sub.setsockopt(zmq.SUBSCRIBE, response_prefix)
        request_ident = b"/goby::zeromq::_internal_manager_request/PROTOBUF/goby.zeromq.protobuf.ManagerRequest/4242/1f/"
        def hold_answers(ready: bool, until_released: bool) -> list[bool]:
            answers: list[bool] = []
            for _ in range(100):  # every 100 ms, as Goby does while held
                request = ManagerRequest(request=PROVIDE_HOLD_STATE, client_name="goby_app", client_pid=4242,
                                         ready=ready)
                pub.send(request_ident + b"\0" + request.SerializeToString())
                while sub.poll(100):
                    frame = sub.recv()
                    assert frame.startswith(response_prefix)
                    response = ManagerResponse.FromString(frame[frame.index(b"\0") + 1:])
                    if (response.client_name, response.client_pid) != ("goby_app", 4242):
                        continue  # another client's answer (the broker's own application's): a client reads its own
                    answers.append(response.hold)
                if answers and (not until_released or answers[-1] is False):
                    return answers
            return answers

        not_ready = hold_answers(False, until_released=False)
        ready = hold_answers(True, until_released=True)
        sub.close()
        pub.close()
    assert not_ready and all(not_ready)  # held while the required client is not ready
    assert ready and ready[-1] is False  # released once it reports ready
