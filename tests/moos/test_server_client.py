"""When the MOOSDB drops a connection for time (``server_client.timeout_reason``), with hand-set times."""

from __future__ import annotations

import socket
from collections.abc import Iterator

import pytest

from gateway.moos.server_client import CLOSED, HELLO, READY, ServerClient, timeout_reason


@pytest.fixture
def client() -> Iterator[ServerClient]:
    a, b = socket.socketpair()
    with a, b:
        c = ServerClient(a, "peer:1", 1024)
        c.accepted = c.last_rx = c.last_progress = 100.0
        yield c


def reason(client: ServerClient, now: float) -> str | None:
    return timeout_reason(client, now, handshake_timeout=5.0, stall_timeout=6.0, client_timeout=3.0)


def test_handshake_timeout_applies_before_the_name(client: ServerClient) -> None:
    assert reason(client, 104.0) is None  # silence is not counted before the handshake
    client.state = HELLO
    assert reason(client, 105.5) == "no handshake within 5 s"


def test_a_ready_client_is_dropped_for_silence_or_for_not_reading(client: ServerClient) -> None:
    client.state = READY
    assert reason(client, 102.9) is None
    assert reason(client, 103.5) == "disconnecting after 3 seconds of silence"
    client.last_rx = 110.0
    client.out_bytes = 10  # mail waits: the reader must take some within the stall timeout
    client.last_progress = 105.0
    assert reason(client, 110.9) is None
    assert reason(client, 111.5) == "not reading: 10 bytes unsent for 6 s"

def test_label_names_client_and_peer(client: ServerClient) -> None:
    assert client.label() == "peer:1"
    client.name = b"alice"
    client.state = CLOSED
    assert client.label() == "'alice' (peer:1)"
