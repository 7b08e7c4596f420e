"""DCCL bounds for messages that carry DCCL options: refuse what DCCL could not send, round what it would round.

Why: DCCL encodes an out-of-range optional field as "not set" without a word, so a USVCommand with radius 5000
would reach the USV as a polygon of radius 0. We refuse such values with an error that names the field, the value
and the bounds, before anything reaches MOOS. The bounds are read from the message's own ``(dccl.field)`` options,
so a changed .proto changes the check with it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TypeVar

from google.protobuf.descriptor import Descriptor, FieldDescriptor
from google.protobuf.message import Message

from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as dccl_options
from translators.errors import TranslatorError

_DEFAULT_CODECS = {"dccl.default2", "dccl.default3", "dccl.default4"}
_NUMERIC_TYPES = {
    FieldDescriptor.TYPE_DOUBLE,
    FieldDescriptor.TYPE_FLOAT,
    FieldDescriptor.TYPE_INT32,
    FieldDescriptor.TYPE_INT64,
    FieldDescriptor.TYPE_UINT32,
    FieldDescriptor.TYPE_UINT64,
    FieldDescriptor.TYPE_SINT32,
    FieldDescriptor.TYPE_SINT64,
    FieldDescriptor.TYPE_FIXED32,
    FieldDescriptor.TYPE_FIXED64,
    FieldDescriptor.TYPE_SFIXED32,
    FieldDescriptor.TYPE_SFIXED64,
}


class DcclBoundsError(TranslatorError, ValueError):
    """A message that DCCL could not carry as given: a field outside its bounds, or a required field unset."""


@dataclass(frozen=True)
class FieldBounds:
    """The range and step DCCL's default numeric codec gives one field."""

    name: str
    minimum: float
    maximum: float
    resolution: float

    def quantize(self, value: float) -> float:
        """Round to the nearest multiple of the resolution, halves up (DCCL's ``round``/``quantize``)."""
        return math.floor(value / self.resolution + 0.5) * self.resolution

    def describe(self) -> str:
        step = f", in steps of {self.resolution:g}" if self.resolution != 1 else ""
        return f"[{self.minimum:g}, {self.maximum:g}]{step}"


def dccl_message_options(descriptor: Descriptor) -> dccl_options.DCCLMessageOptions:
    """The ``(dccl.msg)`` options of a message type (empty if it has none)."""
    return descriptor.GetOptions().Extensions[dccl_options.msg]


def field_bounds(field: FieldDescriptor) -> FieldBounds | None:
    """The bounds of a numeric field with ``(dccl.field)`` min and max under a default codec, else None."""
    options = field.GetOptions().Extensions[dccl_options.field]
    if field.type not in _NUMERIC_TYPES or options.codec not in _DEFAULT_CODECS:
        return None
    if not (options.HasField("min") and options.HasField("max")):
        return None
    if options.HasField("precision"):
        resolution = 10.0 ** (-options.precision)
    else:
        resolution = options.resolution
    if field.type not in (FieldDescriptor.TYPE_DOUBLE, FieldDescriptor.TYPE_FLOAT):
        resolution = max(resolution, 1.0)  # an integer cannot be finer than 1
    return FieldBounds(field.name, options.min, options.max, resolution)


def _checked_value(bounds: FieldBounds, value: float, where: str, field: FieldDescriptor) -> float:
    rounded = bounds.quantize(value)
    if math.isnan(value) or not bounds.minimum <= rounded <= bounds.maximum:
        raise DcclBoundsError(f"{where}{field.name}={value:g} is outside its DCCL bounds {bounds.describe()}")
    if field.type in (FieldDescriptor.TYPE_DOUBLE, FieldDescriptor.TYPE_FLOAT):
        return rounded
    return int(round(rounded))


def _check_in_place(msg: Message, where: str) -> None:
    for field, value in msg.ListFields():
        if field.type == FieldDescriptor.TYPE_MESSAGE:
            children = value if field.is_repeated else [value]
            for child in children:
                _check_in_place(child, f"{where}{field.name}.")
            continue
        bounds = field_bounds(field)
        if bounds is None:
            continue
        if field.is_repeated:
            checked = [_checked_value(bounds, v, where, field) for v in value]
            del value[:]
            value.extend(checked)
        else:
            setattr(msg, field.name, _checked_value(bounds, value, where, field))


M = TypeVar("M", bound=Message)


def check_dccl_bounds(msg: M) -> M:
    """A copy of ``msg`` as DCCL would deliver it, or :class:`DcclBoundsError` if DCCL could not deliver it.

    Required fields must be set; every numeric field with DCCL min/max must lie inside them after rounding to
    the field's precision (DCCL rounds first, then checks), and the copy carries the rounded values.
    """
    missing = msg.FindInitializationErrors()
    if missing:
        raise DcclBoundsError(
            f"{msg.DESCRIPTOR.full_name} is missing required field(s): {', '.join(missing)}"
        )
    checked = type(msg)()
    checked.CopyFrom(msg)
    _check_in_place(checked, f"{msg.DESCRIPTOR.name}.")
    return checked
