"""dccl/option_extensions.proto has DCCL's own numbers, types and defaults, so descriptors mean the same here
and in C++ (Goby ships FileDescriptorProtos with intervehicle data; DCCL reads options by number)."""

from __future__ import annotations

import struct

import pytest
from google.protobuf import descriptor_pb2
from google.protobuf.descriptor import FieldDescriptor as F

from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as dccl_options
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

# GobySoft/dccl src/option_extensions.proto at d0358a1 (4.x HEAD): name -> (number, type, default or None).
DCCL_FIELD_OPTIONS = {
    "codec": (1, F.TYPE_STRING, "dccl.default2"),
    "omit": (2, F.TYPE_BOOL, False),
    "in_head": (3, F.TYPE_BOOL, False),
    "precision": (4, F.TYPE_INT32, 0),
    "min": (5, F.TYPE_DOUBLE, None),
    "max": (6, F.TYPE_DOUBLE, None),
    "num_days": (7, F.TYPE_UINT32, 1),
    "static_value": (8, F.TYPE_STRING, ""),
    "max_length": (9, F.TYPE_UINT32, None),
    "max_repeat": (10, F.TYPE_UINT32, None),
    "packed_enum": (11, F.TYPE_BOOL, True),
    "resolution": (12, F.TYPE_DOUBLE, 1.0),
    "min_repeat": (13, F.TYPE_UINT32, 0),
    "description": (20, F.TYPE_STRING, None),
    "units": (30, F.TYPE_MESSAGE, None),
    "dynamic_conditions": (40, F.TYPE_MESSAGE, None),
}
DCCL_UNITS = {
    "base_dimensions": (1, F.TYPE_STRING, None),
    "derived_dimensions": (2, F.TYPE_STRING, None),
    "system": (3, F.TYPE_STRING, "si"),
    "relative_temperature": (4, F.TYPE_BOOL, False),
    "unit": (5, F.TYPE_STRING, None),
    "prefix": (6, F.TYPE_STRING, None),
}
DCCL_CONDITIONS = {
    "required_if": (1, F.TYPE_STRING, None),
    "omit_if": (2, F.TYPE_STRING, None),
    "only_if": (3, F.TYPE_STRING, None),
    "min": (10, F.TYPE_STRING, None),
    "max": (11, F.TYPE_STRING, None),
}
DCCL_MESSAGE_OPTIONS = {
    "id": (1, F.TYPE_INT32, None),
    "max_bytes": (2, F.TYPE_UINT32, None),
    "codec": (3, F.TYPE_STRING, None),
    "codec_group": (4, F.TYPE_STRING, None),
    "codec_version": (5, F.TYPE_INT32, None),
    "omit_id": (10, F.TYPE_BOOL, False),
    "unit_system": (30, F.TYPE_STRING, "si"),
}


def declared(descriptor) -> dict:
    return {
        f.name: (f.number, f.type, f.default_value if f.has_default_value else None)
        for f in descriptor.fields
    }


@pytest.mark.parametrize(
    ("descriptor", "expected"),
    [
        (dccl_options.DCCLFieldOptions.DESCRIPTOR, DCCL_FIELD_OPTIONS),
        (dccl_options.DCCLFieldOptions.Units.DESCRIPTOR, DCCL_UNITS),
        (dccl_options.DCCLFieldOptions.Conditions.DESCRIPTOR, DCCL_CONDITIONS),
        (dccl_options.DCCLMessageOptions.DESCRIPTOR, DCCL_MESSAGE_OPTIONS),
    ],
    ids=["DCCLFieldOptions", "Units", "Conditions", "DCCLMessageOptions"],
)
def test_every_option_has_dccls_number_type_and_default(descriptor, expected):
    assert declared(descriptor) == expected


def test_extensions_are_dccl_field_and_msg_at_1012():
    assert (dccl_options.field.full_name, dccl_options.field.number) == ("dccl.field", 1012)
    assert (dccl_options.msg.full_name, dccl_options.msg.number) == ("dccl.msg", 1012)
    assert dccl_options.field.containing_type.full_name == "google.protobuf.FieldOptions"
    assert dccl_options.msg.containing_type.full_name == "google.protobuf.MessageOptions"
    assert dccl_options.DCCLFieldOptions.DESCRIPTOR.extension_ranges == [(1000, 536870912)]


def wire_fields(data: bytes) -> list[tuple[int, object]]:
    """(field number, value) pairs of raw protobuf bytes: varints as ints, fixed64 as doubles, others as bytes."""
    out, i = [], 0
    while i < len(data):
        key, i = varint(data, i)
        number, wire = key >> 3, key & 7
        if wire == 0:
            value, i = varint(data, i)
        elif wire == 1:
            value, i = struct.unpack_from("<d", data, i)[0], i + 8
        elif wire == 2:
            length, i = varint(data, i)
            value, i = data[i:i + length], i + length
        else:
            assert wire == 5
            value, i = data[i:i + 4], i + 4
        out.append((number, value))
    return out


def varint(data: bytes, i: int) -> tuple[int, int]:
    shift = value = 0
    while True:
        byte = data[i]
        i += 1
        value |= (byte & 0x7F) << shift
        shift += 7
        if not byte & 0x80:
            return value, i


def dccl_part(options_bytes: bytes) -> dict[int, object]:
    """The DCCL option fields inside a serialized FieldOptions/MessageOptions, by DCCL field number."""
    (payload,) = [value for number, value in wire_fields(options_bytes) if number == 1012]
    return dict(wire_fields(payload))


def test_usv_command_descriptor_carries_dccls_numbers_on_the_wire():
    """Serialise USVCommand's file as a FileDescriptorProto and read the raw option bytes back: the numbers
    are the ones a C++ DCCL reading that descriptor looks for."""
    file_proto = descriptor_pb2.FileDescriptorProto()
    USVCommand.DESCRIPTOR.file.CopyToProto(file_proto)
    parsed = descriptor_pb2.FileDescriptorProto.FromString(file_proto.SerializeToString())
    (message,) = [m for m in parsed.message_type if m.name == "USVCommand"]

    msg_options = dccl_part(message.options.SerializeToString())
    assert msg_options == {5: 3, 1: 126, 2: 32, 30: b"si"}  # codec_version, id, max_bytes, unit_system

    by_name = {f.name: dccl_part(f.options.SerializeToString()) for f in message.field if f.HasField("options")}
    assert by_name["polygon_sides"] == {5: 3.0, 6: 10.0}  # min, max
    assert by_name["polygon_radius"] == {5: 100.0, 6: 2000.0, 4: (1 << 64) - 1}  # min, max, precision -1
    time_options = by_name["time"]
    assert time_options[1] == b"dccl.time2"  # codec
    assert dict(wire_fields(time_options[30])) == {2: b"time"}  # units.derived_dimensions
    assert "desired_state" not in by_name
