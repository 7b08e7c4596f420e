from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class LatLonPoint(_message.Message):
    __slots__ = ("lat", "lon", "depth", "altitude")
    LAT_FIELD_NUMBER: _ClassVar[int]
    LON_FIELD_NUMBER: _ClassVar[int]
    DEPTH_FIELD_NUMBER: _ClassVar[int]
    ALTITUDE_FIELD_NUMBER: _ClassVar[int]
    lat: float
    lon: float
    depth: float
    altitude: float
    def __init__(self, lat: _Optional[float] = ..., lon: _Optional[float] = ..., depth: _Optional[float] = ..., altitude: _Optional[float] = ...) -> None: ...

class Waypoint(_message.Message):
    __slots__ = ("name", "location")
    NAME_FIELD_NUMBER: _ClassVar[int]
    LOCATION_FIELD_NUMBER: _ClassVar[int]
    name: str
    location: LatLonPoint
    def __init__(self, name: _Optional[str] = ..., location: _Optional[_Union[LatLonPoint, _Mapping]] = ...) -> None: ...

class Route(_message.Message):
    __slots__ = ("name", "point")
    NAME_FIELD_NUMBER: _ClassVar[int]
    POINT_FIELD_NUMBER: _ClassVar[int]
    name: str
    point: _containers.RepeatedCompositeFieldContainer[Waypoint]
    def __init__(self, name: _Optional[str] = ..., point: _Optional[_Iterable[_Union[Waypoint, _Mapping]]] = ...) -> None: ...
