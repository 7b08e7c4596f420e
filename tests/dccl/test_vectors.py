"""Golden vectors: the C++ dccl::Codec's bytes (DCCL 4.2) for the course's messages, both ways, and the
worked examples of the DCCL wire format (USVCommand, AUVCommand, Goby's Subscription)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from google.protobuf import text_format

from gateway.goby.dccl import Codec, DecodeError, EncodeError
from tests.dccl.conftest import BY_NAME, build
from tests.protobuf import dccl_test_pb2 as pb
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand, USVCommand

VECTORS = json.loads((Path(__file__).parent / "dccl_vectors.json").read_text())


def vector_codec(vector: dict) -> Codec:
    codec = Codec(clock=lambda: vector["decode_clock_epoch_s"])
    codec.load(BY_NAME[vector["message"]])
    return codec


@pytest.mark.parametrize("vector", VECTORS, ids=[f"{v['message'].rsplit('.', 1)[1]}: {v['case']}" for v in VECTORS])
def test_cpp_vector_encodes_to_its_hex(vector):
    codec = vector_codec(vector)
    message_type = BY_NAME[vector["message"]]
    msg = build(message_type, vector["fields"])
    if vector["encode_error"]:
        with pytest.raises(EncodeError):
            codec.encode(msg)
        return
    data = codec.encode(msg)
    assert data.hex() == vector["hex"]
    assert codec.size(msg) == vector["size"] == len(data)
    assert codec.id_from_encoded(data) == vector["dccl_id"]
    assert (codec.min_size(message_type), codec.max_size(message_type)) == (
        vector["codec_min_size"], vector["codec_max_size"])


@pytest.mark.parametrize("vector", VECTORS, ids=[f"{v['message'].rsplit('.', 1)[1]}: {v['case']}" for v in VECTORS])
def test_cpp_vector_decodes_to_the_recorded_values_at_the_recorded_clock(vector):
    codec = vector_codec(vector)
    message_type = BY_NAME[vector["message"]]
    data = bytes.fromhex(vector["hex"])
    if vector["decode_error"]:
        with pytest.raises(DecodeError):
            codec.decode(data)
        return
    decoded = codec.decode(data)
    assert decoded == build(message_type, vector["decoded"])
    assert decoded == text_format.Parse(vector["decoded_text"], message_type())
    assert codec.decode_prefix(data + b"\x01\x02") == (decoded, b"\x01\x02")


# Worked examples of the wire format: 2021-06-01T12:00:10.4Z.
EXAMPLE_TIME = 1622548810.4


@pytest.mark.parametrize(
    ("msg", "hex_bytes"),
    [
        (USVCommand(time=EXAMPLE_TIME, desired_state=USVCommand.POLYGON, polygon_sides=6, polygon_radius=200),
         "fccaa8d202"),
        (USVCommand(time=EXAMPLE_TIME, desired_state=USVCommand.WAYPOINTS), "fccaa80000"),
        (USVCommand(time=EXAMPLE_TIME, desired_state=USVCommand.POLYGON, polygon_sides=6, polygon_radius=204),
         "fccaa8d202"),
        (AUVCommand(time=EXAMPLE_TIME, desired_state=AUVCommand.RECOVER), "fecaa802"),
    ],
)
def test_worked_examples(msg, hex_bytes):
    codec = Codec()
    codec.load(type(msg))
    assert codec.encode(msg).hex() == hex_bytes


def test_radius_205_rounds_up_to_210_and_2500_is_sent_as_unset():
    codec = Codec(clock=lambda: EXAMPLE_TIME)
    codec.load(USVCommand)
    up = codec.decode(codec.encode(USVCommand(time=EXAMPLE_TIME, desired_state=2, polygon_sides=6, polygon_radius=205)))
    assert up.polygon_radius == 210
    out = codec.decode(codec.encode(USVCommand(time=EXAMPLE_TIME, desired_state=2, polygon_sides=11,
                                               polygon_radius=2500)))
    assert not out.HasField("polygon_radius") and not out.HasField("polygon_sides")


def test_goby_subscription_example():
    """AUV0's broadcast subscription to usv_nav: head = id 3 + api_version, body 137 bits, 20 bytes."""
    sub = pb.Subscription(api_version=1, action=pb.Subscription.SUBSCRIBE, dccl_id=124, group=1)
    sub.header.src = 256
    sub.header.dest.append(258)
    sub.intervehicle.buffer.ack_required = False
    sub.intervehicle.buffer.max_queue = 1
    sub.intervehicle.buffer.newest_first = True
    sub.intervehicle.broadcast = True
    codec = Codec()
    codec.load(pb.Subscription)
    data = codec.encode(sub)
    assert data.hex(" ") == "06 00 00 01 11 08 80 1f 00 00 00 10 06 00 01 08 00 00 00 01"
    assert codec.decode(data) == sub
