"""Wire identifiers: golden vectors from spec §4.3 and malformed frames."""

from __future__ import annotations

import pytest

from gateway.goby.portal import IdentifierError
from gateway.goby.portal.identifier import decode_frame, encode_frame, make_identifier, thread_id, type_prefix


def test_identifier_forms_match_goby() -> None:
    group = "goby::middleware::frontseat::node_status"
    tname = "goby.middleware.frontseat.protobuf.NodeStatus"
    ident = make_identifier(group, 1, tname, pid=12345, thread="9a3f0c2b11d4e7f8")
    assert ident == f"/{group}/PROTOBUF/{tname}/12345/9a3f0c2b11d4e7f8/"
    assert type_prefix(group, 1, tname) == f"/{group}/PROTOBUF/{tname}/"
    frame = encode_frame(ident, b"\x08\x01")
    assert frame == (f"/{group}/PROTOBUF/{tname}/12345/9a3f0c2b11d4e7f8/".encode() + b"\0\x08\x01")


def test_decode_round_trip_and_payload_with_nuls() -> None:
    frame = encode_frame(make_identifier("widget1;1", 0, "CSTR", pid=42, thread="ab"), b"x\0y\0")
    ident, payload = decode_frame(frame)
    assert (ident.group, ident.scheme, ident.type_name, ident.pid, ident.thread) == ("widget1;1", 0, "CSTR", 42, 0xAB)
    assert payload == b"x\0y\0"
    assert ident.prefix == b"/widget1;1/CSTR/CSTR/"


def test_thread_id_is_short_lowercase_hex() -> None:
    tid = thread_id()
    assert 0 < len(tid) <= 16 and tid == tid.lower()
    int(tid, 16)
    assert thread_id(1) != thread_id(2)


@pytest.mark.parametrize(
    "frame, why",
    [
        (b"/g/PROTOBUF/T/1/ab/", "no NUL"),
        (b"/g/PROTOBUF/T/1/\0x", "form"),
        (b"g/PROTOBUF/T/1/ab/\0x", "form"),
        (b"/g/NOPE/T/1/ab/\0x", "malformed identifier"),
        (b"/g/PROTOBUF/T/pid/ab/\0x", "malformed identifier"),
        (b"/g/PROTOBUF/T/1/zz/\0x", "malformed identifier"),
        (b"/g/PROTOBUF/T/1/" + b"a" * 17 + b"/\0x", "longer than 16"),
        (b"/\xff/PROTOBUF/T/1/ab/\0x", "UTF-8"),
    ],
)
def test_malformed_frames_raise_named_errors(frame: bytes, why: str) -> None:
    with pytest.raises(IdentifierError, match=why):
        decode_frame(frame)
