"""Bad input and faults: the offending client alone is dropped with a logged reason; everyone else carries on."""

from __future__ import annotations

import contextlib
import logging
import socket
import struct
from collections.abc import Iterator

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gateway.moos.codec import PROTOCOL_BYTES, PacketReader, encode_packet
from gateway.moos.message import DATA, DOUBLE, NOTIFY, REGISTER, STRING, TIMING, MoosMessage
from gateway.moos.server import MoosDB
from gateway.moos.testing import collect_mail, connected_comms, running_moosdb
from util.process import wait_until


def hello_bytes(name: str, asynchronous: bool = True) -> bytes:
    hello = MoosMessage(DATA, STRING, key=b"asynchronous" if asynchronous else b"", msg_time=1.0, sval=name.encode())
    return PROTOCOL_BYTES + encode_packet([hello])


@contextlib.contextmanager
def raw_connection(port: int) -> Iterator[socket.socket]:
    sock = socket.create_connection(("127.0.0.1", port), timeout=10)
    try:
        yield sock
    finally:
        sock.close()


def read_until_closed(sock: socket.socket, timeout: float = 10.0) -> bytes:
    """Everything the server sends until it closes the connection."""
    sock.settimeout(timeout)
    data = b""
    while True:
        try:
            chunk = sock.recv(65536)
        except ConnectionResetError:
            return data
        if not chunk:
            return data
        data += chunk


def reasons(db: MoosDB) -> str:
    return " | ".join(reason for _, reason in db.dropped)


@contextlib.contextmanager
def good_pair(port: int) -> Iterator[tuple[object, object]]:
    with connected_comms(port, "alice", ["SEQ_B"]) as alice, connected_comms(port, "bob", ["SEQ_A"]) as bob:
        yield alice, bob


def exchange(alice, bob, start: int, count: int) -> None:
    for i in range(start, start + count):
        alice.notify("SEQ_A", float(i))
        bob.notify("SEQ_B", float(i))


def check_sequences(alice, bob, count: int) -> None:
    got_b = collect_mail(alice, ["SEQ_B"], until=count, timeout=30)
    got_a = collect_mail(bob, ["SEQ_A"], until=count, timeout=30)
    assert [m.double() for m in got_a] == [float(i) for i in range(count)]
    assert [m.double() for m in got_b] == [float(i) for i in range(count)]


def test_wrong_protocol_string_is_dropped_without_reply(caplog: pytest.LogCaptureFixture) -> None:
    with running_moosdb() as db, good_pair(db.port) as (alice, bob):
        exchange(alice, bob, 0, 10)
        with raw_connection(db.port) as sock:
            sock.sendall(b"ELKS CAN DANCE 1/1/99".ljust(32, b"\0"))
            assert read_until_closed(sock) == b""
        exchange(alice, bob, 10, 10)
        check_sequences(alice, bob, 20)
        assert "incompatible wire protocol" in reasons(db)
        assert "incompatible wire protocol" in caplog.text


def test_protocol_string_is_case_insensitive() -> None:
    with running_moosdb() as db, raw_connection(db.port) as sock:
        sock.sendall(hello_bytes("lower").replace(b"ELKS CAN'T DANCE", b"elks can't dance"))
        sock.settimeout(10)
        reader = PacketReader()
        packets: list = []
        while not packets:
            packets = reader.feed(sock.recv(4096))
        assert packets[0][0].type() == "W"


@pytest.mark.parametrize(
    "garbage, reason",
    [
        (b"\xff" * 64, "claims -1 bytes"),
        (struct.pack("<iiB", 200_000_000, 1, 0), "claims 200000000 bytes"),
        (struct.pack("<iiB", 20, 5, 0) + b"x" * 11, "cannot hold 5 messages"),
        (b"hello, is anybody there? " * 4, "claims"),
    ],
)
def test_garbage_after_handshake_drops_only_that_client(garbage: bytes, reason: str) -> None:
    with running_moosdb(max_packet_bytes=1 << 20) as db, good_pair(db.port) as (alice, bob):
        with raw_connection(db.port) as sock:
            sock.sendall(hello_bytes("vandal"))
            exchange(alice, bob, 0, 20)
            sock.sendall(garbage)
            read_until_closed(sock)
        exchange(alice, bob, 20, 20)
        check_sequences(alice, bob, 40)
        wait_until(lambda: reason in reasons(db), 5, "reason in reasons(db)")
        assert "'vandal'" in db.dropped[0][0]
        assert "vandal" not in db.client_names()


def test_empty_hello_packet_is_poisoned() -> None:
    with running_moosdb() as db, raw_connection(db.port) as sock:
        sock.sendall(PROTOCOL_BYTES + encode_packet([]))
        reply = read_until_closed(sock)
        (packet,) = PacketReader().feed(reply)
        assert packet[0].type() == "K" and "Failed to read" in packet[0].string()


def test_truncated_packet_then_silence_times_out(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING)
    with running_moosdb(client_timeout=1.0) as db, raw_connection(db.port) as sock:
        sock.sendall(hello_bytes("halfway"))
        packet = encode_packet([MoosMessage.double_msg(NOTIFY, "X", 1.0, 1.0)])
        sock.sendall(packet[: len(packet) // 2])
        read_until_closed(sock)
        assert "seconds of silence" in reasons(db)
        assert "halfway" in caplog.text


def test_no_handshake_in_time_is_dropped() -> None:
    with running_moosdb(handshake_timeout=0.5) as db, raw_connection(db.port) as sock:
        sock.sendall(PROTOCOL_BYTES[:10])
        assert read_until_closed(sock) == b""
        assert "no handshake within" in reasons(db)


def test_slow_reader_is_dropped_with_a_reason_and_others_lose_nothing() -> None:
    window = 200  # messages
    payload = "x" * 3000
    n = 6000  # 18 MB: more than the kernel's socket buffers can absorb for the lazy client
    # The outbox (4 MiB) is far below what the lazy client is sent. The publisher keeps the eager client within
    # `window` messages (0.6 MB) of what it has read, as a reader that keeps up would be, however loaded the machine:
    # only the lazy one may fill its outbox.
    with running_moosdb(stall_timeout=5.0, max_outbox_bytes=4 * 1024 * 1024) as db, \
            socket.socket(socket.AF_INET, socket.SOCK_STREAM) as lazy:
        lazy.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        lazy.connect(("127.0.0.1", db.port))
        lazy.sendall(hello_bytes("lazy"))
        lazy.sendall(encode_packet([MoosMessage(REGISTER, DOUBLE, 0, src=b"lazy", key=b"BIG", dval=0.0)]))
        with connected_comms(db.port, "eager", ["BIG"]) as eager, connected_comms(db.port, "pub") as pub:
            wait_until(lambda: "lazy" in db.client_names(), 5, "'lazy' in db.client_names()")
            got: list[MoosMessage] = []
            for i in range(n):
                assert pub.notify("BIG", f"{i}:{payload}")
                if i % 100 == 0:
                    got += collect_mail(eager, ["BIG"], until=max(0, i - window - len(got)), timeout=60)
                if i % 500 == 0:  # keep the lazy client's connection alive (until it is dropped); it never reads
                    with contextlib.suppress(OSError):
                        lazy.sendall(encode_packet([MoosMessage(TIMING, DOUBLE, key=b"_async_timing", msg_time=1.0)]))
            got += collect_mail(eager, ["BIG"], until=n - len(got), timeout=60)
            assert [int(m.string().split(":", 1)[0]) for m in got] == list(range(n))
        wait_until(lambda: "not keeping up" in reasons(db), 10, "'not keeping up' in reasons(db)")


# ---- property: random and mutated packets from several connections -------------------------------------

def _template_packets(name: str, k: int) -> list[bytes]:
    src = name.encode()
    key = f"R_{k}".encode()
    return [
        encode_packet([MoosMessage(NOTIFY, DOUBLE, 0, src=src, key=key, msg_time=1.0, dval=2.0)]),
        encode_packet([MoosMessage(NOTIFY, STRING, 1, src=src, key=key + b"S", msg_time=1.0, sval=b"abc")]),
        encode_packet([MoosMessage(REGISTER, DOUBLE, 2, src=src, key=key, msg_time=1.0, dval=0.0)]),
        encode_packet([MoosMessage(TIMING, DOUBLE, -1, key=b"_async_timing", msg_time=1.0, dval=0.0),
                       MoosMessage(NOTIFY, DOUBLE, 3, src=src, key=key, msg_time=1.0, dval=3.0)]),
    ]


@st.composite
def rogue_stream(draw: st.DrawFn, k: int) -> bytes:
    """What one misbehaving connection sends: maybe a good handshake, then good, mutated or random packets."""
    name = f"rogue{k}"
    start = draw(st.sampled_from(["good", "bad_protocol", "random"]))
    if start == "bad_protocol":
        return draw(st.binary(min_size=32, max_size=64))
    if start == "random":
        return PROTOCOL_BYTES + draw(st.binary(min_size=1, max_size=200))
    stream = hello_bytes(name)
    for _ in range(draw(st.integers(1, 5))):
        packet = bytearray(draw(st.sampled_from(_template_packets(name, k))))
        how = draw(st.sampled_from(["as_is", "flip", "truncate", "length", "append"]))
        if how == "flip":
            for pos, value in draw(st.lists(st.tuples(st.integers(0, len(packet) - 1), st.integers(0, 255)),
                                            min_size=1, max_size=3)):
                packet[pos] = value
        elif how == "truncate":
            packet = packet[: draw(st.integers(0, len(packet) - 1))]
        elif how == "length":
            struct.pack_into("<i", packet, draw(st.sampled_from([0, 4, 9])), draw(st.integers(-(2**31), 2**31 - 1)))
        elif how == "append":
            packet += draw(st.binary(min_size=1, max_size=50))
        stream += bytes(packet)
    return stream


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_random_and_mutated_packets_never_disturb_good_clients(data: st.DataObject) -> None:
    n_rogues = data.draw(st.integers(1, 4))
    streams = [data.draw(rogue_stream(k)) for k in range(n_rogues)]
    chunk_sizes = [data.draw(st.integers(1, 64)) for _ in range(n_rogues)]
    count = 150
    with running_moosdb(max_packet_bytes=1 << 16) as db, good_pair(db.port) as (alice, bob):
        rogues = [socket.create_connection(("127.0.0.1", db.port), timeout=10) for _ in range(n_rogues)]
        try:
            offsets = [0] * n_rogues
            for i in range(count):
                alice.notify("SEQ_A", float(i))
                bob.notify("SEQ_B", float(i))
                for r, sock in enumerate(rogues):
                    if offsets[r] < len(streams[r]):
                        piece = streams[r][offsets[r] : offsets[r] + chunk_sizes[r]]
                        offsets[r] += len(piece)
                        with contextlib.suppress(OSError):
                            sock.sendall(piece)
            check_sequences(alice, bob, count)
            assert {"alice", "bob"} <= set(db.client_names())
        finally:
            for sock in rogues:
                sock.close()
