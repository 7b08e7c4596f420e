"""Protobuf descriptor access typed as it holds at run time, for code that handles any message type.

Why: types-protobuf is looser than the runtime in three places this project meets everywhere.
``Message.DESCRIPTOR`` is typed ``Descriptor | google._upb._message.Descriptor``: two classes in the stubs, one
at run time (the upb descriptor passes ``isinstance(d, Descriptor)``).  ``FieldDescriptor.enum_type`` and
``message_type`` are optional: None only for fields of other types.  ``Message.FindInitializationErrors`` is
missing.  Stating each fact once here lets the rest of the code be checked against the real types.  Generated
classes need none of this: their ``*_pb2.pyi`` stubs type ``DESCRIPTOR`` exactly.
"""

from __future__ import annotations

from typing import cast

from google.protobuf.descriptor import Descriptor, EnumDescriptor, FieldDescriptor
from google.protobuf.message import Message


def descriptor_of(message: Message | type[Message]) -> Descriptor:
    """``message.DESCRIPTOR`` of a message or message class of any type."""
    return cast(Descriptor, message.DESCRIPTOR)


def enum_type_of(field: FieldDescriptor) -> EnumDescriptor:
    """The enum type of an enum field; TypeError for a field of another type."""
    enum_type = field.enum_type
    if enum_type is None:
        raise TypeError(f"{field.full_name} is not an enum field")
    return enum_type


def message_type_of(field: FieldDescriptor) -> Descriptor:
    """The message type of a message (or group) field; TypeError for a field of another type."""
    message_type = field.message_type
    if message_type is None:
        raise TypeError(f"{field.full_name} is not a message field")
    return message_type


def initialization_errors(message: Message) -> list[str]:
    """Paths of the required fields ``message`` lacks (``Message.FindInitializationErrors``)."""
    errors: list[str] = message.FindInitializationErrors()  # type: ignore[attr-defined]  # not in types-protobuf
    return errors
