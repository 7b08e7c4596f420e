"""Groups and marshalling schemes against Goby's definitions (spec §4.1, §4.2)."""

from __future__ import annotations

import pytest

from gateway.goby.dccl import Codec as DcclCodec
from gateway.goby.portal import Group, InvalidGroupError, MarshallingError, Scheme
from gateway.goby.portal.group import INVALID_NUMERIC_GROUP, as_group, check_named
from gateway.goby.portal.marshalling import (
    default_scheme,
    interprocess_scheme,
    is_dccl,
    parse,
    parse_dynamic,
    scheme_from_string,
    scheme_to_string,
    serialize,
    type_name,
)
from tests.protobuf.sample_messages_pb2 import DCCLSample, Sample
from translators.usv.protobuf.command_dccl_pb2 import USVCommand


def test_group_wire_strings() -> None:
    assert str(Group("widget1", 1)) == "widget1;1"
    assert str(Group("widget1")) == "widget1"
    assert str(Group(numeric=7)) == "7"
    assert str(Group()) == str(INVALID_NUMERIC_GROUP)


def test_group_equality_follows_goby() -> None:
    assert Group("a", 1) == Group("a", 1)
    assert Group("a", 1) != Group("a", 2)
    assert Group("a") != Group("b")
    assert Group("", 3) == Group("x", 3)  # one side has no name: numerics decide
    assert hash(Group("widget1", 1)) == hash("widget1;1")


def test_group_parse_round_trip() -> None:
    for text in ("nav", "widget1;1", "goby::middleware::frontseat::node_status", "a;b"):
        assert str(Group.parse(text)) == text
    assert as_group("w;2") == Group("w", 2)


def test_group_validity() -> None:
    with pytest.raises(InvalidGroupError, match="non-empty string for use on InterProcess"):
        check_named(Group(numeric=3), "InterProcess")
    with pytest.raises(InvalidGroupError):
        Group("x", 2**32 - 1)


def test_scheme_ids_and_names() -> None:
    assert (Scheme.CSTR, Scheme.PROTOBUF, Scheme.DCCL, Scheme.JSON) == (0, 1, 2, 7)
    assert (Scheme.ALL_SCHEMES, Scheme.NULL_SCHEME, Scheme.CXX_OBJECT, Scheme.MAVLINK) == (-2, -1, 5, 6)
    assert scheme_to_string(1) == "PROTOBUF"
    assert scheme_to_string(1000) == "1000"
    assert scheme_from_string("DCCL") == 2
    assert scheme_from_string("1000") == 1000
    with pytest.raises(MarshallingError, match="unknown marshalling scheme 'BOGUS'"):
        scheme_from_string("BOGUS")


def test_protobuf_marshalling() -> None:
    assert default_scheme(Sample) == Scheme.PROTOBUF
    assert type_name(Sample, Scheme.PROTOBUF) == "goby.test.zeromq.protobuf.Sample"
    msg = Sample(a=3, temperature=12.5)
    data = serialize(msg, Scheme.PROTOBUF)
    assert data == msg.SerializeToString()
    assert parse(data, Scheme.PROTOBUF, Sample) == msg
    assert parse_dynamic(data, Scheme.PROTOBUF, "goby.test.zeromq.protobuf.Sample") == msg
    assert parse_dynamic(data, Scheme.PROTOBUF, "no.such.Type") == data  # unknown type: raw bytes
    with pytest.raises(MarshallingError, match="cannot parse goby.test.zeromq.protobuf.Sample"):
        parse(b"\xff\xff\xff", Scheme.PROTOBUF, Sample)


def test_cstr_marshalling_keeps_goby_trailing_nul() -> None:
    assert default_scheme(str) == Scheme.CSTR
    assert type_name(str, Scheme.CSTR) == "CSTR"
    assert serialize("HI", Scheme.CSTR) == b"HI\0"
    assert parse(b"HI\0", Scheme.CSTR, str) == "HI"
    with pytest.raises(MarshallingError):
        default_scheme(dict)


def test_dccl_messages_default_to_dccl_but_travel_as_protobuf_on_interprocess() -> None:
    assert is_dccl(DCCLSample) and not is_dccl(Sample)
    assert default_scheme(DCCLSample) == Scheme.DCCL
    assert interprocess_scheme(DCCLSample) == Scheme.PROTOBUF
    assert interprocess_scheme(str) == Scheme.CSTR


def test_dccl_marshalling_is_exactly_the_dccl_bytes() -> None:
    """Scheme DCCL: the payload is the DCCL encoding (the C++ codec's bytes for this USVCommand: fc80380100)."""
    codec = DcclCodec(clock=lambda: 1700000000)
    command = USVCommand(time=1700000000, desired_state=USVCommand.WAYPOINTS)
    data = serialize(command, Scheme.DCCL, codec)  # loads the type on first use, as Goby's serializer does
    assert data.hex() == "fc80380100"
    assert parse(data, Scheme.DCCL, USVCommand, codec) == command
    assert parse_dynamic(data, Scheme.DCCL, "goby3_course.dccl.USVCommand", codec) == command
    assert parse_dynamic(data, Scheme.DCCL, "goby3_course.dccl.USVCommand") == data  # no codec: raw bytes
    with pytest.raises(MarshallingError, match="cannot DCCL-decode goby3_course.dccl.USVCommand: .*truncated"):
        parse(data[:3], Scheme.DCCL, USVCommand, codec)
    with pytest.raises(MarshallingError, match="cannot DCCL-encode goby.test.zeromq.protobuf.Sample: .*Missing "
                                               "message option `\\(dccl.msg\\).id`"):
        serialize(Sample(a=1), Scheme.DCCL, codec)
