"""Bytes that are not a message give a named error, never a wrong message and never a stray exception."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gateway.goby.dccl import (
    Codec,
    DcclError,
    DecodeError,
    TrailingBytesError,
    TruncatedError,
    UnknownIdError,
)
from tests.dccl.conftest import COURSE_TYPES
from tests.protobuf import dccl_test_pb2 as pb
from translators.trail.protobuf.health_status_pb2 import HealthStatus
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand, USVCommand

NAV = NavigationReport(vehicle=3, time=1700000000, x=1.5, y=-2.5, z=-10, speed_over_ground=1.5, heading=90,
                       type=NavigationReport.USV)


@pytest.fixture(scope="module")
def codec() -> Codec:
    codec = Codec(clock=lambda: 1700000000)
    for message_type in (*COURSE_TYPES, pb.Everything, pb.Layout, pb.Subscription):
        codec.load(message_type)
    return codec


def test_empty_and_short_ids(codec):
    with pytest.raises(TruncatedError, match="no bytes to read a DCCL id from"):
        codec.decode(b"")
    with pytest.raises(TruncatedError, match="announces a two-byte id"):
        codec.decode(b"\xb1")
    with pytest.raises(TruncatedError):
        codec.id_from_encoded(b"")


def test_unknown_id(codec):
    with pytest.raises(UnknownIdError, match="DCCL id 100 has not been loaded") as info:
        codec.decode(bytes([100 << 1]) + bytes(12))
    assert info.value.dccl_id == 100


def test_truncated_fixed_size_message(codec):
    data = codec.encode(NAV)
    with pytest.raises(TruncatedError, match=r"goby3_course.dccl.NavigationReport needs 13 bytes but only 12 are "
                                             r"there \(truncated\)"):
        codec.decode(data[:-1])


def test_truncated_variable_size_message(codec):
    sub = pb.Subscription(api_version=1, action=1, dccl_id=124, group=1)
    sub.header.src = 1
    sub.header.dest.extend([2, 3, 4])
    data = codec.encode(sub)
    for cut in range(1, len(data)):
        with pytest.raises(TruncatedError):
            codec.decode(data[:cut])


def test_trailing_bytes_are_refused_by_decode_and_returned_by_decode_prefix(codec):
    data = codec.encode(NAV)
    with pytest.raises(TrailingBytesError, match="NavigationReport uses 13 byte\\(s\\) but 14 were given "
                                                 "\\(1 trailing\\)"):
        codec.decode(data + b"\x00")
    assert codec.decode_prefix(data + b"\xab\xcd") == (NAV, b"\xab\xcd")


def test_decode_with_the_wrong_type(codec):
    with pytest.raises(DecodeError, match="Received message with id 124 but decode was called with "
                                          "goby3_course.dccl.USVCommand \\(id 126\\)"):
        codec.decode(codec.encode(NAV), USVCommand)


def test_packed_frame_of_several_messages(codec):
    messages = [NAV, USVCommand(time=1700000000, desired_state=1), AUVCommand(time=1700000001, desired_state=2),
                HealthStatus(state=HealthStatus.GOOD, timestamp=1700000000000000), NAV]
    frame = b"".join(codec.encode(m) for m in messages)
    assert codec.decode_all(frame) == messages
    with pytest.raises(UnknownIdError) as info:
        codec.decode_all(frame + b"\x02\x00")
    assert "(message 6 of the packed data, at byte 39)" in info.value.__notes__


def test_structurally_impossible_lengths_are_refused(codec):
    prefix = codec.encode(pb.Everything())[:2]
    # text is the 11th body field: find its bit position from the layout and write length 15 (> max_length 10)
    position = sum(f.max_size for f in codec.compiled(pb.Everything).body[:10])
    body = (15 << position).to_bytes(60, "little")
    with pytest.raises(DecodeError, match="Everything.text: length 15 exceeds max_length 10"):
        codec.decode_prefix(prefix + body)


def test_text_that_is_not_utf8_is_refused(codec):
    prefix = codec.encode(pb.Everything())[:2]
    position = sum(f.max_size for f in codec.compiled(pb.Everything).body[:10])
    body = ((1 | (0xFF << 4)) << position).to_bytes(60, "little")
    with pytest.raises(DecodeError, match="Everything.text: the decoded bytes are not UTF-8 text"):
        codec.decode_prefix(prefix + body)


LOADED_IDS = [3, 20, 124, 125, 126, 127]


@settings(max_examples=500, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(head=st.sampled_from([bytes([i << 1]) for i in LOADED_IDS] + [b"\xb1\x04", b""]), tail=st.binary(max_size=64))
def test_random_bytes_decode_or_raise_the_codecs_own_error(codec, head, tail):
    data = head + tail
    try:
        messages = codec.decode_all(data)
    except DcclError:
        return
    assert all(codec.id(type(m)) in LOADED_IDS + [600] for m in messages)
