from gateway.goby.intervehicle.protobuf import intervehicle_transporter_config_pb2 as _intervehicle_transporter_config_pb2
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class TransporterConfig(_message.Message):
    __slots__ = ("echo", "intervehicle")
    ECHO_FIELD_NUMBER: _ClassVar[int]
    INTERVEHICLE_FIELD_NUMBER: _ClassVar[int]
    echo: bool
    intervehicle: _intervehicle_transporter_config_pb2.TransporterConfig
    def __init__(self, echo: _Optional[bool] = ..., intervehicle: _Optional[_Union[_intervehicle_transporter_config_pb2.TransporterConfig, _Mapping]] = ...) -> None: ...
