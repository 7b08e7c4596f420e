from gateway.goby.protobuf import app_config_pb2 as _app_config_pb2
from gateway.goby.protobuf import interprocess_config_pb2 as _interprocess_config_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class USVManager(_message.Message):
    __slots__ = ("app", "interprocess", "vehicle_id", "auv_modem_id")
    APP_FIELD_NUMBER: _ClassVar[int]
    INTERPROCESS_FIELD_NUMBER: _ClassVar[int]
    VEHICLE_ID_FIELD_NUMBER: _ClassVar[int]
    AUV_MODEM_ID_FIELD_NUMBER: _ClassVar[int]
    app: _app_config_pb2.AppConfig
    interprocess: _interprocess_config_pb2.InterProcessPortalConfig
    vehicle_id: int
    auv_modem_id: _containers.RepeatedScalarFieldContainer[int]
    def __init__(self, app: _Optional[_Union[_app_config_pb2.AppConfig, _Mapping]] = ..., interprocess: _Optional[_Union[_interprocess_config_pb2.InterProcessPortalConfig, _Mapping]] = ..., vehicle_id: _Optional[int] = ..., auv_modem_id: _Optional[_Iterable[int]] = ...) -> None: ...

class CommandTool(_message.Message):
    __slots__ = ("app", "interprocess", "ack_timeout", "intervehicle")
    APP_FIELD_NUMBER: _ClassVar[int]
    INTERPROCESS_FIELD_NUMBER: _ClassVar[int]
    ACK_TIMEOUT_FIELD_NUMBER: _ClassVar[int]
    INTERVEHICLE_FIELD_NUMBER: _ClassVar[int]
    app: _app_config_pb2.AppConfig
    interprocess: _interprocess_config_pb2.InterProcessPortalConfig
    ack_timeout: float
    intervehicle: bool
    def __init__(self, app: _Optional[_Union[_app_config_pb2.AppConfig, _Mapping]] = ..., interprocess: _Optional[_Union[_interprocess_config_pb2.InterProcessPortalConfig, _Mapping]] = ..., ack_timeout: _Optional[float] = ..., intervehicle: _Optional[bool] = ...) -> None: ...
