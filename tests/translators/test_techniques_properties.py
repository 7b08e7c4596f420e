"""Round-trip properties of the techniques over generated messages (hypothesis)."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.protobuf import basic_node_report_pb2
from translators import techniques
from translators.techniques import Technique
from translators.techniques.numbers import simple_dtoa, simple_ftoa

HERE = Path(__file__).resolve().parent


@pytest.fixture(scope="module")
def pb():
    return basic_node_report_pb2


finite = st.floats(allow_nan=False)
floats32 = st.floats(width=32, allow_nan=False)
texts = st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=20)


@settings(max_examples=200, deadline=None)
@given(value=finite)
def test_simple_dtoa_round_trips(value):
    assert float(simple_dtoa(value)) == value


@settings(max_examples=200, deadline=None)
@given(value=floats32)
def test_simple_ftoa_round_trips_as_float32(value):
    import struct

    text = simple_ftoa(value)
    assert struct.unpack("<f", struct.pack("<f", float(text)))[0] == value


@settings(max_examples=100, deadline=None)
@given(d=finite, f=floats32, i=st.integers(-(2**31), 2**31 - 1), u=st.integers(0, 2**64 - 1), b=st.booleans(),
       s=texts, raw=st.binary(max_size=12), reps=st.lists(finite, max_size=4), sval=texts)
def test_text_format_and_hex_round_trip(pb, d, f, i, u, b, s, raw, reps, sval):
    msg = pb.TestMsg(double_default_optional=d, float_default_optional=f, int32_default_optional=i,
                     uint64_default_optional=u, bool_default_optional=b, string_default_optional=s,
                     bytes_default_optional=raw, double_default_repeat=reps,
                     msg_default_optional=pb.EmbeddedMsg1(val=d, msg=pb.EmbeddedMsg2(sval=sval)))
    for technique in (Technique.PROTOBUF_TEXT_FORMAT, Technique.PREFIXED_PROTOBUF_TEXT_FORMAT,
                      Technique.PROTOBUF_NATIVE_HEX, Technique.PREFIXED_PROTOBUF_NATIVE_HEX,
                      Technique.PREFIXED_PROTOBUF_NATIVE_ENCODED):
        value = techniques.serialize(msg, technique)
        assert techniques.parse(value, pb.TestMsg(), technique) == msg
    text = techniques.to_text_format(msg)
    assert text.isascii() and "\n" not in text and text.endswith(" ")


@settings(max_examples=100, deadline=None)
@given(name=st.text(alphabet="abcdefghijklmnopqrstuvwxyz0123456789_ ", max_size=12),
       x=st.integers(-10**6, 10**6), reps=st.lists(st.integers(-(2**31), 2**31 - 1), max_size=6))
def test_key_values_and_format_round_trip(pb, name, x, reps):
    """Lower-case names without delimiters and integral doubles survive both lossy text techniques."""
    msg = pb.BasicNodeReport(Name=name, x=float(x), repeat=reps)
    kv = techniques.to_key_values(msg)
    assert techniques.from_key_values(kv, pb.BasicNodeReport()) == msg
    fmt = "NAME=%1%;X=%202%;R=%10%" if reps else "NAME=%1%;X=%202%"
    assert techniques.parse_format(techniques.format_message(msg, fmt), pb.BasicNodeReport(), fmt) == msg
