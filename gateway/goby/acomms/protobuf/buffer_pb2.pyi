from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from typing import ClassVar as _ClassVar, Optional as _Optional

DESCRIPTOR: _descriptor.FileDescriptor

class DynamicBufferConfig(_message.Message):
    __slots__ = ("ack_required", "blackout_time", "max_queue", "newest_first", "ttl", "value_base")
    ACK_REQUIRED_FIELD_NUMBER: _ClassVar[int]
    BLACKOUT_TIME_FIELD_NUMBER: _ClassVar[int]
    MAX_QUEUE_FIELD_NUMBER: _ClassVar[int]
    NEWEST_FIRST_FIELD_NUMBER: _ClassVar[int]
    TTL_FIELD_NUMBER: _ClassVar[int]
    VALUE_BASE_FIELD_NUMBER: _ClassVar[int]
    ack_required: bool
    blackout_time: float
    max_queue: int
    newest_first: bool
    ttl: float
    value_base: float
    def __init__(self, ack_required: _Optional[bool] = ..., blackout_time: _Optional[float] = ..., max_queue: _Optional[int] = ..., newest_first: _Optional[bool] = ..., ttl: _Optional[float] = ..., value_base: _Optional[float] = ...) -> None: ...
