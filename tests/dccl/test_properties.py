"""Property tests: random message definitions (bounds, precisions, enums, optional/required, repeated, nested)
round-trip through the codec, and every size is the DCCL size formula, computed here independently:

    numeric  ceil(log2((max - min) / step + 1 [+ 1 if optional]))     bool 1 [2]     enum: numeric over indexes
    string   ceil(log2(max_length + 1)) + 8 * length                   bytes 8 * max_length [+ 1 presence]
    repeated ceil(log2(max_repeat - min_repeat + 1)) + n * element (elements in the required form)
    message  sum of its fields [+ 1 presence bit if optional; 1 bit when unset]
    total    id byte + ceil(body bits / 8)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gateway.goby.dccl import Codec
from tests.dccl.conftest import COURSE_TYPES
from tests.dccl.definitions import FieldDef, dccl_type
from translators.trail.protobuf.health_status_pb2 import HealthStatus
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand, USVCommand


def ceil_log2(n: int) -> int:
    return max(0, math.ceil(math.log2(n))) if n > 1 else 0


@dataclass
class Spec:
    """A generated field with what the test needs to know about it: bits and values."""

    field: FieldDef
    steps: int = 0  # numeric: number of grid steps between min and max
    scale: int = 1  # double: 10^precision
    step: int = 1  # integer: grid step

    @property
    def optional(self) -> bool:
        return self.field.label == "optional"

    def element_bits(self, value: Any, required: bool) -> int:
        f, null = self.field, 0 if required else 1
        if f.type == "bool":
            return 1 + null
        if f.type == "enum":
            return ceil_log2(len(f.enum) + null)
        if f.type == "string":
            return ceil_log2(f.options["max_length"] + 1) + 8 * len(value.encode())
        if f.type == "bytes":
            return 8 * f.options["max_length"] + null
        if f.type == "message":
            return sum(spec.bits(value.get(spec.field.name)) for spec in self.children)
        # DCCL's own arithmetic (DefaultNumericFieldCodec::size): floating-point noise in (max - min) / resolution
        # can add a value: min 1.0, max 1.1, precision 1 takes 2 bits, as the C++ `dccl -a` reports
        o = f.options
        resolution = 10.0 ** -o["precision"] if "precision" in o else 1.0
        return ceil_log2(math.ceil((o["max"] - o["min"]) / resolution + 1 + null))

    children: tuple[Spec, ...] = ()

    def bits(self, value: Any) -> int:
        """Bits this field takes with ``value`` (None: unset)."""
        f = self.field
        if f.label == "repeated":
            lo, hi = f.options.get("min_repeat", 0), f.options["max_repeat"]
            return ceil_log2(hi - lo + 1) + sum(self.element_bits(v, True) for v in value)
        if f.type == "message" and self.optional:
            return 1 + (self.element_bits(value, True) if value is not None else 0)
        if value is None:
            if f.type == "string":
                return ceil_log2(f.options["max_length"] + 1)
            if f.type == "bytes":
                return 1
            return self.element_bits(None, False)
        return self.element_bits(value, not self.optional)

    def max_bits(self) -> int:
        f = self.field
        if f.type == "string":
            element = ceil_log2(f.options["max_length"] + 1) + 8 * f.options["max_length"]
        elif f.type == "message":
            element = sum(spec.max_bits() for spec in self.children)
        else:
            element = self.element_bits(None, f.label != "optional")
        if f.label == "repeated":
            lo, hi = f.options.get("min_repeat", 0), f.options["max_repeat"]
            return ceil_log2(hi - lo + 1) + hi * element
        return element + (1 if f.type == "message" and self.optional else 0)


labels = st.sampled_from(["optional", "required", "repeated"])


@st.composite
def numeric_specs(draw, name: str, label: str) -> Spec:
    kind = draw(st.sampled_from(["double", "int32", "int64", "uint32", "sint32"]))
    options: dict[str, Any] = {}
    if kind == "double":
        precision = draw(st.integers(-1, 3))
        steps = draw(st.integers(0, 3000))
        if precision < 0:
            lo = draw(st.integers(-100, 100)) * 10
            options.update(min=float(lo), max=float(lo + 10 * steps), precision=precision)
            spec = Spec(FieldDef(name, kind, label, options), steps=steps, step=10)
        else:
            scale = 10 ** precision
            lo = draw(st.integers(-1000, 1000))
            options.update(min=float(lo), max=(lo * scale + steps) / scale, precision=precision)
            spec = Spec(FieldDef(name, kind, label, options), steps=steps, scale=scale)
    else:
        step = draw(st.sampled_from([1, 1, 10]))
        lo = draw(st.integers(0 if kind == "uint32" else -300, 300)) * step
        steps = draw(st.integers(0, 5000))
        options.update(min=lo, max=lo + steps * step)
        if step == 10:
            options["precision"] = -1
        spec = Spec(FieldDef(name, kind, label, options), steps=steps, step=step)
    if label == "repeated":
        spec.field.options.update(max_repeat=draw(st.integers(1, 4)))
        spec.field.options["min_repeat"] = draw(st.integers(0, spec.field.options["max_repeat"]))
    return spec


@st.composite
def other_specs(draw, name: str, label: str, depth: int) -> Spec:
    kinds = ["bool", "enum", "string", "bytes"] + (["message"] if depth < 2 else [])
    kind = draw(st.sampled_from(kinds))
    field = FieldDef(name, kind, label)
    spec = Spec(field)
    if kind == "enum":
        numbers = draw(st.lists(st.integers(-50, 50), min_size=1, max_size=6, unique=True))
        field.enum = [(f"V{i}", n) for i, n in enumerate(numbers)]
    elif kind in ("string", "bytes"):
        field.options["max_length"] = draw(st.integers(1, 6))
    elif kind == "message":
        spec.children = tuple(draw(st.lists(field_specs(depth + 1), min_size=1, max_size=3)))
        for i, child in enumerate(spec.children):
            child.field.name = f"f{i}"
        field.message = [child.field for child in spec.children]
    if label == "repeated":
        field.options.update(max_repeat=draw(st.integers(1, 3)))
    return spec


@st.composite
def field_specs(draw, depth: int = 0) -> Spec:
    label = draw(labels)
    if draw(st.booleans()):
        return draw(numeric_specs("x", label))
    return draw(other_specs("x", label, depth))


@st.composite
def definitions(draw) -> list[Spec]:
    specs = draw(st.lists(field_specs(), min_size=1, max_size=6))
    for i, spec in enumerate(specs):
        spec.field.name = f"f{i}"
    return specs


def element_value(draw, spec: Spec) -> Any:
    f = spec.field
    if f.type == "bool":
        return draw(st.booleans())
    if f.type == "enum":
        return draw(st.sampled_from(f.enum))[1]
    if f.type == "string":  # not empty: DCCL sends "" as "not present"
        limit = f.options["max_length"]
        return draw(st.text(alphabet="abcxyzé", min_size=1, max_size=limit).filter(lambda t: len(t.encode()) <= limit))
    if f.type == "bytes":
        return draw(st.binary(min_size=f.options["max_length"], max_size=f.options["max_length"]))
    if f.type == "message":
        return {child.field.name: field_value(draw, child) for child in spec.children}
    k = draw(st.integers(0, spec.steps))
    if f.type == "double":
        if f.options["precision"] < 0:
            return f.options["min"] + k * spec.step
        return (f.options["min"] * spec.scale + k) / spec.scale
    return f.options["min"] + k * spec.step


def field_value(draw, spec: Spec) -> Any:
    f = spec.field
    if f.label == "repeated":
        lo, hi = f.options.get("min_repeat", 0), f.options["max_repeat"]
        return [element_value(draw, spec) for _ in range(draw(st.integers(lo, hi)))]
    if f.label == "optional" and draw(st.booleans()):
        return None
    return element_value(draw, spec)


def fill(msg: Any, specs: tuple[Spec, ...] | list[Spec], values: dict[str, Any]) -> None:
    for spec in specs:
        value = values.get(spec.field.name)
        if value is None:
            continue
        if spec.field.type == "message":
            if spec.field.label == "repeated":
                for item in value:
                    fill(getattr(msg, spec.field.name).add(), spec.children, item)
            else:
                sub = getattr(msg, spec.field.name)
                sub.SetInParent()
                fill(sub, spec.children, value)
        elif spec.field.label == "repeated":
            getattr(msg, spec.field.name).extend(value)
        else:
            setattr(msg, spec.field.name, value)


@settings(max_examples=300)
@given(data=st.data())
def test_random_definitions_round_trip_with_the_spec_sizes(data):
    specs = data.draw(definitions())
    message_type = dccl_type([s.field for s in specs], dccl_id=9, max_bytes=100000)
    codec = Codec()
    codec.load(message_type)
    max_bits = sum(s.max_bits() for s in specs)
    assert codec.max_size(message_type) == 1 + 1 + math.ceil(max_bits / 8)  # id counted in its 2-byte form
    values = {s.field.name: field_value(data.draw, s) for s in specs}
    msg = message_type()
    fill(msg, specs, values)
    encoded = codec.encode(msg)
    body_bits = sum(s.bits(values[s.field.name]) for s in specs)
    assert len(encoded) == 1 + math.ceil(body_bits / 8)
    assert codec.min_size(message_type) <= len(encoded) <= codec.max_size(message_type) - 1
    decoded = codec.decode(encoded)
    assert_close(decoded, msg)
    assert codec.encode(decoded) == encoded


def assert_close(decoded: Any, original: Any) -> None:
    """Equal, allowing doubles to differ by rounding noise of the decimal grid."""
    for field, value in original.ListFields():
        got = getattr(decoded, field.name)
        if field.type == field.TYPE_MESSAGE:
            if field.is_repeated:
                assert len(got) == len(value)
                for a, b in zip(got, value, strict=True):
                    assert_close(a, b)
            else:
                assert_close(got, value)
        elif field.type == field.TYPE_DOUBLE:
            assert list(got) == pytest.approx(list(value), abs=1e-9) if field.is_repeated else got == pytest.approx(
                value, abs=1e-9)
        elif field.type == field.TYPE_BYTES and not field.is_repeated:
            assert got == value
        else:
            assert got == value, field.name
    assert {f.name for f, _ in decoded.ListFields()} >= {f.name for f, _ in original.ListFields()}


# -------------------------------------------------------------------------- the course's messages

course_values = {
    NavigationReport: dict(vehicle=st.integers(1, 128), time=st.floats(1.6e9, 1.8e9),
                           x=st.floats(-10000, 10000), y=st.floats(-10000, 10000), z=st.floats(-6000, 0),
                           speed_over_ground=st.floats(0, 5), heading=st.floats(0, 359),
                           type=st.sampled_from([1, 2, 3, 4])),
    USVCommand: dict(time=st.floats(1.6e9, 1.8e9), desired_state=st.sampled_from([1, 2]),
                     polygon_sides=st.integers(3, 10), polygon_radius=st.integers(100, 2000)),
    AUVCommand: dict(time=st.floats(1.6e9, 1.8e9), desired_state=st.sampled_from([1, 2])),
    HealthStatus: dict(state=st.sampled_from([1, 2, 3, 4]), timestamp=st.integers(16 * 10**14, 18 * 10**14)),
}
STEPS = {"x": 0.1, "y": 0.1, "speed_over_ground": 0.1, "z": 1, "heading": 1, "polygon_radius": 10}


@pytest.mark.parametrize("message_type", COURSE_TYPES, ids=lambda t: t.DESCRIPTOR.name)
@settings(max_examples=300)
@given(data=st.data())
def test_course_messages_round_trip_up_to_their_documented_quantisation(message_type, data):
    values = {}
    for name, strategy in course_values[message_type].items():
        required = message_type.DESCRIPTOR.fields_by_name[name].is_required
        if required or data.draw(st.booleans()):
            values[name] = data.draw(strategy)
    msg = message_type(**values)
    clock = values.get("time", values.get("timestamp", 1.7e15) / 1e6)
    codec = Codec(clock=lambda: clock)
    codec.load(message_type)
    encoded = codec.encode(msg)
    assert len(encoded) == codec.min_size(message_type)  # all four are fixed size
    decoded = codec.decode(encoded)
    for name, value in values.items():
        got = getattr(decoded, name)
        if name in ("time",):
            assert abs(got - value) <= 0.5
        elif name == "timestamp":
            assert abs(got - value) <= 500000 and got % 1000000 == 0
        elif name in STEPS:
            assert abs(got - value) <= STEPS[name] / 2 + 1e-9
        else:
            assert got == value
    assert codec.encode(decoded) == encoded
