from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf.internal import python_message as _python_message
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class ModemTransmission(_message.Message):
    __slots__ = ("src", "dest", "time", "time_source", "rate", "type", "max_num_frames", "max_frame_bytes", "ack_requested", "frame", "frame_start", "acked_frame", "slot_seconds", "unique_id", "always_initiate", "slot_index")
    Extensions: _python_message._ExtensionDict
    class TimeSource(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        MODEM_TIME: _ClassVar[ModemTransmission.TimeSource]
        GOBY_TIME: _ClassVar[ModemTransmission.TimeSource]
    MODEM_TIME: ModemTransmission.TimeSource
    GOBY_TIME: ModemTransmission.TimeSource
    class TransmissionType(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        DATA: _ClassVar[ModemTransmission.TransmissionType]
        ACK: _ClassVar[ModemTransmission.TransmissionType]
        DRIVER_SPECIFIC: _ClassVar[ModemTransmission.TransmissionType]
    DATA: ModemTransmission.TransmissionType
    ACK: ModemTransmission.TransmissionType
    DRIVER_SPECIFIC: ModemTransmission.TransmissionType
    SRC_FIELD_NUMBER: _ClassVar[int]
    DEST_FIELD_NUMBER: _ClassVar[int]
    TIME_FIELD_NUMBER: _ClassVar[int]
    TIME_SOURCE_FIELD_NUMBER: _ClassVar[int]
    RATE_FIELD_NUMBER: _ClassVar[int]
    TYPE_FIELD_NUMBER: _ClassVar[int]
    MAX_NUM_FRAMES_FIELD_NUMBER: _ClassVar[int]
    MAX_FRAME_BYTES_FIELD_NUMBER: _ClassVar[int]
    ACK_REQUESTED_FIELD_NUMBER: _ClassVar[int]
    FRAME_FIELD_NUMBER: _ClassVar[int]
    FRAME_START_FIELD_NUMBER: _ClassVar[int]
    ACKED_FRAME_FIELD_NUMBER: _ClassVar[int]
    SLOT_SECONDS_FIELD_NUMBER: _ClassVar[int]
    UNIQUE_ID_FIELD_NUMBER: _ClassVar[int]
    ALWAYS_INITIATE_FIELD_NUMBER: _ClassVar[int]
    SLOT_INDEX_FIELD_NUMBER: _ClassVar[int]
    src: int
    dest: int
    time: int
    time_source: ModemTransmission.TimeSource
    rate: int
    type: ModemTransmission.TransmissionType
    max_num_frames: int
    max_frame_bytes: int
    ack_requested: bool
    frame: _containers.RepeatedScalarFieldContainer[bytes]
    frame_start: int
    acked_frame: _containers.RepeatedScalarFieldContainer[int]
    slot_seconds: float
    unique_id: int
    always_initiate: bool
    slot_index: int
    def __init__(self, src: _Optional[int] = ..., dest: _Optional[int] = ..., time: _Optional[int] = ..., time_source: _Optional[_Union[ModemTransmission.TimeSource, str]] = ..., rate: _Optional[int] = ..., type: _Optional[_Union[ModemTransmission.TransmissionType, str]] = ..., max_num_frames: _Optional[int] = ..., max_frame_bytes: _Optional[int] = ..., ack_requested: _Optional[bool] = ..., frame: _Optional[_Iterable[bytes]] = ..., frame_start: _Optional[int] = ..., acked_frame: _Optional[_Iterable[int]] = ..., slot_seconds: _Optional[float] = ..., unique_id: _Optional[int] = ..., always_initiate: _Optional[bool] = ..., slot_index: _Optional[int] = ...) -> None: ...

class ModemRaw(_message.Message):
    __slots__ = ("raw", "description")
    RAW_FIELD_NUMBER: _ClassVar[int]
    DESCRIPTION_FIELD_NUMBER: _ClassVar[int]
    raw: bytes
    description: str
    def __init__(self, raw: _Optional[bytes] = ..., description: _Optional[str] = ...) -> None: ...

class ModemReport(_message.Message):
    __slots__ = ("modem_id", "time", "link_state", "link_quality")
    Extensions: _python_message._ExtensionDict
    class LinkState(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        LINK_NOT_AVAILABLE: _ClassVar[ModemReport.LinkState]
        LINK_AVAILABLE: _ClassVar[ModemReport.LinkState]
    LINK_NOT_AVAILABLE: ModemReport.LinkState
    LINK_AVAILABLE: ModemReport.LinkState
    class LinkQuality(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        QUALITY_VERY_LOW: _ClassVar[ModemReport.LinkQuality]
        QUALITY_LOW: _ClassVar[ModemReport.LinkQuality]
        QUALITY_UNKNOWN: _ClassVar[ModemReport.LinkQuality]
        QUALITY_MEDIUM: _ClassVar[ModemReport.LinkQuality]
        QUALITY_HIGH: _ClassVar[ModemReport.LinkQuality]
        QUALITY_VERY_HIGH: _ClassVar[ModemReport.LinkQuality]
    QUALITY_VERY_LOW: ModemReport.LinkQuality
    QUALITY_LOW: ModemReport.LinkQuality
    QUALITY_UNKNOWN: ModemReport.LinkQuality
    QUALITY_MEDIUM: ModemReport.LinkQuality
    QUALITY_HIGH: ModemReport.LinkQuality
    QUALITY_VERY_HIGH: ModemReport.LinkQuality
    MODEM_ID_FIELD_NUMBER: _ClassVar[int]
    TIME_FIELD_NUMBER: _ClassVar[int]
    LINK_STATE_FIELD_NUMBER: _ClassVar[int]
    LINK_QUALITY_FIELD_NUMBER: _ClassVar[int]
    modem_id: int
    time: int
    link_state: ModemReport.LinkState
    link_quality: ModemReport.LinkQuality
    def __init__(self, modem_id: _Optional[int] = ..., time: _Optional[int] = ..., link_state: _Optional[_Union[ModemReport.LinkState, str]] = ..., link_quality: _Optional[_Union[ModemReport.LinkQuality, str]] = ...) -> None: ...
