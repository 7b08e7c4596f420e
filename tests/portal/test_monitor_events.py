"""Our ZeroMQ monitor-event reader against libzmq's own events, and malformed frames."""

from __future__ import annotations

import zmq

from gateway.goby.portal.monitor_events import parse_monitor_frames, recv_monitor_event


def test_a_real_connect_event_is_read() -> None:
    ctx = zmq.Context()
    server = ctx.socket(zmq.PULL)
    port = server.bind_to_random_port("tcp://127.0.0.1")
    client = ctx.socket(zmq.PUSH)
    monitor = client.get_monitor_socket(zmq.EVENT_CONNECTED)
    try:
        client.connect(f"tcp://127.0.0.1:{port}")
        assert monitor.poll(5000)
        event = recv_monitor_event(monitor)
        assert event is not None
        assert event.event == zmq.EVENT_CONNECTED
        assert event.endpoint == f"tcp://127.0.0.1:{port}".encode()
    finally:
        client.disable_monitor()
        for sock in (monitor, client, server):
            sock.close(0)
        ctx.term()


def test_malformed_frames_give_none() -> None:
    assert parse_monitor_frames([b"\x01\x00"]) is None
    assert parse_monitor_frames([b"\x01\x00\x00\x00", b"ep"]) is None
    assert parse_monitor_frames([b"\x01" * 6, b"ep", b"extra"]) is None
