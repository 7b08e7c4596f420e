from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class NavigationReport(_message.Message):
    __slots__ = ("vehicle", "time", "x", "y", "z", "speed_over_ground", "heading", "type")
    class VehicleClass(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        AUV: _ClassVar[NavigationReport.VehicleClass]
        USV: _ClassVar[NavigationReport.VehicleClass]
        TOPSIDE: _ClassVar[NavigationReport.VehicleClass]
        OTHER: _ClassVar[NavigationReport.VehicleClass]
    AUV: NavigationReport.VehicleClass
    USV: NavigationReport.VehicleClass
    TOPSIDE: NavigationReport.VehicleClass
    OTHER: NavigationReport.VehicleClass
    VEHICLE_FIELD_NUMBER: _ClassVar[int]
    TIME_FIELD_NUMBER: _ClassVar[int]
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    SPEED_OVER_GROUND_FIELD_NUMBER: _ClassVar[int]
    HEADING_FIELD_NUMBER: _ClassVar[int]
    TYPE_FIELD_NUMBER: _ClassVar[int]
    vehicle: int
    time: float
    x: float
    y: float
    z: float
    speed_over_ground: float
    heading: float
    type: NavigationReport.VehicleClass
    def __init__(self, vehicle: _Optional[int] = ..., time: _Optional[float] = ..., x: _Optional[float] = ..., y: _Optional[float] = ..., z: _Optional[float] = ..., speed_over_ground: _Optional[float] = ..., heading: _Optional[float] = ..., type: _Optional[_Union[NavigationReport.VehicleClass, str]] = ...) -> None: ...
