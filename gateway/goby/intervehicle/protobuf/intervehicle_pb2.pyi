from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from gateway.goby.acomms.protobuf import driver_base_pb2 as _driver_base_pb2
from gateway.goby.acomms.protobuf import amac_config_pb2 as _amac_config_pb2
from gateway.goby.acomms.protobuf import buffer_pb2 as _buffer_pb2
from gateway.goby.acomms.protobuf import modem_message_pb2 as _modem_message_pb2
from gateway.goby.intervehicle.protobuf import intervehicle_transporter_config_pb2 as _intervehicle_transporter_config_pb2
from gateway.goby.intervehicle.protobuf import serializer_transporter_pb2 as _serializer_transporter_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class SubscriptionDCCLID(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    SUBSCRIPTION_DCCL_ID__GOBY_3_0: _ClassVar[SubscriptionDCCLID]
    SUBSCRIPTION_DCCL_ID__GOBY_3_1: _ClassVar[SubscriptionDCCLID]
SUBSCRIPTION_DCCL_ID__GOBY_3_0: SubscriptionDCCLID
SUBSCRIPTION_DCCL_ID__GOBY_3_1: SubscriptionDCCLID

class PortalConfig(_message.Message):
    __slots__ = ("link", "persist_subscriptions")
    class LinkConfig(_message.Message):
        __slots__ = ("modem_id", "subnet_mask", "driver", "mac", "subscription_buffer", "ack_timeout", "modem_report_interval")
        MODEM_ID_FIELD_NUMBER: _ClassVar[int]
        SUBNET_MASK_FIELD_NUMBER: _ClassVar[int]
        DRIVER_FIELD_NUMBER: _ClassVar[int]
        MAC_FIELD_NUMBER: _ClassVar[int]
        SUBSCRIPTION_BUFFER_FIELD_NUMBER: _ClassVar[int]
        ACK_TIMEOUT_FIELD_NUMBER: _ClassVar[int]
        MODEM_REPORT_INTERVAL_FIELD_NUMBER: _ClassVar[int]
        modem_id: int
        subnet_mask: int
        driver: _driver_base_pb2.DriverConfig
        mac: _amac_config_pb2.MACConfig
        subscription_buffer: _buffer_pb2.DynamicBufferConfig
        ack_timeout: float
        modem_report_interval: float
        def __init__(self, modem_id: _Optional[int] = ..., subnet_mask: _Optional[int] = ..., driver: _Optional[_Union[_driver_base_pb2.DriverConfig, _Mapping]] = ..., mac: _Optional[_Union[_amac_config_pb2.MACConfig, _Mapping]] = ..., subscription_buffer: _Optional[_Union[_buffer_pb2.DynamicBufferConfig, _Mapping]] = ..., ack_timeout: _Optional[float] = ..., modem_report_interval: _Optional[float] = ...) -> None: ...
    class PersistSubscriptions(_message.Message):
        __slots__ = ("name", "dir")
        NAME_FIELD_NUMBER: _ClassVar[int]
        DIR_FIELD_NUMBER: _ClassVar[int]
        name: str
        dir: str
        def __init__(self, name: _Optional[str] = ..., dir: _Optional[str] = ...) -> None: ...
    LINK_FIELD_NUMBER: _ClassVar[int]
    PERSIST_SUBSCRIPTIONS_FIELD_NUMBER: _ClassVar[int]
    link: _containers.RepeatedCompositeFieldContainer[PortalConfig.LinkConfig]
    persist_subscriptions: PortalConfig.PersistSubscriptions
    def __init__(self, link: _Optional[_Iterable[_Union[PortalConfig.LinkConfig, _Mapping]]] = ..., persist_subscriptions: _Optional[_Union[PortalConfig.PersistSubscriptions, _Mapping]] = ...) -> None: ...

class Status(_message.Message):
    __slots__ = ("tx_queue_size",)
    TX_QUEUE_SIZE_FIELD_NUMBER: _ClassVar[int]
    tx_queue_size: int
    def __init__(self, tx_queue_size: _Optional[int] = ...) -> None: ...

class Subscription(_message.Message):
    __slots__ = ("api_version", "header", "time", "action", "dccl_id", "group", "intervehicle", "metadata")
    class Action(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        SUBSCRIBE: _ClassVar[Subscription.Action]
        UNSUBSCRIBE: _ClassVar[Subscription.Action]
    SUBSCRIBE: Subscription.Action
    UNSUBSCRIBE: Subscription.Action
    API_VERSION_FIELD_NUMBER: _ClassVar[int]
    HEADER_FIELD_NUMBER: _ClassVar[int]
    TIME_FIELD_NUMBER: _ClassVar[int]
    ACTION_FIELD_NUMBER: _ClassVar[int]
    DCCL_ID_FIELD_NUMBER: _ClassVar[int]
    GROUP_FIELD_NUMBER: _ClassVar[int]
    INTERVEHICLE_FIELD_NUMBER: _ClassVar[int]
    METADATA_FIELD_NUMBER: _ClassVar[int]
    api_version: int
    header: Header
    time: int
    action: Subscription.Action
    dccl_id: int
    group: int
    intervehicle: _intervehicle_transporter_config_pb2.TransporterConfig
    metadata: _serializer_transporter_pb2.SerializerProtobufMetadata
    def __init__(self, api_version: _Optional[int] = ..., header: _Optional[_Union[Header, _Mapping]] = ..., time: _Optional[int] = ..., action: _Optional[_Union[Subscription.Action, str]] = ..., dccl_id: _Optional[int] = ..., group: _Optional[int] = ..., intervehicle: _Optional[_Union[_intervehicle_transporter_config_pb2.TransporterConfig, _Mapping]] = ..., metadata: _Optional[_Union[_serializer_transporter_pb2.SerializerProtobufMetadata, _Mapping]] = ...) -> None: ...

class Header(_message.Message):
    __slots__ = ("src", "dest", "modem_msg")
    SRC_FIELD_NUMBER: _ClassVar[int]
    DEST_FIELD_NUMBER: _ClassVar[int]
    MODEM_MSG_FIELD_NUMBER: _ClassVar[int]
    src: int
    dest: _containers.RepeatedScalarFieldContainer[int]
    modem_msg: _modem_message_pb2.ModemTransmission
    def __init__(self, src: _Optional[int] = ..., dest: _Optional[_Iterable[int]] = ..., modem_msg: _Optional[_Union[_modem_message_pb2.ModemTransmission, _Mapping]] = ...) -> None: ...

class DCCLPacket(_message.Message):
    __slots__ = ("dccl_id", "data")
    DCCL_ID_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    dccl_id: int
    data: bytes
    def __init__(self, dccl_id: _Optional[int] = ..., data: _Optional[bytes] = ...) -> None: ...

class DCCLForwardedData(_message.Message):
    __slots__ = ("header", "frame")
    HEADER_FIELD_NUMBER: _ClassVar[int]
    FRAME_FIELD_NUMBER: _ClassVar[int]
    header: Header
    frame: _containers.RepeatedCompositeFieldContainer[DCCLPacket]
    def __init__(self, header: _Optional[_Union[Header, _Mapping]] = ..., frame: _Optional[_Iterable[_Union[DCCLPacket, _Mapping]]] = ...) -> None: ...

class AckData(_message.Message):
    __slots__ = ("header", "latency")
    HEADER_FIELD_NUMBER: _ClassVar[int]
    LATENCY_FIELD_NUMBER: _ClassVar[int]
    header: Header
    latency: int
    def __init__(self, header: _Optional[_Union[Header, _Mapping]] = ..., latency: _Optional[int] = ...) -> None: ...

class ExpireData(_message.Message):
    __slots__ = ("header", "latency", "reason")
    class ExpireReason(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        EXPIRED_NO_SUBSCRIBERS: _ClassVar[ExpireData.ExpireReason]
        EXPIRED_TIME_TO_LIVE_EXCEEDED: _ClassVar[ExpireData.ExpireReason]
        EXPIRED_BUFFER_OVERFLOW: _ClassVar[ExpireData.ExpireReason]
    EXPIRED_NO_SUBSCRIBERS: ExpireData.ExpireReason
    EXPIRED_TIME_TO_LIVE_EXCEEDED: ExpireData.ExpireReason
    EXPIRED_BUFFER_OVERFLOW: ExpireData.ExpireReason
    HEADER_FIELD_NUMBER: _ClassVar[int]
    LATENCY_FIELD_NUMBER: _ClassVar[int]
    REASON_FIELD_NUMBER: _ClassVar[int]
    header: Header
    latency: int
    reason: ExpireData.ExpireReason
    def __init__(self, header: _Optional[_Union[Header, _Mapping]] = ..., latency: _Optional[int] = ..., reason: _Optional[_Union[ExpireData.ExpireReason, str]] = ...) -> None: ...

class AckMessagePair(_message.Message):
    __slots__ = ("serializer", "data")
    SERIALIZER_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    serializer: _serializer_transporter_pb2.SerializerTransporterMessage
    data: AckData
    def __init__(self, serializer: _Optional[_Union[_serializer_transporter_pb2.SerializerTransporterMessage, _Mapping]] = ..., data: _Optional[_Union[AckData, _Mapping]] = ...) -> None: ...

class ExpireMessagePair(_message.Message):
    __slots__ = ("serializer", "data")
    SERIALIZER_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    serializer: _serializer_transporter_pb2.SerializerTransporterMessage
    data: ExpireData
    def __init__(self, serializer: _Optional[_Union[_serializer_transporter_pb2.SerializerTransporterMessage, _Mapping]] = ..., data: _Optional[_Union[ExpireData, _Mapping]] = ...) -> None: ...

class SubscriptionReport(_message.Message):
    __slots__ = ("link_modem_id", "subscription", "changed")
    LINK_MODEM_ID_FIELD_NUMBER: _ClassVar[int]
    SUBSCRIPTION_FIELD_NUMBER: _ClassVar[int]
    CHANGED_FIELD_NUMBER: _ClassVar[int]
    link_modem_id: int
    subscription: _containers.RepeatedCompositeFieldContainer[Subscription]
    changed: Subscription
    def __init__(self, link_modem_id: _Optional[int] = ..., subscription: _Optional[_Iterable[_Union[Subscription, _Mapping]]] = ..., changed: _Optional[_Union[Subscription, _Mapping]] = ...) -> None: ...

class SubscriptionPersistCollection(_message.Message):
    __slots__ = ("time", "subscription")
    TIME_FIELD_NUMBER: _ClassVar[int]
    SUBSCRIPTION_FIELD_NUMBER: _ClassVar[int]
    time: int
    subscription: _containers.RepeatedCompositeFieldContainer[Subscription]
    def __init__(self, time: _Optional[int] = ..., subscription: _Optional[_Iterable[_Union[Subscription, _Mapping]]] = ...) -> None: ...

class ModemTransmissionWithLinkID(_message.Message):
    __slots__ = ("link_modem_id", "data")
    LINK_MODEM_ID_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    link_modem_id: int
    data: _modem_message_pb2.ModemTransmission
    def __init__(self, link_modem_id: _Optional[int] = ..., data: _Optional[_Union[_modem_message_pb2.ModemTransmission, _Mapping]] = ...) -> None: ...

class ModemRawWithLinkID(_message.Message):
    __slots__ = ("link_modem_id", "data")
    LINK_MODEM_ID_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    link_modem_id: int
    data: _modem_message_pb2.ModemRaw
    def __init__(self, link_modem_id: _Optional[int] = ..., data: _Optional[_Union[_modem_message_pb2.ModemRaw, _Mapping]] = ...) -> None: ...

class ModemReportWithLinkID(_message.Message):
    __slots__ = ("link_modem_id", "data")
    LINK_MODEM_ID_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    link_modem_id: int
    data: _modem_message_pb2.ModemReport
    def __init__(self, link_modem_id: _Optional[int] = ..., data: _Optional[_Union[_modem_message_pb2.ModemReport, _Mapping]] = ...) -> None: ...
