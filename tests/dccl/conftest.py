"""Shared helpers of the DCCL tests: the course's message types and building messages from plain values."""

from __future__ import annotations

from typing import Any

import pytest
from google.protobuf.message import Message

from gateway.goby.dccl import Codec
from translators.trail.protobuf.health_status_pb2 import HealthStatus
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import AUVCommand, USVCommand

COURSE_TYPES = (NavigationReport, HealthStatus, USVCommand, AUVCommand)
BY_NAME = {t.DESCRIPTOR.full_name: t for t in COURSE_TYPES}


def build(message_type: type[Message], values: dict[str, Any]) -> Message:
    """A message from field values as JSON gives them (enums by name)."""
    msg = message_type()
    for name, value in values.items():
        field = message_type.DESCRIPTOR.fields_by_name[name]
        if isinstance(value, str) and field.enum_type is not None:
            value = field.enum_type.values_by_name[value].number
        setattr(msg, name, value)
    return msg


@pytest.fixture
def course_codec() -> Codec:
    """A codec with the course's four DCCL messages loaded and its clock at 2023-11-14T22:13:20Z."""
    codec = Codec(clock=lambda: 1700000000)
    for message_type in COURSE_TYPES:
        codec.load(message_type)
    return codec
