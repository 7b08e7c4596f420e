"""The codec against the golden packets of the spec (§4), both ways, plus round trips and malformed input."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gateway.moos.codec import (
    PROTOCOL_BYTES,
    PacketReader,
    decode_packet,
    encode_message,
    encode_packet,
    message_size,
)
from gateway.moos.errors import ProtocolError
from gateway.moos.message import BINARY, DOUBLE, STRING, MoosMessage

T0 = 1700000000.5

GOLDEN = {
    "hello_sync": (
        "4300000001000000003a000000ffffffff69530000000000000000000000000000000000002040fc54d941000000000000f0bf"
        "000000000000f0bf0400000061707031",
        MoosMessage(b"i", STRING, -1, key=b"", msg_time=T0, sval=b"app1"),
    ),
    "hello_async": (
        "4f000000010000000046000000ffffffff69530000000000000000000000000c0000006173796e6368726f6e6f757300002040"
        "fc54d941000000000000f0bf000000000000f0bf0400000061707031",
        MoosMessage(b"i", STRING, -1, key=b"asynchronous", msg_time=T0, sval=b"app1"),
    ),
    "null_keepalive": (
        "4300000001000000003a000000ffffffff2e440400000061707031000000000000000000000000000000000000f0bf0000000000"
        "00f0bf000000000000f0bf00000000",
        MoosMessage(b".", DOUBLE, -1, src=b"app1"),
    ),
    "register_x": (
        "4400000001000000003b00000000000000524404000000617070310000000000000000010000005800002040fc54d94100000000"
        "0000e03f000000000000f0bf00000000",
        MoosMessage(b"R", DOUBLE, 0, src=b"app1", key=b"X", msg_time=T0, dval=0.5),
    ),
    "timing": (
        "4c000000010000000043000000ffffffff54440000000000000000000000000d0000005f6173796e635f74696d696e670000"
        "2040fc54d9410000000000000000000000000000f0bf00000000",
        MoosMessage(b"T", DOUBLE, -1, key=b"_async_timing", msg_time=T0, dval=0.0),
    ),
}

# The 88-byte WELCOME captured from the real DB (spec §4), reassembled from its annotated dump.
WELCOME_HEX = (
    "58000000" "01000000" "00"
    "4f000000" "ffffffff" "57" "44"
    "00000000"
    "0b000000" "686f73746e616d653d766d"
    "02000000" "2331"
    "00000000"
    "3f3b941598c0da41"
    "0000000088acb93f"
    "000000000000f0bf"
    "0c000000" "6173796e6368726f6e6f7573"
)


@pytest.mark.parametrize("name", sorted(GOLDEN))
def test_golden_packets_encode_exactly(name: str) -> None:
    wire, msg = GOLDEN[name]
    assert encode_packet([msg]).hex() == wire


@pytest.mark.parametrize("name", sorted(GOLDEN))
def test_golden_packets_decode_exactly(name: str) -> None:
    wire, msg = GOLDEN[name]
    assert decode_packet(bytes.fromhex(wire)) == [msg]


def test_welcome_from_the_real_db_decodes() -> None:
    data = bytes.fromhex(WELCOME_HEX)
    assert len(data) == 88
    (welcome,) = decode_packet(data)
    assert welcome.type() == "W" and welcome.is_double()
    assert welcome.source_aux() == "hostname=vm"
    assert welcome.community() == "#1"
    assert welcome.string() == "asynchronous"
    assert welcome.double() == pytest.approx(0.1003, abs=1e-4)
    assert welcome.double_aux() == -1.0
    assert welcome.time() == pytest.approx(1795317846.316, abs=1e-3)
    assert encode_packet([welcome]) == data


def test_default_message_is_54_bytes_and_null_packet_63() -> None:
    msg = MoosMessage()
    assert message_size(msg) == 54 == len(encode_message(msg))
    assert len(encode_packet([msg])) == 63


def test_protocol_string_is_32_bytes_nul_padded() -> None:
    assert len(PROTOCOL_BYTES) == 32
    assert PROTOCOL_BYTES.startswith(b"ELKS CAN'T DANCE 2/8/10\0")
    assert PROTOCOL_BYTES.rstrip(b"\0") == b"ELKS CAN'T DANCE 2/8/10"


field_bytes = st.binary(max_size=40)
messages = st.builds(
    MoosMessage,
    msg_type=st.sampled_from([b"N", b"R", b"U", b"*", b"/", b"Q", b"T", b".", b"i", b"W", b"K"]),
    data_type=st.sampled_from([DOUBLE, STRING, BINARY]),
    msg_id=st.integers(-(2**31), 2**31 - 1),
    src=field_bytes,
    aux=field_bytes,
    community=field_bytes,
    key=field_bytes,
    msg_time=st.floats(allow_nan=False),
    dval=st.floats(allow_nan=False),
    dval2=st.floats(allow_nan=False),
    sval=st.binary(max_size=300),
)


@given(st.lists(messages, max_size=8))
def test_any_packet_round_trips(batch: list[MoosMessage]) -> None:
    wire = encode_packet(batch)
    assert struct.unpack_from("<iiB", wire) == (len(wire), len(batch), 0)
    assert decode_packet(wire) == batch


@given(st.lists(messages, min_size=1, max_size=5), st.data())
def test_reader_reassembles_packets_split_anywhere(batch: list[MoosMessage], data: st.DataObject) -> None:
    stream = b"".join(encode_packet([m]) for m in batch)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=6)))
    reader = PacketReader()
    got = []
    last = 0
    for cut in [*cuts, len(stream)]:
        got.extend(reader.feed(stream[last:cut]))
        last = cut
    assert got == [[m] for m in batch]
    assert reader.pending_bytes == 0


def test_binary_payload_keeps_nul_bytes() -> None:
    payload = bytes(range(256)) * 4
    msg = MoosMessage.binary_msg(b"N", "BLOB", payload, 1.0)
    (back,) = decode_packet(encode_packet([msg]))
    assert back.is_binary() and back.is_string() and back.binary_data() == payload
    assert back.binary_data_size() == 1024


def test_utf8_and_undecodable_strings_round_trip_through_str() -> None:
    msg = MoosMessage.string_msg(b"N", "GRÜSSE", "日本語 \udcff", 2.0)
    (back,) = decode_packet(encode_packet([msg]))
    assert back.key() == "GRÜSSE"
    assert back.string() == "日本語 \udcff"
    assert back.raw_sval.endswith(b"\xff")


@pytest.mark.parametrize(
    "mutate, reason",
    [
        (lambda w: w[:-1], "does not fit|says"),
        (lambda w: struct.pack("<i", 4) + w[4:], "claims 4 bytes"),
        (lambda w: w[:4] + struct.pack("<i", 2) + w[8:], "cannot hold 2 messages"),
        (lambda w: w[:4] + struct.pack("<i", -1) + w[8:], "cannot hold -1"),
        (lambda w: w[:9] + struct.pack("<i", 1000) + w[13:], "claims 1000 bytes"),
        (lambda w: w[:18] + struct.pack("<i", 10_000) + w[22:], "overruns"),
        (lambda w: w[:9] + struct.pack("<i", 60) + w[13:], "overruns|truncated|fields take|remain"),
    ],
)
def test_malformed_packets_raise_protocol_error(mutate, reason: str) -> None:
    wire = bytes.fromhex(GOLDEN["register_x"][0])
    bad = mutate(wire)
    with pytest.raises(ProtocolError, match=reason):
        reader = PacketReader()
        packets = reader.feed(bad)
        if not packets:
            decode_packet(bad)


def test_oversized_header_rejected_before_body_arrives() -> None:
    reader = PacketReader(max_packet_bytes=1024)
    with pytest.raises(ProtocolError, match="claims 2000 bytes"):
        reader.feed(struct.pack("<iiB", 2000, 1, 0))


def test_good_packets_before_a_bad_one_are_kept_on_the_error() -> None:
    good = encode_packet([MoosMessage.double_msg(b"N", "A", 1.0, 1.0)])
    reader = PacketReader()
    with pytest.raises(ProtocolError) as info:
        reader.feed(good + struct.pack("<iiB", 3, 0, 0))
    assert len(info.value.packets) == 1 and info.value.packets[0][0].key() == "A"


def test_stray_bytes_after_messages_are_an_error() -> None:
    wire = bytearray(encode_packet([MoosMessage()]))
    wire += b"xx"
    struct.pack_into("<i", wire, 0, len(wire))
    with pytest.raises(ProtocolError, match="stray bytes"):
        decode_packet(bytes(wire))
