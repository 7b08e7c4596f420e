"""A user adds a field codec by name, as DCCL allows (``codec.manager().add<...>("name")``)."""

from __future__ import annotations

from typing import Any

import pytest
from google.protobuf.descriptor import FieldDescriptor

from gateway.goby.dccl import Bits, Codec, DefinitionError, FieldCodec
from tests.dccl.definitions import FieldDef, dccl_type


class Unary(FieldCodec):
    """n as n one-bits then a zero (optional fields: n + 1 ones, and unset as a single zero)."""

    LIMIT = 8

    @property
    def min_size(self) -> int:
        return 1

    @property
    def max_size(self) -> int:
        return self.LIMIT + 2

    def validate(self) -> None:
        self.field.require(self.field.options.max <= self.LIMIT, f"max must be <= {self.LIMIT} for unary")

    def encode(self, value: Any | None) -> tuple[int, int]:
        if value is None:
            return 0, 1
        count = min(int(value), self.LIMIT) + (0 if self.field.required else 1)
        return (1 << count) - 1, count + 1

    def decode(self, bits: Bits) -> Any | None:
        count = 0
        while bits.read(1):
            count += 1
        if not self.field.required:
            if count == 0:
                return None
            count -= 1
        return count

    def describe(self) -> dict[str, Any]:
        return {"min": 0, "max": self.LIMIT}


def test_user_codec_by_name_round_trips_in_all_positions():
    codec = Codec()
    codec.registry.add("test.unary", Unary, [FieldDescriptor.TYPE_INT32])
    message_type = dccl_type([
        FieldDef("a", "int32", "required", {"codec": "test.unary", "max": 8}),
        FieldDef("b", "int32", options={"codec": "test.unary", "max": 8}),
        FieldDef("c", "int32", "repeated", {"codec": "test.unary", "max": 8, "max_repeat": 3}),
        FieldDef("d", "int32", options={"min": 0, "max": 3}),
    ])
    codec.load(message_type)
    for values in ({"a": 3}, {"a": 0, "b": 5, "c": [1, 0, 8], "d": 2}, {"a": 8, "b": 0, "c": [], "d": 0}):
        msg = message_type(**values)
        assert codec.decode(codec.encode(msg)) == msg
    # a = 3: 1110 (first bit lowest), b unset: 0, c: 2-bit count 0, d unset: 3 zero bits
    assert codec.encode(message_type(a=3)) == bytes([10 << 1, 0b0111, 0])
    bounds = {b.name: b for b in codec.bounds(message_type)}
    assert bounds["a"].codec == "test.unary" and bounds["a"].max == 8
    assert "a...." in codec.info(message_type).replace("1. a", "a")


def test_user_codec_validation_and_unknown_types():
    codec = Codec()
    codec.registry.add("test.unary", Unary, [FieldDescriptor.TYPE_INT32])
    with pytest.raises(DefinitionError, match=r"M\.a: max must be <= 8 for unary"):
        codec.load(dccl_type([FieldDef("a", "int32", options={"codec": "test.unary", "max": 9})]))
    with pytest.raises(DefinitionError, match="No codec by the name `test.unary` found for type: TYPE_INT64"):
        codec.load(dccl_type([FieldDef("a", "int64", options={"codec": "test.unary", "max": 2})]))
    assert "test.unary" in codec.registry.names() and "dccl.default3" in codec.registry.names()
    codec.registry.remove("test.unary")
    assert "test.unary" not in codec.registry.names()


def test_registries_are_per_codec():
    mine, other = Codec(), Codec()
    mine.registry.add("test.unary", Unary, [FieldDescriptor.TYPE_INT32])
    with pytest.raises(DefinitionError):
        other.load(dccl_type([FieldDef("a", "int32", options={"codec": "test.unary", "max": 2})]))
