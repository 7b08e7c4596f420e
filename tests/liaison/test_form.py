"""The commander's form schema and the server-side check of what a browser sends back."""

from __future__ import annotations

import pytest

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from launch.liaison.errors import CommandRefused
from launch.liaison.form_schema import message_schema
from launch.liaison.form_values import build_command
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand


def now() -> float:
    return 1234.5


def fields(schema):
    return {f["name"]: f for f in schema["fields"]}


def test_usv_command_schema_carries_the_dccl_bounds():
    f = fields(message_schema(USVCommand.DESCRIPTOR))
    expected = {"kind": "int", "min": 3, "max": 10, "step": 1, "dccl_bounds": True, "label": "optional"}
    assert {k: f["polygon_sides"][k] for k in expected} == expected
    assert f["polygon_radius"]["min"] == 100 and f["polygon_radius"]["max"] == 2000
    assert f["polygon_radius"]["step"] == 10  # precision -1
    assert f["desired_state"]["enum"] == ["WAYPOINTS", "POLYGON"] and f["desired_state"]["label"] == "required"
    assert f["time"]["auto_time"] is True  # dccl.time2: filled when sent


def test_nested_and_repeated_fields_are_described():
    f = fields(message_schema(NodeStatus.DESCRIPTOR))
    assert f["global_fix"]["kind"] == "message" and f["global_fix"]["label"] == "required"
    assert {"lat", "lon"} <= set(fields(f["global_fix"]["message"]))
    assert f["global_fix"]["message"]["fields"][3]["default"] == "nan"  # altitude: JSON has no NaN
    repeated = fields(message_schema(USVCommandAck.DESCRIPTOR))["moos_post"]
    assert repeated["label"] == "repeated" and repeated["max_repeat"] > 0


def test_a_valid_command_is_built_with_the_time_filled_in():
    msg = build_command(USVCommand, {"desired_state": "POLYGON", "polygon_sides": "8", "polygon_radius": 404}, now)
    assert msg.time == 1234.5 and msg.polygon_sides == 8
    assert msg.polygon_radius == 400  # rounded to its DCCL precision, as the link would


@pytest.mark.parametrize(
    ("values", "field", "words"),
    [
        ({"desired_state": "POLYGON", "polygon_radius": 5000}, "polygon_radius", "outside its DCCL bounds"),
        ({"desired_state": "POLYGON", "polygon_sides": "eight"}, "polygon_sides", "not a number"),
        ({"desired_state": "POLYGON", "polygon_sides": 3.5}, "polygon_sides", "not a whole number"),
        ({"desired_state": "SPIN"}, "desired_state", "not one of WAYPOINTS, POLYGON"),
        ({"polygon_sides": 4}, "desired_state", "is required"),
        ({"desired_state": "POLYGON", "radius": 4}, "radius", "no field named 'radius'"),
        ({"desired_state": "POLYGON", "polygon_sides": 2**40}, "polygon_sides", "outside the range of int"),
        ({"desired_state": "POLYGON", "polygon_sides": True}, "polygon_sides", "expected a number"),
        ({"desired_state": "POLYGON", "polygon_sides": "nan"}, "polygon_sides", "not a finite number"),
        ("POLYGON", "", "expected an object"),
    ],
)
def test_bad_values_are_refused_naming_the_field(values, field, words):
    with pytest.raises(CommandRefused) as refused:
        build_command(USVCommand, values, now)
    assert refused.value.field == field
    assert words in str(refused.value)


def test_nested_repeated_and_bytes_values():
    status = build_command(NodeStatus, {
        "time": 1, "name": "x", "global_fix": {"lat": "21.5", "lon": -159.5}, "pose": {"heading": 90},
        "speed": {"over_ground": 1.5}, "type": "USV"}, now)
    assert status.global_fix.lat == 21.5 and status.pose.heading == 90
    ack = build_command(USVCommandAck, {"stage": "POSTED_TO_MOOS", "moos_post": ["A=1", "B=2"]}, now)
    assert list(ack.moos_post) == ["A=1", "B=2"]
    with pytest.raises(CommandRefused, match=r"global_fix.lat is required"):
        build_command(NodeStatus, {"time": 1, "global_fix": {"lon": 1}, "pose": {}, "speed": {"over_ground": 1}},
                      now)
    with pytest.raises(CommandRefused, match=r"moos_post\[1\]: empty value"):
        build_command(USVCommandAck, {"stage": "REFUSED", "moos_post": ["A=1", ""]}, now)
    with pytest.raises(CommandRefused, match=r"expected a list"):
        build_command(USVCommandAck, {"stage": "REFUSED", "moos_post": "A=1"}, now)
