"""MOOS <-> protobuf string techniques: the spec's examples (Goby's translator1 test) are the expectations."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from tests.protobuf import basic_node_report_pb2
from translators import techniques
from translators.techniques import Technique, TechniqueError

HERE = Path(__file__).resolve().parent
R_TEXT = 'Name: "unicorn" y: 1023.5 repeat: 1 repeat: -1 repeat: 2 heading: 240 x: 550 '
R_HEX = "0a07756e69636f726e190000000000fc8f40500150ffffffffffffffffff015002c90c0000000000006e40d10c0000000000308140"
PREFIX = "@PB[goby.test.moos.protobuf.BasicNodeReport] "


@pytest.fixture(scope="module")
def pb():
    """The test-only protos (committed generated code, tests/protobuf)."""
    return basic_node_report_pb2


@pytest.fixture
def report(pb):
    """The spec's running example R."""
    return pb.BasicNodeReport(Name="unicorn", x=550, y=1023.5, heading=240, repeat=[1, -1, 2])


def test_text_format_matches_cpp_single_line_printer(report, pb):
    assert techniques.serialize(report, Technique.PROTOBUF_TEXT_FORMAT) == R_TEXT
    back = techniques.parse(R_TEXT, pb.BasicNodeReport(Name="stale", speed=3), Technique.PROTOBUF_TEXT_FORMAT)
    assert back == report  # parse clears first: no stale speed


def test_text_format_number_and_string_spelling(pb):
    msg = pb.TestMsg(
        double_default_optional=0.1, float_default_optional=0.1, string_default_optional='a"\n\u00e9',
        bytes_default_optional=b"\x00\xff", enum_default_optional=pb.ENUM_B, bool_default_optional=True,
        msg_default_optional=pb.EmbeddedMsg1(val=1e20, msg=pb.EmbeddedMsg2(sval="x")),
    )
    text = techniques.to_text_format(msg)
    assert text == (
        'double_default_optional: 0.1 float_default_optional: 0.1 bool_default_optional: true '
        'string_default_optional: "a\\"\\n\\303\\251" bytes_default_optional: "\\000\\377" '
        "enum_default_optional: ENUM_B msg_default_optional { val: 1e+20 msg { sval: \"x\" } } "
    )
    assert techniques.from_text_format(text, pb.TestMsg()) == msg
    # %.15g does not round-trip 0.1+0.2, so C++ falls back to %.17g
    assert techniques.to_text_format(pb.TestMsg(double_default_optional=0.1 + 0.2)) == (
        "double_default_optional: 0.30000000000000004 "
    )
    assert techniques.to_text_format(pb.TestMsg(double_default_optional=math.inf)) == "double_default_optional: inf "


def test_text_format_parse_error_names_the_type(pb):
    with pytest.raises(TechniqueError, match="goby.test.moos.protobuf.BasicNodeReport"):
        techniques.parse("no_such_field: 3", pb.BasicNodeReport(), Technique.PROTOBUF_TEXT_FORMAT)


def test_native_encoded_and_hex(report, pb):
    raw = techniques.serialize(report, Technique.PROTOBUF_NATIVE_ENCODED)
    assert isinstance(raw, bytes) and raw.hex() == R_HEX
    assert techniques.is_binary(Technique.PROTOBUF_NATIVE_ENCODED)
    assert not techniques.is_binary(Technique.PROTOBUF_NATIVE_HEX)
    assert techniques.serialize(report, Technique.PROTOBUF_NATIVE_HEX) == R_HEX
    assert techniques.parse(raw, pb.BasicNodeReport(), Technique.PROTOBUF_NATIVE_ENCODED) == report
    assert techniques.parse(R_HEX.upper(), pb.BasicNodeReport(), Technique.PROTOBUF_NATIVE_HEX) == report
    # odd length reads as if it had a leading 0 nibble: "9" + 16 zeros is 09 (field 1, fixed64) + 0.0
    odd = techniques.serialize(pb.TestMsg(double_default_optional=0), Technique.PROTOBUF_NATIVE_HEX)
    assert odd == "09" + "00" * 8
    assert techniques.parse(odd[1:], pb.TestMsg(), Technique.PROTOBUF_NATIVE_HEX).HasField("double_default_optional")
    with pytest.raises(TechniqueError, match="not hex"):
        techniques.parse("zz", pb.BasicNodeReport(), Technique.PROTOBUF_NATIVE_HEX)


def test_prefixed_variants(report, pb):
    assert techniques.serialize(report) == PREFIX + R_TEXT  # default technique is 5, as Goby's
    assert techniques.serialize(report, Technique.PREFIXED_PROTOBUF_NATIVE_HEX) == PREFIX + R_HEX
    binary = techniques.serialize(report, Technique.PREFIXED_PROTOBUF_NATIVE_ENCODED)
    assert binary == PREFIX.encode() + bytes.fromhex(R_HEX)
    for technique, value in [
        (Technique.PREFIXED_PROTOBUF_TEXT_FORMAT, PREFIX + R_TEXT),
        (Technique.PREFIXED_PROTOBUF_NATIVE_HEX, PREFIX + R_HEX),
        (Technique.PREFIXED_PROTOBUF_NATIVE_ENCODED, binary),
    ]:
        assert techniques.parse(value, pb.BasicNodeReport(), technique) == report
    # a binary value that reached us as a str (as our MOOS client decodes strings) parses the same
    as_str = binary.decode("utf-8", "surrogateescape")
    assert techniques.parse(as_str, pb.BasicNodeReport(), Technique.PREFIXED_PROTOBUF_NATIVE_ENCODED) == report
    # un-prefixed input is still accepted (Goby's backward compatibility)
    assert techniques.parse(R_TEXT, pb.BasicNodeReport(), Technique.PREFIXED_PROTOBUF_TEXT_FORMAT) == report
    # a prefix with no body clears the message
    assert techniques.parse(PREFIX.strip(), pb.BasicNodeReport(Name="x")) == pb.BasicNodeReport()


def test_prefixed_errors(pb):
    with pytest.raises(TechniqueError, match=r"Expected: goby.test.moos.protobuf.TestMsg, received: goby.test.moos.protobuf.BasicNodeReport"):
        techniques.parse(PREFIX + R_TEXT, pb.TestMsg())
    with pytest.raises(TechniqueError, match="Incorrectly formatted protobuf message.*PREFIXED_PROTOBUF_TEXT_FORMAT"):
        techniques.parse("@PB[goby.test", pb.TestMsg())


def test_dynamic_parse(report, pb):
    assert techniques.dynamic_parse(PREFIX + R_TEXT) == report
    binary = techniques.serialize(report, Technique.PREFIXED_PROTOBUF_NATIVE_ENCODED)
    assert techniques.dynamic_parse(binary, Technique.PREFIXED_PROTOBUF_NATIVE_ENCODED) == report
    assert techniques.dynamic_parse(R_TEXT) is None
    with pytest.raises(TechniqueError, match="Unknown Protobuf type: no.such.Type"):
        techniques.dynamic_parse("@PB[no.such.Type] a: 1")
    with pytest.raises(TechniqueError, match="Non-PREFIX"):
        techniques.dynamic_parse(R_TEXT, Technique.FORMAT)


def test_key_values_serialize(report, pb):
    assert techniques.serialize(report, Technique.COMMA_SEPARATED_KEY_EQUALS_VALUE_PAIRS) == (
        "Name=unicorn,x=550,y=1023.5,heading=240,repeat={1,-1,2}"
    )
    msg = pb.TestMsg(
        enum_default_optional=pb.ENUM_C,
        msg_default_optional=pb.EmbeddedMsg1(val=19.998),
        msg_default_repeat=[pb.EmbeddedMsg1(val=1), pb.EmbeddedMsg1(val=2.5)],
        bytes_default_optional=b"\x01\xab",
    )
    assert techniques.to_key_values(msg) == (
        "bytes_default_optional=01ab,enum_default_optional=ENUM_C,"
        "msg_default_optional_val=19.998,msg_default_optional_msg=,"
        "msg_default_repeat_val={1,2.5},msg_default_repeat_msg={,}"
    )
    assert techniques.to_key_values(pb.TestMsg(enum_default_optional=pb.ENUM_C), use_short_enum=True) == (
        "enum_default_optional=ENUM_C"  # prefix is the field name, not the enum's
    )


def test_key_values_parse(report, pb):
    text = "Name=unicorn,x=550,y=1023.5,heading=240,repeat={1,-1,2}"
    assert techniques.parse(text, pb.BasicNodeReport(), Technique.COMMA_SEPARATED_KEY_EQUALS_VALUE_PAIRS) == report
    # the whole input is lowercased first; keys match anywhere a key starts (not inside "xname=")
    parsed = techniques.from_key_values("XNAME=no,NAME=UniCorn,X=abc", pb.BasicNodeReport())
    assert parsed.Name == "unicorn" and math.isnan(parsed.x)
    nested = techniques.from_key_values(
        "msg_default_optional_val=19.998,msg_default_repeat_val={1,2.5},enum_default_optional=enum_b,"
        "uint64_default_optional=-1,int32_default_optional=2.5,bool_default_optional=1",
        pb.TestMsg(),
    )
    assert nested.msg_default_optional.val == 19.998
    assert [m.val for m in nested.msg_default_repeat] == [1, 2.5]
    assert nested.enum_default_optional == pb.ENUM_B
    assert nested.uint64_default_optional == 2**64 - 1  # lexical_cast wraps -1
    assert nested.int32_default_optional == 2**31 - 1  # failed cast -> max
    assert nested.bool_default_optional is True


def test_format_serialize_and_round_trip(pb):
    msg = pb.BasicNodeReport(Name="unicorn", x=550, y=1023.5, heading=240, repeat=[1, -1, 2, -2, 3, -3, 4, -4, 5, -5, 6, -6])
    fmt = "NAME=%1%,X=%202%,Y=%3%,HEADING=%201%,REPEAT={%10%},REPEAT={" + ",".join(f"%10.{i}%" for i in range(12)) + "}"
    text = techniques.serialize(msg, Technique.FORMAT, format=fmt)
    assert text == (
        "NAME=unicorn,X=550,Y=1023.5,HEADING=240,REPEAT={1,-1,2,-2,3,-3,4,-4,5,-5,6,-6},"
        "REPEAT={1,-1,2,-2,3,-3,4,-4,5,-5,6,-6}"
    )
    back = techniques.parse(text, pb.BasicNodeReport(), Technique.FORMAT, format=fmt)
    assert back.SerializeToString() == msg.SerializeToString()


def test_format_unknown_numbers_and_literal_percent(report):
    assert techniques.format_message(report, "%1%:%5%:%300%:100%%") == "unicorn:unknown::100%"
    with pytest.raises(TechniqueError, match="bad format"):
        techniques.format_message(report, "%s")


def test_format_embedded_paths(pb):
    msg = pb.TestMsg(msg_default_optional=pb.EmbeddedMsg1(val=19.998))
    assert techniques.format_message(msg, "em.val=%17:1%") == "em.val=19.998"
    assert techniques.parse_format("em.val=19.998", pb.TestMsg(), "em.val=%17:1%") == msg

    msg = pb.TestMsg(
        msg_default_repeat=[pb.EmbeddedMsg1(val=21.123), pb.EmbeddedMsg1(val=100.5)],
        msg_default_required=pb.EmbeddedMsg1(msg=pb.EmbeddedMsg2(val=45)),
        uint64_default_repeat=[0, 100, 200],
    )
    fmt = (
        "em0.val=%117.0:1%,1uint64=%106.1%,0uint64=%106.0%.2uint64=%106.2%:em1.val=%117.1:1%,"
        "dbl0=%101.0%,dbl1=%101.1%,dbl2=%101.2%,dbl3=%101.3%,em0.em1.val=%37:2:1%"
    )
    text = techniques.format_message(msg, fmt)
    assert text == (
        "em0.val=21.123,1uint64=100,0uint64=0.2uint64=200:em1.val=100.5,"
        "dbl0=nan,dbl1=nan,dbl2=nan,dbl3=nan,em0.em1.val=45"
    )
    back = techniques.parse_format(text, pb.TestMsg(), fmt)
    assert len(back.double_default_repeat) == 4 and all(math.isnan(v) for v in back.double_default_repeat)
    del back.double_default_repeat[:]
    assert back == msg


def test_format_errors(pb, report):
    with pytest.raises(TechniqueError, match="Invalid ':' syntax"):
        techniques.format_message(pb.TestMsg(), "%1:1%")
    with pytest.raises(TechniqueError, match="Invalid '.' syntax"):
        techniques.format_message(pb.TestMsg(), "%117:1%")
    with pytest.raises(TechniqueError, match="Bad field: 99 not in message goby.test.moos.protobuf.BasicNodeReport"):
        techniques.parse_format("a", pb.BasicNodeReport(), "%99%")
    with pytest.raises(TechniqueError, match="Bad specifier: x"):
        techniques.parse_format("a", pb.BasicNodeReport(), "%x%")
    with pytest.raises(TechniqueError, match="needs a format"):
        techniques.serialize(report, Technique.FORMAT)


def test_format_parse_empty_double_is_nan(pb):
    assert math.isnan(techniques.parse_format("", pb.BasicNodeReport(), "%202%").x)


def test_technique_numbers_follow_the_proto():
    from gateway.moos_gateway.protobuf.translator_pb2 import TranslatorEntry

    for technique in Technique:
        assert TranslatorEntry.ParserSerializerTechnique.Value(technique.proto_name) == technique
