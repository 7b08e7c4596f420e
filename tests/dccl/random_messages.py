"""Random messages of any DCCL type, in and out of bounds (too long, too many, out of range), for cross-checks."""

from __future__ import annotations

import random
from typing import Any

from google.protobuf.descriptor import FieldDescriptor as F
from google.protobuf.message import Message

from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as dccl_options

INT_RANGES = {F.TYPE_INT32: 31, F.TYPE_SINT32: 31, F.TYPE_SFIXED32: 31, F.TYPE_INT64: 63, F.TYPE_SINT64: 63,
              F.TYPE_SFIXED64: 63}
UINT_RANGES = {F.TYPE_UINT32: 32, F.TYPE_FIXED32: 32, F.TYPE_UINT64: 64, F.TYPE_FIXED64: 64}


def random_value(rnd: random.Random, fd: Any, clock: float) -> Any:
    options = fd.GetOptions().Extensions[dccl_options.field]
    kind = fd.type
    if kind == F.TYPE_BOOL:
        return rnd.random() < 0.5
    if kind == F.TYPE_ENUM:
        return rnd.choice(fd.enum_type.values).number
    if kind in (F.TYPE_STRING, F.TYPE_BYTES):
        length = rnd.randint(0, (options.max_length or 5) + 2)
        if kind == F.TYPE_STRING:
            return "".join(rnd.choice("abcXYZ019 ") for _ in range(length))
        return bytes(rnd.randrange(256) for _ in range(length))
    if options.codec.startswith("dccl.time") or options.codec == "_time":
        seconds = clock + rnd.uniform(-40000, 40000)
        return seconds if kind == F.TYPE_DOUBLE else int(seconds * 1e6) + rnd.randint(0, 999999)
    if options.codec == "dccl.default.id":
        return rnd.choice([0, 1, 127, 128, 300, 32767])
    lo, hi = (options.min, options.max) if options.HasField("min") else (-100.0, 100.0)
    span = hi - lo
    if kind in (F.TYPE_DOUBLE, F.TYPE_FLOAT):
        return rnd.uniform(lo - 0.1 * span - 1, hi + 0.1 * span + 1)
    value = rnd.randint(int(lo - 0.1 * span) - 3, int(hi + 0.1 * span) + 3)
    if kind in UINT_RANGES:
        return max(0, min((1 << UINT_RANGES[kind]) - 1, value))
    bits = INT_RANGES.get(kind, 31)
    return max(-(1 << bits), min((1 << bits) - 1, value))


def fill(rnd: random.Random, msg: Message, clock: float) -> Message:
    """Set required fields, most optional ones and a random number of repeated values (sometimes too many)."""
    for fd in msg.DESCRIPTOR.fields:
        options = fd.GetOptions().Extensions[dccl_options.field]
        if fd.is_repeated:
            container = getattr(msg, fd.name)
            for _ in range(rnd.randint(0, (options.max_repeat or 2) + 1)):
                if fd.type == F.TYPE_MESSAGE:
                    fill(rnd, container.add(), clock)
                else:
                    container.append(random_value(rnd, fd, clock))
        elif fd.is_required or rnd.random() < 0.7:
            if fd.type == F.TYPE_MESSAGE:
                sub = getattr(msg, fd.name)
                sub.SetInParent()
                fill(rnd, sub, clock)
            else:
                setattr(msg, fd.name, random_value(rnd, fd, clock))
    return msg
