from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class InterProcessPortalConfig(_message.Message):
    __slots__ = ("platform", "transport", "socket_name", "ipv4_address", "ip_address", "tcp_port", "send_queue_size", "receive_queue_size", "zeromq_number_io_threads", "manager_timeout_seconds", "client_name")
    class Transport(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        IPC: _ClassVar[InterProcessPortalConfig.Transport]
        TCP: _ClassVar[InterProcessPortalConfig.Transport]
    IPC: InterProcessPortalConfig.Transport
    TCP: InterProcessPortalConfig.Transport
    PLATFORM_FIELD_NUMBER: _ClassVar[int]
    TRANSPORT_FIELD_NUMBER: _ClassVar[int]
    SOCKET_NAME_FIELD_NUMBER: _ClassVar[int]
    IPV4_ADDRESS_FIELD_NUMBER: _ClassVar[int]
    IP_ADDRESS_FIELD_NUMBER: _ClassVar[int]
    TCP_PORT_FIELD_NUMBER: _ClassVar[int]
    SEND_QUEUE_SIZE_FIELD_NUMBER: _ClassVar[int]
    RECEIVE_QUEUE_SIZE_FIELD_NUMBER: _ClassVar[int]
    ZEROMQ_NUMBER_IO_THREADS_FIELD_NUMBER: _ClassVar[int]
    MANAGER_TIMEOUT_SECONDS_FIELD_NUMBER: _ClassVar[int]
    CLIENT_NAME_FIELD_NUMBER: _ClassVar[int]
    platform: str
    transport: InterProcessPortalConfig.Transport
    socket_name: str
    ipv4_address: str
    ip_address: str
    tcp_port: int
    send_queue_size: int
    receive_queue_size: int
    zeromq_number_io_threads: int
    manager_timeout_seconds: int
    client_name: str
    def __init__(self, platform: _Optional[str] = ..., transport: _Optional[_Union[InterProcessPortalConfig.Transport, str]] = ..., socket_name: _Optional[str] = ..., ipv4_address: _Optional[str] = ..., ip_address: _Optional[str] = ..., tcp_port: _Optional[int] = ..., send_queue_size: _Optional[int] = ..., receive_queue_size: _Optional[int] = ..., zeromq_number_io_threads: _Optional[int] = ..., manager_timeout_seconds: _Optional[int] = ..., client_name: _Optional[str] = ...) -> None: ...

class InterProcessManagerHold(_message.Message):
    __slots__ = ("required_client",)
    REQUIRED_CLIENT_FIELD_NUMBER: _ClassVar[int]
    required_client: _containers.RepeatedScalarFieldContainer[str]
    def __init__(self, required_client: _Optional[_Iterable[str]] = ...) -> None: ...
