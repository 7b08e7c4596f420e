"""DESIRED_* -> DesiredCourse (the fallback rules) and IVPHELM_STATE -> HelmState."""

from __future__ import annotations

import pytest

from frontseat.protobuf.frontseat_pb2 import HELM_DRIVE, HELM_NOT_RUNNING, HELM_PARK
from gateway.moos.message import NOTIFY, MoosMessage
from translators.frontseat.helm_conversion import SetpointError, desired_course, helm_state


def number(key: str, value: float, t: float = 100.0) -> MoosMessage:
    return MoosMessage.double_msg(NOTIFY, key, value, t)


def text(key: str, value: str, t: float = 100.0) -> MoosMessage:
    return MoosMessage.string_msg(NOTIFY, key, value, t)


def test_speed_alone_gives_proto_defaults_for_everything_else():
    speed = number("DESIRED_SPEED", 1.5, t=1234.25)
    course, errors = desired_course(speed, {"DESIRED_SPEED": speed})
    assert errors == []
    assert course.time == 1234.25
    assert course.speed == 1.5
    assert not course.HasField("heading")
    assert (course.heading, course.depth, course.altitude) == (0.0, 0.0, 10.0)


def test_buffered_setpoints_are_used_once_and_speed_stays_buffered():
    speed = number("DESIRED_SPEED", 2.0)
    buffer = {
        "DESIRED_SPEED": speed,
        "DESIRED_HEADING": number("DESIRED_HEADING", 270.0),
        "DESIRED_DEPTH": number("DESIRED_DEPTH", 15.0),
        "DESIRED_PITCH": number("DESIRED_PITCH", 3.0),
        "DESIRED_ROLL": number("DESIRED_ROLL", -1.0),
        "DESIRED_Z_RATE": number("DESIRED_Z_RATE", 0.5),
        "DESIRED_ALTITUDE": number("DESIRED_ALTITUDE", 4.0),
    }
    course, errors = desired_course(speed, buffer)
    assert errors == []
    assert (course.heading, course.depth, course.pitch, course.roll, course.z_rate, course.altitude) == (
        270.0, 15.0, 3.0, -1.0, 0.5, 4.0,
    )
    assert list(buffer) == ["DESIRED_SPEED"]
    again, _ = desired_course(speed, buffer)
    assert not again.HasField("heading") and again.altitude == 10.0


def test_a_string_setpoint_is_reported_and_dropped_while_the_rest_is_published():
    speed = number("DESIRED_SPEED", 1.0)
    buffer = {"DESIRED_HEADING": text("DESIRED_HEADING", "north"), "DESIRED_DEPTH": number("DESIRED_DEPTH", 3.0)}
    course, errors = desired_course(speed, buffer)
    assert course.depth == 3.0 and not course.HasField("heading")
    assert len(errors) == 1 and "DESIRED_HEADING" in str(errors[0]) and "north" in str(errors[0])
    assert buffer == {}


def test_a_string_desired_speed_is_refused():
    with pytest.raises(SetpointError, match="DESIRED_SPEED"):
        desired_course(text("DESIRED_SPEED", "fast"), {})


@pytest.mark.parametrize(
    ("value", "state"),
    [
        ("DRIVE", HELM_DRIVE), ("drive", HELM_DRIVE), ("  Drive\n", HELM_DRIVE),
        ("PARK", HELM_PARK), ("park ", HELM_PARK),
        ("DRIVE+", HELM_NOT_RUNNING), ("PARK+", HELM_NOT_RUNNING), ("STANDBY", HELM_NOT_RUNNING),
        ("DISABLED", HELM_NOT_RUNNING), ("MALCONFIG", HELM_NOT_RUNNING), ("", HELM_NOT_RUNNING),
    ],
)
def test_helm_state(value, state):
    assert helm_state(value) == state
