from google.protobuf import descriptor_pb2 as _descriptor_pb2
from google.protobuf.internal import python_message as _python_message
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor
FIELD_FIELD_NUMBER: _ClassVar[int]
field: _descriptor.FieldDescriptor
MSG_FIELD_NUMBER: _ClassVar[int]
msg: _descriptor.FieldDescriptor

class DCCLFieldOptions(_message.Message):
    __slots__ = ("codec", "omit", "in_head", "precision", "resolution", "min", "max", "num_days", "static_value", "max_length", "max_repeat", "min_repeat", "packed_enum", "description", "units", "dynamic_conditions")
    Extensions: _python_message._ExtensionDict
    class Units(_message.Message):
        __slots__ = ("base_dimensions", "derived_dimensions", "system", "relative_temperature", "unit", "prefix")
        BASE_DIMENSIONS_FIELD_NUMBER: _ClassVar[int]
        DERIVED_DIMENSIONS_FIELD_NUMBER: _ClassVar[int]
        SYSTEM_FIELD_NUMBER: _ClassVar[int]
        RELATIVE_TEMPERATURE_FIELD_NUMBER: _ClassVar[int]
        UNIT_FIELD_NUMBER: _ClassVar[int]
        PREFIX_FIELD_NUMBER: _ClassVar[int]
        base_dimensions: str
        derived_dimensions: str
        system: str
        relative_temperature: bool
        unit: str
        prefix: str
        def __init__(self, base_dimensions: _Optional[str] = ..., derived_dimensions: _Optional[str] = ..., system: _Optional[str] = ..., relative_temperature: _Optional[bool] = ..., unit: _Optional[str] = ..., prefix: _Optional[str] = ...) -> None: ...
    class Conditions(_message.Message):
        __slots__ = ("required_if", "omit_if", "only_if", "min", "max")
        REQUIRED_IF_FIELD_NUMBER: _ClassVar[int]
        OMIT_IF_FIELD_NUMBER: _ClassVar[int]
        ONLY_IF_FIELD_NUMBER: _ClassVar[int]
        MIN_FIELD_NUMBER: _ClassVar[int]
        MAX_FIELD_NUMBER: _ClassVar[int]
        required_if: str
        omit_if: str
        only_if: str
        min: str
        max: str
        def __init__(self, required_if: _Optional[str] = ..., omit_if: _Optional[str] = ..., only_if: _Optional[str] = ..., min: _Optional[str] = ..., max: _Optional[str] = ...) -> None: ...
    CODEC_FIELD_NUMBER: _ClassVar[int]
    OMIT_FIELD_NUMBER: _ClassVar[int]
    IN_HEAD_FIELD_NUMBER: _ClassVar[int]
    PRECISION_FIELD_NUMBER: _ClassVar[int]
    RESOLUTION_FIELD_NUMBER: _ClassVar[int]
    MIN_FIELD_NUMBER: _ClassVar[int]
    MAX_FIELD_NUMBER: _ClassVar[int]
    NUM_DAYS_FIELD_NUMBER: _ClassVar[int]
    STATIC_VALUE_FIELD_NUMBER: _ClassVar[int]
    MAX_LENGTH_FIELD_NUMBER: _ClassVar[int]
    MAX_REPEAT_FIELD_NUMBER: _ClassVar[int]
    MIN_REPEAT_FIELD_NUMBER: _ClassVar[int]
    PACKED_ENUM_FIELD_NUMBER: _ClassVar[int]
    DESCRIPTION_FIELD_NUMBER: _ClassVar[int]
    UNITS_FIELD_NUMBER: _ClassVar[int]
    DYNAMIC_CONDITIONS_FIELD_NUMBER: _ClassVar[int]
    codec: str
    omit: bool
    in_head: bool
    precision: int
    resolution: float
    min: float
    max: float
    num_days: int
    static_value: str
    max_length: int
    max_repeat: int
    min_repeat: int
    packed_enum: bool
    description: str
    units: DCCLFieldOptions.Units
    dynamic_conditions: DCCLFieldOptions.Conditions
    def __init__(self, codec: _Optional[str] = ..., omit: _Optional[bool] = ..., in_head: _Optional[bool] = ..., precision: _Optional[int] = ..., resolution: _Optional[float] = ..., min: _Optional[float] = ..., max: _Optional[float] = ..., num_days: _Optional[int] = ..., static_value: _Optional[str] = ..., max_length: _Optional[int] = ..., max_repeat: _Optional[int] = ..., min_repeat: _Optional[int] = ..., packed_enum: _Optional[bool] = ..., description: _Optional[str] = ..., units: _Optional[_Union[DCCLFieldOptions.Units, _Mapping]] = ..., dynamic_conditions: _Optional[_Union[DCCLFieldOptions.Conditions, _Mapping]] = ...) -> None: ...

class DCCLMessageOptions(_message.Message):
    __slots__ = ("id", "max_bytes", "codec", "codec_group", "codec_version", "omit_id", "unit_system")
    ID_FIELD_NUMBER: _ClassVar[int]
    MAX_BYTES_FIELD_NUMBER: _ClassVar[int]
    CODEC_FIELD_NUMBER: _ClassVar[int]
    CODEC_GROUP_FIELD_NUMBER: _ClassVar[int]
    CODEC_VERSION_FIELD_NUMBER: _ClassVar[int]
    OMIT_ID_FIELD_NUMBER: _ClassVar[int]
    UNIT_SYSTEM_FIELD_NUMBER: _ClassVar[int]
    id: int
    max_bytes: int
    codec: str
    codec_group: str
    codec_version: int
    omit_id: bool
    unit_system: str
    def __init__(self, id: _Optional[int] = ..., max_bytes: _Optional[int] = ..., codec: _Optional[str] = ..., codec_group: _Optional[str] = ..., codec_version: _Optional[int] = ..., omit_id: _Optional[bool] = ..., unit_system: _Optional[str] = ...) -> None: ...
