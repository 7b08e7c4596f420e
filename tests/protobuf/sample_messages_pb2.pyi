from gateway.goby.protobuf import app_config_pb2 as _app_config_pb2
from gateway.goby.protobuf import interprocess_config_pb2 as _interprocess_config_pb2
from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class Sample(_message.Message):
    __slots__ = ("a", "temperature", "salinity", "depth", "sent_micro", "padding")
    A_FIELD_NUMBER: _ClassVar[int]
    TEMPERATURE_FIELD_NUMBER: _ClassVar[int]
    SALINITY_FIELD_NUMBER: _ClassVar[int]
    DEPTH_FIELD_NUMBER: _ClassVar[int]
    SENT_MICRO_FIELD_NUMBER: _ClassVar[int]
    PADDING_FIELD_NUMBER: _ClassVar[int]
    a: int
    temperature: float
    salinity: float
    depth: float
    sent_micro: int
    padding: bytes
    def __init__(self, a: _Optional[int] = ..., temperature: _Optional[float] = ..., salinity: _Optional[float] = ..., depth: _Optional[float] = ..., sent_micro: _Optional[int] = ..., padding: _Optional[bytes] = ...) -> None: ...

class Widget(_message.Message):
    __slots__ = ("b",)
    B_FIELD_NUMBER: _ClassVar[int]
    b: int
    def __init__(self, b: _Optional[int] = ...) -> None: ...

class DCCLSample(_message.Message):
    __slots__ = ("a",)
    A_FIELD_NUMBER: _ClassVar[int]
    a: int
    def __init__(self, a: _Optional[int] = ...) -> None: ...

class SampleAppConfig(_message.Message):
    __slots__ = ("app", "interprocess", "role", "count", "group", "publish_period")
    APP_FIELD_NUMBER: _ClassVar[int]
    INTERPROCESS_FIELD_NUMBER: _ClassVar[int]
    ROLE_FIELD_NUMBER: _ClassVar[int]
    COUNT_FIELD_NUMBER: _ClassVar[int]
    GROUP_FIELD_NUMBER: _ClassVar[int]
    PUBLISH_PERIOD_FIELD_NUMBER: _ClassVar[int]
    app: _app_config_pb2.AppConfig
    interprocess: _interprocess_config_pb2.InterProcessPortalConfig
    role: str
    count: int
    group: _containers.RepeatedScalarFieldContainer[str]
    publish_period: float
    def __init__(self, app: _Optional[_Union[_app_config_pb2.AppConfig, _Mapping]] = ..., interprocess: _Optional[_Union[_interprocess_config_pb2.InterProcessPortalConfig, _Mapping]] = ..., role: _Optional[str] = ..., count: _Optional[int] = ..., group: _Optional[_Iterable[str]] = ..., publish_period: _Optional[float] = ...) -> None: ...
