from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from gateway.goby.intervehicle.protobuf import transporter_config_pb2 as _transporter_config_pb2
from google.protobuf import descriptor_pb2 as _descriptor_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class SerializerProtobufMetadata(_message.Message):
    __slots__ = ("protobuf_name", "file_descriptor")
    PROTOBUF_NAME_FIELD_NUMBER: _ClassVar[int]
    FILE_DESCRIPTOR_FIELD_NUMBER: _ClassVar[int]
    protobuf_name: str
    file_descriptor: _containers.RepeatedCompositeFieldContainer[_descriptor_pb2.FileDescriptorProto]
    def __init__(self, protobuf_name: _Optional[str] = ..., file_descriptor: _Optional[_Iterable[_Union[_descriptor_pb2.FileDescriptorProto, _Mapping]]] = ...) -> None: ...

class SerializerTransporterKey(_message.Message):
    __slots__ = ("marshalling_scheme", "type", "group", "group_numeric", "serialize_time", "cfg", "metadata")
    MARSHALLING_SCHEME_FIELD_NUMBER: _ClassVar[int]
    TYPE_FIELD_NUMBER: _ClassVar[int]
    GROUP_FIELD_NUMBER: _ClassVar[int]
    GROUP_NUMERIC_FIELD_NUMBER: _ClassVar[int]
    SERIALIZE_TIME_FIELD_NUMBER: _ClassVar[int]
    CFG_FIELD_NUMBER: _ClassVar[int]
    METADATA_FIELD_NUMBER: _ClassVar[int]
    marshalling_scheme: int
    type: str
    group: str
    group_numeric: int
    serialize_time: int
    cfg: _transporter_config_pb2.TransporterConfig
    metadata: SerializerProtobufMetadata
    def __init__(self, marshalling_scheme: _Optional[int] = ..., type: _Optional[str] = ..., group: _Optional[str] = ..., group_numeric: _Optional[int] = ..., serialize_time: _Optional[int] = ..., cfg: _Optional[_Union[_transporter_config_pb2.TransporterConfig, _Mapping]] = ..., metadata: _Optional[_Union[SerializerProtobufMetadata, _Mapping]] = ...) -> None: ...

class SerializerTransporterMessage(_message.Message):
    __slots__ = ("key", "data")
    KEY_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    key: SerializerTransporterKey
    data: bytes
    def __init__(self, key: _Optional[_Union[SerializerTransporterKey, _Mapping]] = ..., data: _Optional[bytes] = ...) -> None: ...

class SerializerMetadataRequest(_message.Message):
    __slots__ = ("key", "request")
    class Request(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        METADATA_INCLUDE: _ClassVar[SerializerMetadataRequest.Request]
        METADATA_EXCLUDE: _ClassVar[SerializerMetadataRequest.Request]
    METADATA_INCLUDE: SerializerMetadataRequest.Request
    METADATA_EXCLUDE: SerializerMetadataRequest.Request
    KEY_FIELD_NUMBER: _ClassVar[int]
    REQUEST_FIELD_NUMBER: _ClassVar[int]
    key: SerializerTransporterKey
    request: SerializerMetadataRequest.Request
    def __init__(self, key: _Optional[_Union[SerializerTransporterKey, _Mapping]] = ..., request: _Optional[_Union[SerializerMetadataRequest.Request, str]] = ...) -> None: ...
