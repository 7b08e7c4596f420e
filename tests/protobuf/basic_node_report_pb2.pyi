from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class Enum1(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    ENUM_A: _ClassVar[Enum1]
    ENUM_B: _ClassVar[Enum1]
    ENUM_C: _ClassVar[Enum1]
ENUM_A: Enum1
ENUM_B: Enum1
ENUM_C: Enum1

class BasicNodeReport(_message.Message):
    __slots__ = ("Name", "x", "y", "speed", "heading", "depth", "altitude", "lat", "lon", "time", "repeat")
    NAME_FIELD_NUMBER: _ClassVar[int]
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    SPEED_FIELD_NUMBER: _ClassVar[int]
    HEADING_FIELD_NUMBER: _ClassVar[int]
    DEPTH_FIELD_NUMBER: _ClassVar[int]
    ALTITUDE_FIELD_NUMBER: _ClassVar[int]
    LAT_FIELD_NUMBER: _ClassVar[int]
    LON_FIELD_NUMBER: _ClassVar[int]
    TIME_FIELD_NUMBER: _ClassVar[int]
    REPEAT_FIELD_NUMBER: _ClassVar[int]
    Name: str
    x: float
    y: float
    speed: float
    heading: float
    depth: float
    altitude: float
    lat: float
    lon: float
    time: float
    repeat: _containers.RepeatedScalarFieldContainer[int]
    def __init__(self, Name: _Optional[str] = ..., x: _Optional[float] = ..., y: _Optional[float] = ..., speed: _Optional[float] = ..., heading: _Optional[float] = ..., depth: _Optional[float] = ..., altitude: _Optional[float] = ..., lat: _Optional[float] = ..., lon: _Optional[float] = ..., time: _Optional[float] = ..., repeat: _Optional[_Iterable[int]] = ...) -> None: ...

class EmbeddedMsg2(_message.Message):
    __slots__ = ("val", "sval", "enum_default")
    VAL_FIELD_NUMBER: _ClassVar[int]
    SVAL_FIELD_NUMBER: _ClassVar[int]
    ENUM_DEFAULT_FIELD_NUMBER: _ClassVar[int]
    val: float
    sval: str
    enum_default: Enum1
    def __init__(self, val: _Optional[float] = ..., sval: _Optional[str] = ..., enum_default: _Optional[_Union[Enum1, str]] = ...) -> None: ...

class EmbeddedMsg1(_message.Message):
    __slots__ = ("val", "msg")
    VAL_FIELD_NUMBER: _ClassVar[int]
    MSG_FIELD_NUMBER: _ClassVar[int]
    val: float
    msg: EmbeddedMsg2
    def __init__(self, val: _Optional[float] = ..., msg: _Optional[_Union[EmbeddedMsg2, _Mapping]] = ...) -> None: ...

class TestMsg(_message.Message):
    __slots__ = ("double_default_optional", "float_default_optional", "int32_default_optional", "uint64_default_optional", "bool_default_optional", "string_default_optional", "bytes_default_optional", "enum_default_optional", "msg_default_optional", "msg_default_required", "double_default_repeat", "uint64_default_repeat", "string_default_repeat", "enum_default_repeat", "msg_default_repeat")
    DOUBLE_DEFAULT_OPTIONAL_FIELD_NUMBER: _ClassVar[int]
    FLOAT_DEFAULT_OPTIONAL_FIELD_NUMBER: _ClassVar[int]
    INT32_DEFAULT_OPTIONAL_FIELD_NUMBER: _ClassVar[int]
    UINT64_DEFAULT_OPTIONAL_FIELD_NUMBER: _ClassVar[int]
    BOOL_DEFAULT_OPTIONAL_FIELD_NUMBER: _ClassVar[int]
    STRING_DEFAULT_OPTIONAL_FIELD_NUMBER: _ClassVar[int]
    BYTES_DEFAULT_OPTIONAL_FIELD_NUMBER: _ClassVar[int]
    ENUM_DEFAULT_OPTIONAL_FIELD_NUMBER: _ClassVar[int]
    MSG_DEFAULT_OPTIONAL_FIELD_NUMBER: _ClassVar[int]
    MSG_DEFAULT_REQUIRED_FIELD_NUMBER: _ClassVar[int]
    DOUBLE_DEFAULT_REPEAT_FIELD_NUMBER: _ClassVar[int]
    UINT64_DEFAULT_REPEAT_FIELD_NUMBER: _ClassVar[int]
    STRING_DEFAULT_REPEAT_FIELD_NUMBER: _ClassVar[int]
    ENUM_DEFAULT_REPEAT_FIELD_NUMBER: _ClassVar[int]
    MSG_DEFAULT_REPEAT_FIELD_NUMBER: _ClassVar[int]
    double_default_optional: float
    float_default_optional: float
    int32_default_optional: int
    uint64_default_optional: int
    bool_default_optional: bool
    string_default_optional: str
    bytes_default_optional: bytes
    enum_default_optional: Enum1
    msg_default_optional: EmbeddedMsg1
    msg_default_required: EmbeddedMsg1
    double_default_repeat: _containers.RepeatedScalarFieldContainer[float]
    uint64_default_repeat: _containers.RepeatedScalarFieldContainer[int]
    string_default_repeat: _containers.RepeatedScalarFieldContainer[str]
    enum_default_repeat: _containers.RepeatedScalarFieldContainer[Enum1]
    msg_default_repeat: _containers.RepeatedCompositeFieldContainer[EmbeddedMsg1]
    def __init__(self, double_default_optional: _Optional[float] = ..., float_default_optional: _Optional[float] = ..., int32_default_optional: _Optional[int] = ..., uint64_default_optional: _Optional[int] = ..., bool_default_optional: _Optional[bool] = ..., string_default_optional: _Optional[str] = ..., bytes_default_optional: _Optional[bytes] = ..., enum_default_optional: _Optional[_Union[Enum1, str]] = ..., msg_default_optional: _Optional[_Union[EmbeddedMsg1, _Mapping]] = ..., msg_default_required: _Optional[_Union[EmbeddedMsg1, _Mapping]] = ..., double_default_repeat: _Optional[_Iterable[float]] = ..., uint64_default_repeat: _Optional[_Iterable[int]] = ..., string_default_repeat: _Optional[_Iterable[str]] = ..., enum_default_repeat: _Optional[_Iterable[_Union[Enum1, str]]] = ..., msg_default_repeat: _Optional[_Iterable[_Union[EmbeddedMsg1, _Mapping]]] = ...) -> None: ...
