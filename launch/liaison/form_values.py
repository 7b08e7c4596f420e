"""What a browser sends back for a command -> a protobuf message, or :class:`CommandRefused` naming the field.

The values are JSON shaped like the message (``{"desired_state": "POLYGON", "polygon_radius": 400}``; a
sub-message is an object, a repeated field a list; numbers may arrive as text).  Every check the page makes is
made again here from the descriptor (type, range, DCCL bounds, enum names, required fields, lengths), and the
finished message then goes through :func:`translators.usv.validation.check_dccl_bounds`, the command path's own
check, which also rounds values to their DCCL precision as the link would.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.message import Message

from gateway.goby.dccl.arith import quantize_float, quantize_int
from launch.liaison.errors import CommandRefused
from launch.liaison.form_schema import (
    FLOAT_MAX,
    TYPE_RANGES,
    dccl_bounds,
    dccl_field_options,
    describe_bounds,
    field_kind,
    is_auto_time,
    numeric_limits,
)
from translators.usv.validation import DcclBoundsError, check_dccl_bounds
from util.descriptors import descriptor_of, enum_type_of

MAX_TEXT = 10_000  # characters accepted for one string or bytes value without (dccl.field).max_length


def _unset(value: Any) -> bool:
    return value is None or (isinstance(value, str) and value.strip() == "")


def _number(value: Any, path: str) -> float:
    if isinstance(value, bool):
        raise CommandRefused(f"{path}: expected a number, got {value!r}", path)
    if isinstance(value, int | float):
        number = float(value)
    elif isinstance(value, str):
        try:
            number = float(value.strip())
        except ValueError:
            raise CommandRefused(f"{path}: {value!r} is not a number", path) from None
    else:
        raise CommandRefused(f"{path}: expected a number, got {type(value).__name__}", path)
    if not math.isfinite(number):
        raise CommandRefused(f"{path}: {value!r} is not a finite number", path)
    return number


def _integer(value: Any, path: str, kind: str) -> int:
    if isinstance(value, str) and value.strip().lstrip("+-").isdigit():
        number = int(value.strip())  # exact, also past 2^53
    else:
        real = _number(value, path)
        if real != int(real):
            raise CommandRefused(f"{path}: {value!r} is not a whole number", path)
        number = int(real)
    low, high = TYPE_RANGES[kind]
    if not low <= number <= high:
        raise CommandRefused(f"{path}: {number} is outside the range of {kind} [{low}, {high}]", path)
    return number


def _scalar(field: FieldDescriptor, value: Any, path: str) -> Any:
    kind = field_kind(field)
    if kind in TYPE_RANGES:
        result: Any = _integer(value, path, kind)
    elif kind in ("float", "double"):
        result = _number(value, path)
        if kind == "float" and abs(result) > FLOAT_MAX:
            raise CommandRefused(f"{path}: {result:g} does not fit in a float", path)
    elif kind == "bool":
        if isinstance(value, bool):
            result = value
        elif isinstance(value, str) and value.strip().lower() in ("true", "false"):
            result = value.strip().lower() == "true"
        else:
            raise CommandRefused(f"{path}: expected true or false, got {value!r}", path)
    elif kind == "enum":
        enum_type = enum_type_of(field)
        names = [v.name for v in enum_type.values]
        if not isinstance(value, str) or value not in names:
            raise CommandRefused(f"{path}: {value!r} is not one of {', '.join(names)}", path)
        result = enum_type.values_by_name[value].number
    elif kind == "string":
        if not isinstance(value, str):
            raise CommandRefused(f"{path}: expected text, got {type(value).__name__}", path)
        result = value
    else:  # bytes, as hex
        if not isinstance(value, str):
            raise CommandRefused(f"{path}: expected hex text, got {type(value).__name__}", path)
        try:
            result = bytes.fromhex(value)
        except ValueError:
            raise CommandRefused(f"{path}: {value!r} is not hex (pairs of 0-9, a-f)", path) from None
    _check_limits(field, result, path)
    return result


def _check_limits(field: FieldDescriptor, value: Any, path: str) -> None:
    options = dccl_field_options(field)
    if isinstance(value, str | bytes):
        limit = options.max_length if options.HasField("max_length") else MAX_TEXT
        if len(value) > limit:
            raise CommandRefused(f"{path}: {len(value)} characters, more than the {limit} allowed", path)
        return
    bounds = dccl_bounds(field)
    if bounds is not None and isinstance(value, int | float) and not isinstance(value, bool):
        low, high, step = bounds
        # DCCL rounds (as its codec: integers by remainder toward zero), then checks
        rounded = quantize_int(value, step) if isinstance(value, int) else quantize_float(value, step)
        if not low <= rounded <= high:
            raise CommandRefused(f"{path}: {value:g} is outside its DCCL bounds {describe_bounds(low, high, step)}",
                                 path)
    elif field_kind(field) in ("float", "double"):
        low, high, _, _ = numeric_limits(field)
        if not low <= value <= high:
            raise CommandRefused(f"{path}: {value:g} is outside [{low:g}, {high:g}]", path)


def fill_message(msg: Message, values: Any, now: Callable[[], float], path: str = "") -> None:
    """Set ``msg``'s fields from ``values`` (see the module docstring); raises CommandRefused."""
    where = path or msg.DESCRIPTOR.name
    if not isinstance(values, dict):
        raise CommandRefused(f"{where}: expected an object of field values, got {type(values).__name__}", path)
    descriptor = descriptor_of(msg)
    fields = descriptor.fields_by_name
    unknown = sorted(set(values) - set(fields))
    if unknown:
        raise CommandRefused(f"{where}: no field named {', '.join(map(repr, unknown))}", f"{path}{unknown[0]}")
    for field in descriptor.fields:
        fpath = f"{path}{field.name}"
        if is_auto_time(field):
            seconds = now()
            value: Any = seconds if field_kind(field) in ("float", "double") else int(seconds * 1e6)
            setattr(msg, field.name, value)
            continue
        raw = values.get(field.name)
        if field.is_repeated:
            _fill_repeated(msg, field, raw, now, fpath)
        elif field.type == FieldDescriptor.TYPE_MESSAGE:
            if raw is not None:
                fill_message(getattr(msg, field.name), raw, now, f"{fpath}.")
                getattr(msg, field.name).SetInParent()
        elif not _unset(raw):
            setattr(msg, field.name, _scalar(field, raw, fpath))
        if field.is_required and not field.is_repeated and not msg.HasField(field.name):
            raise CommandRefused(f"{fpath} is required", fpath)


def _fill_repeated(msg: Message, field: FieldDescriptor, raw: Any, now: Callable[[], float], path: str) -> None:
    if raw is None:
        raw = []
    if not isinstance(raw, list):
        raise CommandRefused(f"{path}: expected a list, got {type(raw).__name__}", path)
    options = dccl_field_options(field)
    if options.HasField("max_repeat") and len(raw) > options.max_repeat:
        raise CommandRefused(f"{path}: {len(raw)} values, more than max_repeat {options.max_repeat}", path)
    if len(raw) < options.min_repeat:
        raise CommandRefused(f"{path}: {len(raw)} values, fewer than min_repeat {options.min_repeat}", path)
    target = getattr(msg, field.name)
    for index, item in enumerate(raw):
        ipath = f"{path}[{index}]"
        if field.type == FieldDescriptor.TYPE_MESSAGE:
            fill_message(target.add(), item, now, f"{ipath}.")
        elif _unset(item):
            raise CommandRefused(f"{ipath}: empty value in a repeated field", ipath)
        else:
            target.append(_scalar(field, item, ipath))


def build_command(cls: type[Message], values: Any, now: Callable[[], float]) -> Message:
    """A message of ``cls`` from browser values, checked as DCCL would carry it; CommandRefused otherwise.

    ``now``: the application clock (seconds), for DCCL time fields.
    """
    msg = cls()
    fill_message(msg, values, now)
    try:
        return check_dccl_bounds(msg)
    except DcclBoundsError as exc:
        raise CommandRefused(f"refused by the DCCL check: {exc}") from exc
