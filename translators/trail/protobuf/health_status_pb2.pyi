from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class HealthStatus(_message.Message):
    __slots__ = ("state", "timestamp")
    class HealthState(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        GOOD: _ClassVar[HealthStatus.HealthState]
        DEGRADED: _ClassVar[HealthStatus.HealthState]
        FAILING: _ClassVar[HealthStatus.HealthState]
        FAILED: _ClassVar[HealthStatus.HealthState]
    GOOD: HealthStatus.HealthState
    DEGRADED: HealthStatus.HealthState
    FAILING: HealthStatus.HealthState
    FAILED: HealthStatus.HealthState
    STATE_FIELD_NUMBER: _ClassVar[int]
    TIMESTAMP_FIELD_NUMBER: _ClassVar[int]
    state: HealthStatus.HealthState
    timestamp: int
    def __init__(self, state: _Optional[_Union[HealthStatus.HealthState, str]] = ..., timestamp: _Optional[int] = ...) -> None: ...
