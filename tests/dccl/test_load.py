"""``load`` refuses what DCCL refuses, with an error that names the message and the field."""

from __future__ import annotations

import pytest

from gateway.goby.dccl import Codec, DefinitionError
from tests.dccl.definitions import FieldDef, dccl_type, make_type
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

INT = FieldDef("a", "int32", options={"min": 0, "max": 10})


@pytest.mark.parametrize(
    ("options", "reason"),
    [
        ({"max_bytes": 32, "codec_version": 3}, r"gen\d+\.M: Missing message option `\(dccl.msg\).id`"),
        ({"id": 1, "codec_version": 3}, r"gen\d+\.M: Missing message option `\(dccl.msg\).max_bytes`"),
        ({"id": 1, "max_bytes": 32}, r"No \(dccl.msg\).codec_version set for DCCL Message 'gen\d+\.M'"),
        ({"id": 1, "max_bytes": 32, "codec_version": 4}, r"codec_version 4 is not supported"),
        ({"id": 32768, "max_bytes": 32, "codec_version": 3}, r"DCCL id 32768 is outside 0..32767"),
    ],
)
def test_message_options(options, reason):
    assert refused_match(make_type([INT], **options), reason)


def refused_match(message_type, pattern: str) -> bool:
    with pytest.raises(DefinitionError, match=pattern):
        Codec().load(message_type)
    return True


@pytest.mark.parametrize(
    ("field", "reason"),
    [
        (FieldDef("x", "double", options={"max": 1}), r"M\.x: missing \(dccl.field\).min"),
        (FieldDef("x", "int32", options={"min": 1}), r"M\.x: missing \(dccl.field\).max"),
        (FieldDef("x", "double", options={"min": 0, "max": 1, "precision": 1, "resolution": 0.1}),
         "at most one of either"),
        (FieldDef("x", "double", options={"min": 0.05, "max": 1, "resolution": 0.1}),
         r"min must be an exact multiple of \(dccl.field\).resolution"),
        (FieldDef("x", "double", options={"min": 0, "max": 1, "resolution": 0}), "resolution must be greater than 0"),
        (FieldDef("x", "int32", options={"min": 5, "max": 1}), r"max \(1\) must not be less than \(dccl.field\).min"),
        (FieldDef("x", "int32", options={"min": -1e10, "max": 1}), "min must be >= minimum of this field type"),
        (FieldDef("x", "uint32", options={"min": 0, "max": 1e10}), "max must be <= maximum of this field type"),
        (FieldDef("x", "double", options={"min": 0, "max": 1e300, "precision": 3}), "must fit in a double"),
        (FieldDef("x", "string"), r"M\.x: missing \(dccl.field\).max_length"),
        (FieldDef("x", "bytes"), r"missing \(dccl.field\).max_length"),
        (FieldDef("x", "int32", "repeated", {"min": 0, "max": 1}), r"Missing \(dccl.field\).max_repeat"),
        (FieldDef("x", "int32", "repeated", {"min": 0, "max": 1, "max_repeat": 0}), "max_repeat must not be less than 1"),
        (FieldDef("x", "int32", "repeated", {"min": 0, "max": 1, "max_repeat": 2, "min_repeat": 3}),
         r"max_repeat must not be less than \(dccl.field\).min_repeat"),
        (FieldDef("x", "int32", options={"codec": "my.codec"}),
         r"M\.x: No codec by the name `my.codec` found for type: TYPE_INT32 \(tried names: `my.codec3` `my.codec`\)"),
        (FieldDef("x", "bool", options={"codec": "dccl.time2"}), "No codec by the name `dccl.time2`"),
        (FieldDef("x", "double", options={"codec": "dccl.static"}), r"missing \(dccl.field\).static_value"),
        (FieldDef("x", "int32", options={"codec": "dccl.static", "static_value": "abc"}), "invalid static_value"),
        (FieldDef("x", "string", options={"max_length": 3, "in_head": True}), "Variable size codec used in header"),
        (FieldDef("x", "message", options={"in_head": True}, message=[FieldDef("s", "string", options={"max_length": 2})]),
         "Variable size codec used in header"),
        (FieldDef("x", "message", message=[FieldDef("y", "int32")]), r"M\.x\.y: missing \(dccl.field\).min"),
    ],
)
def test_field_options(field, reason):
    assert refused_match(dccl_type([field]), reason)


def test_oneof_is_refused_in_codec_version_3():
    fields = [FieldDef("a", "int32", options={"min": 0, "max": 1}, oneof=True),
              FieldDef("b", "int32", options={"min": 0, "max": 1}, oneof=True)]
    assert refused_match(dccl_type(fields), "DCCL Codec Version 3 does not support 'oneof' declarations")


def test_dccl4_dynamic_conditions_are_refused():
    field = FieldDef("a", "int32", options={"min": 0, "max": 1, "dynamic_conditions": "return true"})
    assert refused_match(dccl_type([field]), r"M\.a: \(dccl.field\).dynamic_conditions \(DCCL4\) are not supported")


def test_max_bytes_is_checked_against_the_largest_encoding_and_states_it():
    fields = [FieldDef(f"f{i}", "double", "required", {"min": 0, "max": 1000, "precision": 3}) for i in range(14)]
    # 14 x 20 bits = 280 bits = 35 bytes, + 1 id byte = 36
    assert refused_match(dccl_type(fields, max_bytes=32), r"Actual maximum size of message \(36B\) exceeds allowed "
                                                         r"maximum \(32B\)")
    Codec().load(dccl_type(fields, max_bytes=36))


def test_a_second_type_with_the_same_id_is_refused():
    codec = Codec()
    codec.load(USVCommand)
    with pytest.raises(DefinitionError, match="`dccl id` 126 is already in use by Message goby3_course.dccl.USVCommand"):
        codec.load(dccl_type([INT], dccl_id=126))
    codec.load(USVCommand)  # loading again is fine


def test_omit_id_messages_decode_with_their_type():
    message_type = make_type([INT], max_bytes=4, codec_version=3, omit_id=True)
    codec = Codec()
    codec.load(message_type)
    data = codec.encode(message_type(a=7))
    assert data == bytes([7 + 1]) and codec.id(message_type) is None
    assert codec.decode(data, message_type) == message_type(a=7)
    assert codec.max_size(message_type) == 1


def test_fixed_count_repeated_field_in_the_head():
    """min_repeat == max_repeat makes a repeated field fixed-size, so DCCL allows it in the head."""
    message_type = dccl_type([
        FieldDef("h", "int32", "repeated", {"min": 0, "max": 7, "min_repeat": 2, "max_repeat": 2, "in_head": True}),
        FieldDef("b", "int32", "required", {"min": 0, "max": 255}),
    ])
    codec = Codec()
    codec.load(message_type)
    msg = message_type(h=[5, 6], b=200)
    data = codec.encode(msg)
    assert data == bytes([10 << 1, 5 | 6 << 3, 200])  # id; count prefix 0 bits, 3 + 3 bits in the head; body
    assert codec.decode(data) == msg
