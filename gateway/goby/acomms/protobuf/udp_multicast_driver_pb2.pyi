from gateway.goby.acomms.protobuf import driver_base_pb2 as _driver_base_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor
CONFIG_FIELD_NUMBER: _ClassVar[int]
config: _descriptor.FieldDescriptor

class Config(_message.Message):
    __slots__ = ("listen_address", "multicast_address", "multicast_port", "max_frame_size", "rate_to_bytes")
    class RateBytesPair(_message.Message):
        __slots__ = ("rate", "bytes")
        RATE_FIELD_NUMBER: _ClassVar[int]
        BYTES_FIELD_NUMBER: _ClassVar[int]
        rate: int
        bytes: int
        def __init__(self, rate: _Optional[int] = ..., bytes: _Optional[int] = ...) -> None: ...
    LISTEN_ADDRESS_FIELD_NUMBER: _ClassVar[int]
    MULTICAST_ADDRESS_FIELD_NUMBER: _ClassVar[int]
    MULTICAST_PORT_FIELD_NUMBER: _ClassVar[int]
    MAX_FRAME_SIZE_FIELD_NUMBER: _ClassVar[int]
    RATE_TO_BYTES_FIELD_NUMBER: _ClassVar[int]
    listen_address: str
    multicast_address: str
    multicast_port: int
    max_frame_size: int
    rate_to_bytes: _containers.RepeatedCompositeFieldContainer[Config.RateBytesPair]
    def __init__(self, listen_address: _Optional[str] = ..., multicast_address: _Optional[str] = ..., multicast_port: _Optional[int] = ..., max_frame_size: _Optional[int] = ..., rate_to_bytes: _Optional[_Iterable[_Union[Config.RateBytesPair, _Mapping]]] = ...) -> None: ...
