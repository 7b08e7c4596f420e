"""Each built-in codec and layout rule, on test messages that use them all (sizes by DCCL's formulas)."""

from __future__ import annotations

import pytest

from gateway.goby.dccl import Codec, EncodeError, MissingFieldError, NotLoadedError, OutOfRangeError
from tests.protobuf import dccl_test_pb2 as pb

NOW = 1700000000  # 2023-11-14T22:13:20Z
E = pb.Everything


@pytest.fixture
def codec() -> Codec:
    codec = Codec(clock=lambda: NOW)
    for message_type in (pb.Everything, pb.Layout, pb.Subscription):
        codec.load(message_type)
    return codec


def round_trip(codec: Codec, msg, **kwargs):
    return codec.decode(codec.encode(msg, **kwargs))


def test_everything_set_round_trips_with_dccls_quantisation(codec):
    msg = E(d=12.344, f=1.25, i32=-251, i64=-4999999999, u32=15, u64=123456789012, s32=-3, flag=False,
            packed=E.BLUE, unpacked=E.GREEN, text="héllo", blob=b"\x01\x02", var_blob=b"abc", var_text="xy",
            present=4, present_text="abc", fixed=9.0, fixed_text="ignored", time_us=1700000000999999,
            time_us_p=1700000000123456, time_s=1699999999.26, other_id=300, skipped=1.0)
    out = round_trip(codec, msg)
    expected = E(d=12.34, f=1.2999999523162842, i32=-200, i64=-4999999999, u32=16, u64=123456789012, s32=-3,
                 flag=False, packed=E.BLUE, unpacked=E.GREEN, text="héllo", blob=b"\x01\x02\x00", var_blob=b"abc",
                 var_text="xy", present=4, present_text="abc", fixed=2.5, fixed_text="hello",
                 time_us=1700000001000000, time_us_p=1700000000123000, time_s=1699999999.3, other_id=300)
    assert out == expected


def test_unset_optionals_arrive_unset_except_static_and_id_codecs(codec):
    data = codec.encode(E())
    assert data[:2] == bytes([0xB1, 0x04])  # id 600: (600 << 1) | 1, little-endian
    assert codec.decode(data) == E(fixed=2.5, fixed_text="hello", other_id=0)
    assert len(data) == codec.min_size(E) + 1  # the two-byte id; min_size counts a one-byte id, as DCCL's


@pytest.mark.parametrize(("value", "sent"), [(-207, -200), (-250, -200), (-251, -200), (-299, -200), (249, 200), (250, 300),
                                             (1000, 1000), (1049, 1000)])
def test_negative_precision_on_integers_truncates_the_remainder_like_cpp(codec, value, sent):
    assert round_trip(codec, E(i32=value)).i32 == sent


@pytest.mark.parametrize("value", [1050, -1100, 5000])
def test_rounded_out_of_range_is_unset_and_strict_names_field_and_value(codec, value):
    assert not round_trip(codec, E(i32=value)).HasField("i32")
    with pytest.raises(OutOfRangeError, match=rf"Everything.i32={value} is outside its DCCL bounds "
                                              r"\[-1000, 1000\], in steps of 100"):
        codec.encode(E(i32=value), strict=True)


@pytest.mark.parametrize(("value", "sent"), [(10, 10), (11, 12), (13, 14), (20, 20)])
def test_integer_resolution(codec, value, sent):
    assert round_trip(codec, E(u32=value)).u32 == sent


def test_presence_codec_sends_out_of_range_as_the_minimum_not_unset(codec):
    assert round_trip(codec, E(present=7)).present == 0
    assert not round_trip(codec, E()).HasField("present")
    assert not round_trip(codec, E(present_text="")).HasField("present_text")


def test_strings_truncate_at_max_length_on_a_character_boundary(codec):
    assert round_trip(codec, E(text="abcdefghijkl")).text == "abcdefghij"
    assert round_trip(codec, E(text="abcdefghié")).text == "abcdefghi"  # é is two bytes; one would not fit
    assert not round_trip(codec, E(text="")).HasField("text")  # an empty string is "not present" in DCCL
    with pytest.raises(OutOfRangeError, match="Everything.text='abcdefghijkl' is outside its DCCL bounds max_length"):
        codec.encode(E(text="abcdefghijkl"), strict=True)


def test_bytes_pad_and_truncate(codec):
    assert round_trip(codec, E(blob=b"\xff\xfe\xfd\xfc")).blob == b"\xff\xfe\xfd"
    assert round_trip(codec, E(var_blob=b"")).var_blob == b""
    assert round_trip(codec, E(var_blob=b"123456")).var_blob == b"12345"


def test_unpacked_enum_uses_numbers_and_packed_uses_indexes(codec):
    fields = {f.name: f for f in codec.compiled(E).body}
    assert fields["packed"].max_size == 2 and fields["unpacked"].max_size == 6
    for colour in (E.RED, E.GREEN, E.BLUE):
        out = round_trip(codec, E(packed=colour, unpacked=colour))
        assert (out.packed, out.unpacked) == (colour, colour)


def test_id_codec_field_refuses_ids_dccl_cannot_send(codec):
    assert round_trip(codec, E(other_id=32767)).other_id == 32767
    with pytest.raises(EncodeError, match="other_id=32768 exceeds the largest DCCL id"):
        codec.encode(E(other_id=32768))


def test_time_codecs_use_the_receivers_clock_window(codec):
    day = 86400
    # time_us_p has num_days 2: decoded within +-1 day of the clock
    out = round_trip(codec, E(time_us_p=(NOW - day + 10) * 1000000, time_us=(NOW - 43300) * 1000000))
    assert out.time_us_p == (NOW - day + 10) * 1000000
    assert out.time_us == (NOW - 43300 + day) * 1000000  # more than 12 h away: aliased to the other side
    assert round_trip(codec, E(time_us=(NOW + 43000) * 1000000)).time_us == (NOW + 43000) * 1000000
    decoded_later = codec.decode(codec.encode(E(time_s=NOW + 0.04)), now=NOW + 3 * day)
    assert decoded_later.time_s == NOW + 3 * day


def test_layout_head_and_body_parts(codec):
    msg = pb.Layout(head_a=100, ok=True, ratio=0.5)
    msg.head_pair.a, msg.head_pair.b = 3, 2
    msg.body_inner.a, msg.body_inner.b = 1, 0
    msg.body_inner.c.extend([True, False, True])
    msg.plain_inner.a, msg.plain_inner.b = 2, 3
    msg.words.extend(["ab", "cdef"])
    msg.values.append(0.54)
    out = round_trip(codec, msg)
    compiled = codec.compiled(pb.Layout)
    assert [f.name for f in compiled.head] == ["head_a", "head_pair"]
    assert codec.encode(msg)[0] == 20 << 1 and compiled.head_bits == 12
    assert (out.head_pair.a, out.head_pair.b) == (3, 2)  # in_head on the message field: all of it in the head
    assert (out.body_inner.a, out.body_inner.b, list(out.body_inner.c)) == (1, 0, [True, False, True])
    # DCCL: inside a message field with no explicit in_head, an in_head field is in neither part
    assert out.plain_inner.a == 2 and not out.plain_inner.HasField("b")
    assert list(out.words) == ["ab", "cde"]
    assert list(out.values) == [0.5, 0.0]  # padded up to min_repeat with zeros (the minimum)
    assert len(out.many) == 1 and out.many[0].a == 0  # min_repeat 1
    assert out.ratio == 0.5


def test_repeats_beyond_max_repeat_are_dropped_or_refused(codec):
    msg = pb.Layout(head_a=1, ok=False, ratio=0.0, values=[0.1, 0.2, 0.3, 0.4, 0.5])
    msg.head_pair.a = 0
    msg.body_inner.a = 0
    msg.many.add(a=1)
    assert list(round_trip(codec, msg).values) == pytest.approx([0.1, 0.2, 0.3, 0.4])
    with pytest.raises(OutOfRangeError, match=r"Layout.values count=5 is outside its DCCL bounds \[2, 4\]"):
        codec.encode(msg, strict=True)


def test_required_out_of_range_arrives_as_the_minimum(codec):
    msg = pb.Layout(head_a=101, ok=True, ratio=2.0)
    msg.head_pair.a = 0
    msg.body_inner.a = 9
    out = round_trip(codec, msg)
    assert (out.head_a, out.body_inner.a, out.ratio) == (0, 0, 0.0)


def test_missing_required_fields_are_named(codec):
    with pytest.raises(MissingFieldError, match=r"goby.test.dccl.Layout is missing required field\(s\): "
                                                r"head_a, head_pair.a"):
        codec.encode(pb.Layout(head_pair=pb.Layout.Pair(b=1), body_inner=pb.Layout.Inner(a=1), ok=True, ratio=0.1))


def test_encode_and_decode_need_load():
    codec = Codec()
    with pytest.raises(NotLoadedError, match="goby.test.dccl.Everything has not been loaded"):
        codec.encode(E())
    codec.load(E)
    codec.unload(E)
    with pytest.raises(NotLoadedError):
        codec.max_size(E)


def test_bounds_as_data(codec):
    bounds = {b.name: b for b in codec.bounds(E)}
    assert (bounds["i32"].min, bounds["i32"].max, bounds["i32"].resolution, bounds["i32"].precision) == (
        -1000, 1000, 100, -2)
    assert bounds["i32"].describe() == "[-1000, 1000], in steps of 100"
    assert bounds["packed"].enum == (("RED", 5), ("GREEN", -2), ("BLUE", 40))
    assert bounds["text"].max_length == 10 and bounds["text"].max_bits == 84 and bounds["text"].min_bits == 4
    assert bounds["time_us"].time and bounds["time_us"].codec == "dccl.time3"
    assert bounds["fixed_text"].static_value == "hello"
    assert "skipped" not in bounds
    layout = {b.name: b for b in codec.bounds(pb.Layout)}
    assert layout["head_a"].part == "head" and layout["values"].part == "body"
    assert (layout["values"].min_repeat, layout["values"].max_repeat, layout["values"].label) == (2, 4, "repeated")
    assert [f.path for f in layout["body_inner"].fields] == ["body_inner.a", "body_inner.b", "body_inner.c"]


def test_info_has_dccls_layout(codec):
    text = codec.info(pb.Subscription)
    assert text.splitlines()[:3] == [
        "=============== 3: goby.test.dccl.Subscription ===============",
        "Actual maximum size of message: 27 bytes / 216 bits",
        "        dccl.id head...........................8",
    ]
    assert "        2. header..........................19-83 {dccl.default3}" in text
    assert "                2. dest[4]..........................3-67 {dccl.default3}" in text
    assert "        5. dccl_id..........................8-16 {dccl.default.id}" in text


def test_generated_source_is_available(codec):
    assert "def encode(m):" in codec.source(E) and "def decode(data, start, now):" in codec.source(E)


def test_numeric_bounds_of_one_field_without_loading_its_message():
    from gateway.goby.dccl import numeric_bounds

    fields = E.DESCRIPTOR.fields_by_name
    assert numeric_bounds(fields["i32"]) == (-1000.0, 1000.0, 100.0)
    assert numeric_bounds(fields["d"]) == (-100.0, 100.0, 0.01)
    assert numeric_bounds(fields["u32"]) == (10.0, 20.0, 2.0)
    for name in ("time_us", "fixed", "packed", "text", "present"):  # other codecs, or not numeric
        assert numeric_bounds(fields[name]) is None, name
