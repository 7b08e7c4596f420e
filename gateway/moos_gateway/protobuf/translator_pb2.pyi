from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class TranslatorEntry(_message.Message):
    __slots__ = ("protobuf_name", "trigger", "create", "publish", "use_short_enum")
    class ParserSerializerTechnique(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        TECHNIQUE_PROTOBUF_TEXT_FORMAT: _ClassVar[TranslatorEntry.ParserSerializerTechnique]
        TECHNIQUE_PROTOBUF_NATIVE_ENCODED: _ClassVar[TranslatorEntry.ParserSerializerTechnique]
        TECHNIQUE_COMMA_SEPARATED_KEY_EQUALS_VALUE_PAIRS: _ClassVar[TranslatorEntry.ParserSerializerTechnique]
        TECHNIQUE_FORMAT: _ClassVar[TranslatorEntry.ParserSerializerTechnique]
        TECHNIQUE_PREFIXED_PROTOBUF_TEXT_FORMAT: _ClassVar[TranslatorEntry.ParserSerializerTechnique]
        TECHNIQUE_PROTOBUF_NATIVE_HEX: _ClassVar[TranslatorEntry.ParserSerializerTechnique]
        TECHNIQUE_PREFIXED_PROTOBUF_NATIVE_HEX: _ClassVar[TranslatorEntry.ParserSerializerTechnique]
        TECHNIQUE_PREFIXED_PROTOBUF_NATIVE_ENCODED: _ClassVar[TranslatorEntry.ParserSerializerTechnique]
    TECHNIQUE_PROTOBUF_TEXT_FORMAT: TranslatorEntry.ParserSerializerTechnique
    TECHNIQUE_PROTOBUF_NATIVE_ENCODED: TranslatorEntry.ParserSerializerTechnique
    TECHNIQUE_COMMA_SEPARATED_KEY_EQUALS_VALUE_PAIRS: TranslatorEntry.ParserSerializerTechnique
    TECHNIQUE_FORMAT: TranslatorEntry.ParserSerializerTechnique
    TECHNIQUE_PREFIXED_PROTOBUF_TEXT_FORMAT: TranslatorEntry.ParserSerializerTechnique
    TECHNIQUE_PROTOBUF_NATIVE_HEX: TranslatorEntry.ParserSerializerTechnique
    TECHNIQUE_PREFIXED_PROTOBUF_NATIVE_HEX: TranslatorEntry.ParserSerializerTechnique
    TECHNIQUE_PREFIXED_PROTOBUF_NATIVE_ENCODED: TranslatorEntry.ParserSerializerTechnique
    class Trigger(_message.Message):
        __slots__ = ("type", "moos_var", "period", "mandatory_content")
        class Type(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
            __slots__ = ()
            TRIGGER_PUBLISH: _ClassVar[TranslatorEntry.Trigger.Type]
            TRIGGER_TIME: _ClassVar[TranslatorEntry.Trigger.Type]
        TRIGGER_PUBLISH: TranslatorEntry.Trigger.Type
        TRIGGER_TIME: TranslatorEntry.Trigger.Type
        TYPE_FIELD_NUMBER: _ClassVar[int]
        MOOS_VAR_FIELD_NUMBER: _ClassVar[int]
        PERIOD_FIELD_NUMBER: _ClassVar[int]
        MANDATORY_CONTENT_FIELD_NUMBER: _ClassVar[int]
        type: TranslatorEntry.Trigger.Type
        moos_var: str
        period: int
        mandatory_content: str
        def __init__(self, type: _Optional[_Union[TranslatorEntry.Trigger.Type, str]] = ..., moos_var: _Optional[str] = ..., period: _Optional[int] = ..., mandatory_content: _Optional[str] = ...) -> None: ...
    class CreateParser(_message.Message):
        __slots__ = ("technique", "moos_var", "format", "repeated_delimiter", "algorithm")
        class Algorithm(_message.Message):
            __slots__ = ("name", "primary_field")
            NAME_FIELD_NUMBER: _ClassVar[int]
            PRIMARY_FIELD_FIELD_NUMBER: _ClassVar[int]
            name: str
            primary_field: int
            def __init__(self, name: _Optional[str] = ..., primary_field: _Optional[int] = ...) -> None: ...
        TECHNIQUE_FIELD_NUMBER: _ClassVar[int]
        MOOS_VAR_FIELD_NUMBER: _ClassVar[int]
        FORMAT_FIELD_NUMBER: _ClassVar[int]
        REPEATED_DELIMITER_FIELD_NUMBER: _ClassVar[int]
        ALGORITHM_FIELD_NUMBER: _ClassVar[int]
        technique: TranslatorEntry.ParserSerializerTechnique
        moos_var: str
        format: str
        repeated_delimiter: str
        algorithm: _containers.RepeatedCompositeFieldContainer[TranslatorEntry.CreateParser.Algorithm]
        def __init__(self, technique: _Optional[_Union[TranslatorEntry.ParserSerializerTechnique, str]] = ..., moos_var: _Optional[str] = ..., format: _Optional[str] = ..., repeated_delimiter: _Optional[str] = ..., algorithm: _Optional[_Iterable[_Union[TranslatorEntry.CreateParser.Algorithm, _Mapping]]] = ...) -> None: ...
    class PublishSerializer(_message.Message):
        __slots__ = ("technique", "moos_var", "format", "repeated_delimiter", "algorithm")
        class Algorithm(_message.Message):
            __slots__ = ("name", "output_virtual_field", "primary_field", "reference_field")
            NAME_FIELD_NUMBER: _ClassVar[int]
            OUTPUT_VIRTUAL_FIELD_FIELD_NUMBER: _ClassVar[int]
            PRIMARY_FIELD_FIELD_NUMBER: _ClassVar[int]
            REFERENCE_FIELD_FIELD_NUMBER: _ClassVar[int]
            name: str
            output_virtual_field: int
            primary_field: int
            reference_field: _containers.RepeatedScalarFieldContainer[int]
            def __init__(self, name: _Optional[str] = ..., output_virtual_field: _Optional[int] = ..., primary_field: _Optional[int] = ..., reference_field: _Optional[_Iterable[int]] = ...) -> None: ...
        TECHNIQUE_FIELD_NUMBER: _ClassVar[int]
        MOOS_VAR_FIELD_NUMBER: _ClassVar[int]
        FORMAT_FIELD_NUMBER: _ClassVar[int]
        REPEATED_DELIMITER_FIELD_NUMBER: _ClassVar[int]
        ALGORITHM_FIELD_NUMBER: _ClassVar[int]
        technique: TranslatorEntry.ParserSerializerTechnique
        moos_var: str
        format: str
        repeated_delimiter: str
        algorithm: _containers.RepeatedCompositeFieldContainer[TranslatorEntry.PublishSerializer.Algorithm]
        def __init__(self, technique: _Optional[_Union[TranslatorEntry.ParserSerializerTechnique, str]] = ..., moos_var: _Optional[str] = ..., format: _Optional[str] = ..., repeated_delimiter: _Optional[str] = ..., algorithm: _Optional[_Iterable[_Union[TranslatorEntry.PublishSerializer.Algorithm, _Mapping]]] = ...) -> None: ...
    PROTOBUF_NAME_FIELD_NUMBER: _ClassVar[int]
    TRIGGER_FIELD_NUMBER: _ClassVar[int]
    CREATE_FIELD_NUMBER: _ClassVar[int]
    PUBLISH_FIELD_NUMBER: _ClassVar[int]
    USE_SHORT_ENUM_FIELD_NUMBER: _ClassVar[int]
    protobuf_name: str
    trigger: TranslatorEntry.Trigger
    create: _containers.RepeatedCompositeFieldContainer[TranslatorEntry.CreateParser]
    publish: _containers.RepeatedCompositeFieldContainer[TranslatorEntry.PublishSerializer]
    use_short_enum: bool
    def __init__(self, protobuf_name: _Optional[str] = ..., trigger: _Optional[_Union[TranslatorEntry.Trigger, _Mapping]] = ..., create: _Optional[_Iterable[_Union[TranslatorEntry.CreateParser, _Mapping]]] = ..., publish: _Optional[_Iterable[_Union[TranslatorEntry.PublishSerializer, _Mapping]]] = ..., use_short_enum: _Optional[bool] = ...) -> None: ...
