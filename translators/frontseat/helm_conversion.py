"""pHelmIvP's MOOS outputs -> Goby frontseat messages: DESIRED_* -> DesiredCourse, IVPHELM_STATE -> HelmState.

Pure functions over ``MoosMessage`` values so the fallback rules can be tested without a MOOSDB.
"""

from __future__ import annotations

from collections.abc import MutableMapping

from frontseat.protobuf.frontseat_data_pb2 import DesiredCourse
from frontseat.protobuf.frontseat_pb2 import HELM_DRIVE, HELM_NOT_RUNNING, HELM_PARK, HelmState
from gateway.moos.message import MoosMessage
from translators.errors import TranslatorError

DESIRED_SPEED = "DESIRED_SPEED"
IVPHELM_STATE = "IVPHELM_STATE"

# DESIRED_* variable -> DesiredCourse field, in the order Goby fills them after speed.
OPTIONAL_SETPOINTS: tuple[tuple[str, str], ...] = (
    ("DESIRED_HEADING", "heading"),
    ("DESIRED_PITCH", "pitch"),
    ("DESIRED_ROLL", "roll"),
    ("DESIRED_DEPTH", "depth"),
    ("DESIRED_ALTITUDE", "altitude"),
    ("DESIRED_Z_RATE", "z_rate"),
)

# Every variable the translator buffers (DESIRED_SPEED is both buffered and the trigger).
BUFFERED_SETPOINTS: tuple[str, ...] = (
    DESIRED_SPEED,
    "DESIRED_HEADING",
    "DESIRED_DEPTH",
    "DESIRED_PITCH",
    "DESIRED_ROLL",
    "DESIRED_Z_RATE",
    "DESIRED_ALTITUDE",
)


class SetpointError(TranslatorError, ValueError):
    """A DESIRED_* message that cannot be a setpoint (for example a string where a number belongs)."""


def setpoint_value(msg: MoosMessage) -> float:
    """The numeric value of a DESIRED_* message; strings are refused (pHelmIvP posts doubles)."""
    if not msg.is_double():
        raise SetpointError(f"{msg.key()} must be a number, got the string {msg.string()!r} from {msg.source()!r}")
    return msg.double()


def desired_course(
    speed_msg: MoosMessage, buffer: MutableMapping[str, MoosMessage]
) -> tuple[DesiredCourse, list[SetpointError]]:
    """The DesiredCourse for one DESIRED_SPEED, consuming the other setpoints from ``buffer``.

    As Goby's frontseat translator: ``time`` is the DESIRED_SPEED message's MOOS time, ``speed`` its value,
    and each other DESIRED_* present in the buffer is set and then erased, so a setpoint is used at most once
    and fields not posted since the previous DESIRED_SPEED keep the proto defaults (altitude 10, others 0).
    DESIRED_SPEED itself stays in the buffer. Bad setpoints are erased too and returned as errors (the course
    is still published with the good ones); a bad DESIRED_SPEED raises :class:`SetpointError`.
    """
    course = DesiredCourse(time=speed_msg.time(), speed=setpoint_value(speed_msg))
    errors: list[SetpointError] = []
    for variable, field in OPTIONAL_SETPOINTS:
        msg = buffer.pop(variable, None)
        if msg is None:
            continue
        try:
            setattr(course, field, setpoint_value(msg))
        except SetpointError as error:
            errors.append(error)
    return course, errors


def helm_state(value: str) -> HelmState.ValueType:
    """IVPHELM_STATE -> HelmState: ``drive``/``park`` (trimmed, any case), anything else NOT_RUNNING."""
    word = value.strip().lower()
    if word == "drive":
        return HELM_DRIVE
    if word == "park":
        return HELM_PARK
    return HELM_NOT_RUNNING
