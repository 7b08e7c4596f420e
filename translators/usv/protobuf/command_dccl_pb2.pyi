from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class USVCommand(_message.Message):
    __slots__ = ("time", "desired_state", "polygon_sides", "polygon_radius")
    class AutonomyState(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        WAYPOINTS: _ClassVar[USVCommand.AutonomyState]
        POLYGON: _ClassVar[USVCommand.AutonomyState]
    WAYPOINTS: USVCommand.AutonomyState
    POLYGON: USVCommand.AutonomyState
    TIME_FIELD_NUMBER: _ClassVar[int]
    DESIRED_STATE_FIELD_NUMBER: _ClassVar[int]
    POLYGON_SIDES_FIELD_NUMBER: _ClassVar[int]
    POLYGON_RADIUS_FIELD_NUMBER: _ClassVar[int]
    time: float
    desired_state: USVCommand.AutonomyState
    polygon_sides: int
    polygon_radius: int
    def __init__(self, time: _Optional[float] = ..., desired_state: _Optional[_Union[USVCommand.AutonomyState, str]] = ..., polygon_sides: _Optional[int] = ..., polygon_radius: _Optional[int] = ...) -> None: ...

class AUVCommand(_message.Message):
    __slots__ = ("time", "desired_state")
    class AutonomyState(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        TRAIL: _ClassVar[AUVCommand.AutonomyState]
        RECOVER: _ClassVar[AUVCommand.AutonomyState]
    TRAIL: AUVCommand.AutonomyState
    RECOVER: AUVCommand.AutonomyState
    TIME_FIELD_NUMBER: _ClassVar[int]
    DESIRED_STATE_FIELD_NUMBER: _ClassVar[int]
    time: float
    desired_state: AUVCommand.AutonomyState
    def __init__(self, time: _Optional[float] = ..., desired_state: _Optional[_Union[AUVCommand.AutonomyState, str]] = ...) -> None: ...
