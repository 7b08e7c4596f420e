from gateway.goby.protobuf import app_config_pb2 as _app_config_pb2
from gateway.goby.protobuf import interprocess_config_pb2 as _interprocess_config_pb2
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class Helm(_message.Message):
    __slots__ = ("app", "interprocess", "speed", "east_duration", "south_duration", "closing_window")
    APP_FIELD_NUMBER: _ClassVar[int]
    INTERPROCESS_FIELD_NUMBER: _ClassVar[int]
    SPEED_FIELD_NUMBER: _ClassVar[int]
    EAST_DURATION_FIELD_NUMBER: _ClassVar[int]
    SOUTH_DURATION_FIELD_NUMBER: _ClassVar[int]
    CLOSING_WINDOW_FIELD_NUMBER: _ClassVar[int]
    app: _app_config_pb2.AppConfig
    interprocess: _interprocess_config_pb2.InterProcessPortalConfig
    speed: float
    east_duration: int
    south_duration: int
    closing_window: int
    def __init__(self, app: _Optional[_Union[_app_config_pb2.AppConfig, _Mapping]] = ..., interprocess: _Optional[_Union[_interprocess_config_pb2.InterProcessPortalConfig, _Mapping]] = ..., speed: _Optional[float] = ..., east_duration: _Optional[int] = ..., south_duration: _Optional[int] = ..., closing_window: _Optional[int] = ...) -> None: ...
