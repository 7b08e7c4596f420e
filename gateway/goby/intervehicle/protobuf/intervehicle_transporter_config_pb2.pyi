from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from gateway.goby.acomms.protobuf import buffer_pb2 as _buffer_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class TransporterConfig(_message.Message):
    __slots__ = ("publisher_id", "subscriber_uuid", "buffer", "broadcast")
    PUBLISHER_ID_FIELD_NUMBER: _ClassVar[int]
    SUBSCRIBER_UUID_FIELD_NUMBER: _ClassVar[int]
    BUFFER_FIELD_NUMBER: _ClassVar[int]
    BROADCAST_FIELD_NUMBER: _ClassVar[int]
    publisher_id: _containers.RepeatedScalarFieldContainer[int]
    subscriber_uuid: int
    buffer: _buffer_pb2.DynamicBufferConfig
    broadcast: bool
    def __init__(self, publisher_id: _Optional[_Iterable[int]] = ..., subscriber_uuid: _Optional[int] = ..., buffer: _Optional[_Union[_buffer_pb2.DynamicBufferConfig, _Mapping]] = ..., broadcast: _Optional[bool] = ...) -> None: ...
