from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class USVCommandAck(_message.Message):
    __slots__ = ("stage", "command_time", "responder", "error", "moos_post", "command", "slot_wait", "link_latency")
    class Stage(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        RECEIVED_BY_MANAGER: _ClassVar[USVCommandAck.Stage]
        POSTED_TO_MOOS: _ClassVar[USVCommandAck.Stage]
        REFUSED: _ClassVar[USVCommandAck.Stage]
        LINK_ACKED: _ClassVar[USVCommandAck.Stage]
        LINK_EXPIRED: _ClassVar[USVCommandAck.Stage]
    RECEIVED_BY_MANAGER: USVCommandAck.Stage
    POSTED_TO_MOOS: USVCommandAck.Stage
    REFUSED: USVCommandAck.Stage
    LINK_ACKED: USVCommandAck.Stage
    LINK_EXPIRED: USVCommandAck.Stage
    STAGE_FIELD_NUMBER: _ClassVar[int]
    COMMAND_TIME_FIELD_NUMBER: _ClassVar[int]
    RESPONDER_FIELD_NUMBER: _ClassVar[int]
    ERROR_FIELD_NUMBER: _ClassVar[int]
    MOOS_POST_FIELD_NUMBER: _ClassVar[int]
    COMMAND_FIELD_NUMBER: _ClassVar[int]
    SLOT_WAIT_FIELD_NUMBER: _ClassVar[int]
    LINK_LATENCY_FIELD_NUMBER: _ClassVar[int]
    stage: USVCommandAck.Stage
    command_time: float
    responder: str
    error: str
    moos_post: _containers.RepeatedScalarFieldContainer[str]
    command: str
    slot_wait: float
    link_latency: float
    def __init__(self, stage: _Optional[_Union[USVCommandAck.Stage, str]] = ..., command_time: _Optional[float] = ..., responder: _Optional[str] = ..., error: _Optional[str] = ..., moos_post: _Optional[_Iterable[str]] = ..., command: _Optional[str] = ..., slot_wait: _Optional[float] = ..., link_latency: _Optional[float] = ...) -> None: ...
