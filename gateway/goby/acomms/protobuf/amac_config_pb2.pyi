from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from gateway.goby.acomms.protobuf import modem_message_pb2 as _modem_message_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class MACType(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    MAC_NONE: _ClassVar[MACType]
    MAC_FIXED_DECENTRALIZED: _ClassVar[MACType]
    MAC_POLLED: _ClassVar[MACType]
MAC_NONE: MACType
MAC_FIXED_DECENTRALIZED: MACType
MAC_POLLED: MACType

class MACConfig(_message.Message):
    __slots__ = ("modem_id", "type", "slot", "start_cycle_in_middle", "ref_time_type", "fixed_ref_time")
    class MACRefTime(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        REFERENCE_START_OF_DAY: _ClassVar[MACConfig.MACRefTime]
        REFERENCE_FIXED: _ClassVar[MACConfig.MACRefTime]
    REFERENCE_START_OF_DAY: MACConfig.MACRefTime
    REFERENCE_FIXED: MACConfig.MACRefTime
    MODEM_ID_FIELD_NUMBER: _ClassVar[int]
    TYPE_FIELD_NUMBER: _ClassVar[int]
    SLOT_FIELD_NUMBER: _ClassVar[int]
    START_CYCLE_IN_MIDDLE_FIELD_NUMBER: _ClassVar[int]
    REF_TIME_TYPE_FIELD_NUMBER: _ClassVar[int]
    FIXED_REF_TIME_FIELD_NUMBER: _ClassVar[int]
    modem_id: int
    type: MACType
    slot: _containers.RepeatedCompositeFieldContainer[_modem_message_pb2.ModemTransmission]
    start_cycle_in_middle: bool
    ref_time_type: MACConfig.MACRefTime
    fixed_ref_time: int
    def __init__(self, modem_id: _Optional[int] = ..., type: _Optional[_Union[MACType, str]] = ..., slot: _Optional[_Iterable[_Union[_modem_message_pb2.ModemTransmission, _Mapping]]] = ..., start_cycle_in_middle: _Optional[bool] = ..., ref_time_type: _Optional[_Union[MACConfig.MACRefTime, str]] = ..., fixed_ref_time: _Optional[int] = ...) -> None: ...
