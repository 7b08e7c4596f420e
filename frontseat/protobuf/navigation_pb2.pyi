from gateway.goby.protobuf import geographic_pb2 as _geographic_pb2
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class DatumUpdate(_message.Message):
    __slots__ = ("datum",)
    DATUM_FIELD_NUMBER: _ClassVar[int]
    datum: _geographic_pb2.LatLonPoint
    def __init__(self, datum: _Optional[_Union[_geographic_pb2.LatLonPoint, _Mapping]] = ...) -> None: ...
