"""Message definitions built at run time (FileDescriptorProto -> class), for load-error and property tests."""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from google.protobuf.message import Message

from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as dccl_options

FDP = descriptor_pb2.FieldDescriptorProto
LABELS = {"optional": FDP.LABEL_OPTIONAL, "required": FDP.LABEL_REQUIRED, "repeated": FDP.LABEL_REPEATED}
TYPES = {
    "double": FDP.TYPE_DOUBLE, "float": FDP.TYPE_FLOAT, "int32": FDP.TYPE_INT32, "int64": FDP.TYPE_INT64,
    "uint32": FDP.TYPE_UINT32, "uint64": FDP.TYPE_UINT64, "sint32": FDP.TYPE_SINT32, "bool": FDP.TYPE_BOOL,
    "string": FDP.TYPE_STRING, "bytes": FDP.TYPE_BYTES, "enum": FDP.TYPE_ENUM, "message": FDP.TYPE_MESSAGE,
}
_counter = itertools.count()


@dataclass
class FieldDef:
    """One field: name, type (a key of ``TYPES``), label, DCCL options; ``enum`` values or ``message`` fields."""

    name: str
    type: str
    label: str = "optional"
    options: dict[str, Any] = field(default_factory=dict)
    enum: list[tuple[str, int]] = field(default_factory=list)
    message: list[FieldDef] = field(default_factory=list)
    oneof: bool = False


def _add_message(file_proto: descriptor_pb2.FileDescriptorProto, container: Any, name: str,
                 fields: list[FieldDef], package: str, msg_options: dict[str, Any] | None) -> None:
    message = container.add(name=name)
    if msg_options is not None:
        options = message.options.Extensions[dccl_options.msg]
        for key, value in msg_options.items():
            setattr(options, key, value)
    for number, spec in enumerate(fields, start=1):
        proto = message.field.add(name=spec.name, number=number, type=TYPES[spec.type], label=LABELS[spec.label])
        if spec.type == "enum":
            enum_name = f"E_{spec.name}"
            enum = message.enum_type.add(name=enum_name)
            for value_name, value in spec.enum:
                enum.value.add(name=f"{spec.name.upper()}_{value_name}", number=value)
            proto.type_name = f".{package}.{name}.{enum_name}"
        if spec.type == "message":
            sub_name = f"M_{spec.name}"
            _add_message(file_proto, message.nested_type, sub_name, spec.message, f"{package}.{name}", None)
            proto.type_name = f".{package}.{name}.{sub_name}"
        if spec.oneof:
            if not message.oneof_decl:
                message.oneof_decl.add(name="choice")
            proto.oneof_index = 0
        options = proto.options.Extensions[dccl_options.field]
        for key, value in spec.options.items():
            if key == "units":
                options.units.derived_dimensions = value
            elif key == "dynamic_conditions":
                options.dynamic_conditions.required_if = value
            else:
                setattr(options, key, value)


def make_type(fields: list[FieldDef], **msg_options: Any) -> type[Message]:
    """A message class named ``gen<N>.M`` in a pool of its own, with ``(dccl.msg)`` options ``msg_options``."""
    package = f"gen{next(_counter)}"
    file_proto = descriptor_pb2.FileDescriptorProto(name=f"{package}.proto", package=package, syntax="proto2")
    _add_message(file_proto, file_proto.message_type, "M", fields, package, msg_options)
    pool = descriptor_pool.DescriptorPool()
    pool.Add(file_proto)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(f"{package}.M"))


def dccl_type(fields: list[FieldDef], dccl_id: int = 10, max_bytes: int = 64, **more: Any) -> type[Message]:
    """``make_type`` with the options every DCCL message needs."""
    return make_type(fields, id=dccl_id, max_bytes=max_bytes, codec_version=3, **more)
