from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf.internal import python_message as _python_message
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class DriverType(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    DRIVER_NONE: _ClassVar[DriverType]
    DRIVER_WHOI_MICROMODEM: _ClassVar[DriverType]
    DRIVER_ABC_EXAMPLE_MODEM: _ClassVar[DriverType]
    DRIVER_UFIELD_SIM_DRIVER: _ClassVar[DriverType]
    DRIVER_STORE_SERVER: _ClassVar[DriverType]
    DRIVER_UDP: _ClassVar[DriverType]
    DRIVER_BLUEFIN_MOOS: _ClassVar[DriverType]
    DRIVER_IRIDIUM: _ClassVar[DriverType]
    DRIVER_IRIDIUM_SHORE: _ClassVar[DriverType]
    DRIVER_BENTHOS_ATM900: _ClassVar[DriverType]
    DRIVER_UDP_MULTICAST: _ClassVar[DriverType]
    DRIVER_POPOTO: _ClassVar[DriverType]
DRIVER_NONE: DriverType
DRIVER_WHOI_MICROMODEM: DriverType
DRIVER_ABC_EXAMPLE_MODEM: DriverType
DRIVER_UFIELD_SIM_DRIVER: DriverType
DRIVER_STORE_SERVER: DriverType
DRIVER_UDP: DriverType
DRIVER_BLUEFIN_MOOS: DriverType
DRIVER_IRIDIUM: DriverType
DRIVER_IRIDIUM_SHORE: DriverType
DRIVER_BENTHOS_ATM900: DriverType
DRIVER_UDP_MULTICAST: DriverType
DRIVER_POPOTO: DriverType

class DriverConfig(_message.Message):
    __slots__ = ("driver_type", "driver_name", "modem_id", "connection_type", "line_delimiter", "serial_port", "serial_baud", "tcp_server", "tcp_port", "reconnect_interval", "raw_log")
    Extensions: _python_message._ExtensionDict
    class ConnectionType(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        CONNECTION_SERIAL: _ClassVar[DriverConfig.ConnectionType]
        CONNECTION_TCP_AS_CLIENT: _ClassVar[DriverConfig.ConnectionType]
        CONNECTION_TCP_AS_SERVER: _ClassVar[DriverConfig.ConnectionType]
    CONNECTION_SERIAL: DriverConfig.ConnectionType
    CONNECTION_TCP_AS_CLIENT: DriverConfig.ConnectionType
    CONNECTION_TCP_AS_SERVER: DriverConfig.ConnectionType
    DRIVER_TYPE_FIELD_NUMBER: _ClassVar[int]
    DRIVER_NAME_FIELD_NUMBER: _ClassVar[int]
    MODEM_ID_FIELD_NUMBER: _ClassVar[int]
    CONNECTION_TYPE_FIELD_NUMBER: _ClassVar[int]
    LINE_DELIMITER_FIELD_NUMBER: _ClassVar[int]
    SERIAL_PORT_FIELD_NUMBER: _ClassVar[int]
    SERIAL_BAUD_FIELD_NUMBER: _ClassVar[int]
    TCP_SERVER_FIELD_NUMBER: _ClassVar[int]
    TCP_PORT_FIELD_NUMBER: _ClassVar[int]
    RECONNECT_INTERVAL_FIELD_NUMBER: _ClassVar[int]
    RAW_LOG_FIELD_NUMBER: _ClassVar[int]
    driver_type: DriverType
    driver_name: str
    modem_id: int
    connection_type: DriverConfig.ConnectionType
    line_delimiter: str
    serial_port: str
    serial_baud: int
    tcp_server: str
    tcp_port: int
    reconnect_interval: int
    raw_log: str
    def __init__(self, driver_type: _Optional[_Union[DriverType, str]] = ..., driver_name: _Optional[str] = ..., modem_id: _Optional[int] = ..., connection_type: _Optional[_Union[DriverConfig.ConnectionType, str]] = ..., line_delimiter: _Optional[str] = ..., serial_port: _Optional[str] = ..., serial_baud: _Optional[int] = ..., tcp_server: _Optional[str] = ..., tcp_port: _Optional[int] = ..., reconnect_interval: _Optional[int] = ..., raw_log: _Optional[str] = ...) -> None: ...
