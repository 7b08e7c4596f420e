from launch.liaison.protobuf import liaison_config_pb2 as _liaison_config_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor
WEB_FIELD_NUMBER: _ClassVar[int]
web: _descriptor.FieldDescriptor

class Point(_message.Message):
    __slots__ = ("x", "y")
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ...) -> None: ...

class MapConfig(_message.Message):
    __slots__ = ("waypoint", "loiter_polygon", "center_activate", "trail_points")
    WAYPOINT_FIELD_NUMBER: _ClassVar[int]
    LOITER_POLYGON_FIELD_NUMBER: _ClassVar[int]
    CENTER_ACTIVATE_FIELD_NUMBER: _ClassVar[int]
    TRAIL_POINTS_FIELD_NUMBER: _ClassVar[int]
    waypoint: _containers.RepeatedCompositeFieldContainer[Point]
    loiter_polygon: _containers.RepeatedCompositeFieldContainer[Point]
    center_activate: bool
    trail_points: int
    def __init__(self, waypoint: _Optional[_Iterable[_Union[Point, _Mapping]]] = ..., loiter_polygon: _Optional[_Iterable[_Union[Point, _Mapping]]] = ..., center_activate: _Optional[bool] = ..., trail_points: _Optional[int] = ...) -> None: ...

class InterProcessAck(_message.Message):
    __slots__ = ("command_type", "ack_type", "ack_group", "command_field", "ack_field", "final_field", "final_value", "refused_value", "timeout")
    COMMAND_TYPE_FIELD_NUMBER: _ClassVar[int]
    ACK_TYPE_FIELD_NUMBER: _ClassVar[int]
    ACK_GROUP_FIELD_NUMBER: _ClassVar[int]
    COMMAND_FIELD_FIELD_NUMBER: _ClassVar[int]
    ACK_FIELD_FIELD_NUMBER: _ClassVar[int]
    FINAL_FIELD_FIELD_NUMBER: _ClassVar[int]
    FINAL_VALUE_FIELD_NUMBER: _ClassVar[int]
    REFUSED_VALUE_FIELD_NUMBER: _ClassVar[int]
    TIMEOUT_FIELD_NUMBER: _ClassVar[int]
    command_type: str
    ack_type: str
    ack_group: str
    command_field: str
    ack_field: str
    final_field: str
    final_value: _containers.RepeatedScalarFieldContainer[str]
    refused_value: str
    timeout: float
    def __init__(self, command_type: _Optional[str] = ..., ack_type: _Optional[str] = ..., ack_group: _Optional[str] = ..., command_field: _Optional[str] = ..., ack_field: _Optional[str] = ..., final_field: _Optional[str] = ..., final_value: _Optional[_Iterable[str]] = ..., refused_value: _Optional[str] = ..., timeout: _Optional[float] = ...) -> None: ...

class WebConfig(_message.Message):
    __slots__ = ("load_python_module", "map", "interprocess_ack", "client_queue_updates", "max_clients", "max_scope_rows", "command_history", "allowed_host")
    LOAD_PYTHON_MODULE_FIELD_NUMBER: _ClassVar[int]
    MAP_FIELD_NUMBER: _ClassVar[int]
    INTERPROCESS_ACK_FIELD_NUMBER: _ClassVar[int]
    CLIENT_QUEUE_UPDATES_FIELD_NUMBER: _ClassVar[int]
    MAX_CLIENTS_FIELD_NUMBER: _ClassVar[int]
    MAX_SCOPE_ROWS_FIELD_NUMBER: _ClassVar[int]
    COMMAND_HISTORY_FIELD_NUMBER: _ClassVar[int]
    ALLOWED_HOST_FIELD_NUMBER: _ClassVar[int]
    load_python_module: _containers.RepeatedScalarFieldContainer[str]
    map: MapConfig
    interprocess_ack: _containers.RepeatedCompositeFieldContainer[InterProcessAck]
    client_queue_updates: int
    max_clients: int
    max_scope_rows: int
    command_history: int
    allowed_host: _containers.RepeatedScalarFieldContainer[str]
    def __init__(self, load_python_module: _Optional[_Iterable[str]] = ..., map: _Optional[_Union[MapConfig, _Mapping]] = ..., interprocess_ack: _Optional[_Iterable[_Union[InterProcessAck, _Mapping]]] = ..., client_queue_updates: _Optional[int] = ..., max_clients: _Optional[int] = ..., max_scope_rows: _Optional[int] = ..., command_history: _Optional[int] = ..., allowed_host: _Optional[_Iterable[str]] = ...) -> None: ...
