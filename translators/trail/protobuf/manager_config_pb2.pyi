from gateway.goby.protobuf import app_config_pb2 as _app_config_pb2
from gateway.goby.protobuf import interprocess_config_pb2 as _interprocess_config_pb2
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class AUVManager(_message.Message):
    __slots__ = ("app", "interprocess", "usv_modem_id", "vehicle_id")
    APP_FIELD_NUMBER: _ClassVar[int]
    INTERPROCESS_FIELD_NUMBER: _ClassVar[int]
    USV_MODEM_ID_FIELD_NUMBER: _ClassVar[int]
    VEHICLE_ID_FIELD_NUMBER: _ClassVar[int]
    app: _app_config_pb2.AppConfig
    interprocess: _interprocess_config_pb2.InterProcessPortalConfig
    usv_modem_id: int
    vehicle_id: int
    def __init__(self, app: _Optional[_Union[_app_config_pb2.AppConfig, _Mapping]] = ..., interprocess: _Optional[_Union[_interprocess_config_pb2.InterProcessPortalConfig, _Mapping]] = ..., usv_modem_id: _Optional[int] = ..., vehicle_id: _Optional[int] = ...) -> None: ...

class TopsideManager(_message.Message):
    __slots__ = ("app", "interprocess", "usv_modem_id", "vehicle_id", "vehicle_name_prefix")
    APP_FIELD_NUMBER: _ClassVar[int]
    INTERPROCESS_FIELD_NUMBER: _ClassVar[int]
    USV_MODEM_ID_FIELD_NUMBER: _ClassVar[int]
    VEHICLE_ID_FIELD_NUMBER: _ClassVar[int]
    VEHICLE_NAME_PREFIX_FIELD_NUMBER: _ClassVar[int]
    app: _app_config_pb2.AppConfig
    interprocess: _interprocess_config_pb2.InterProcessPortalConfig
    usv_modem_id: int
    vehicle_id: int
    vehicle_name_prefix: str
    def __init__(self, app: _Optional[_Union[_app_config_pb2.AppConfig, _Mapping]] = ..., interprocess: _Optional[_Union[_interprocess_config_pb2.InterProcessPortalConfig, _Mapping]] = ..., usv_modem_id: _Optional[int] = ..., vehicle_id: _Optional[int] = ..., vehicle_name_prefix: _Optional[str] = ...) -> None: ...
