from gateway.goby.protobuf import app_config_pb2 as _app_config_pb2
from gateway.goby.protobuf import interprocess_config_pb2 as _interprocess_config_pb2
from gateway.goby.intervehicle.protobuf import intervehicle_pb2 as _intervehicle_pb2
from gateway.goby.acomms.protobuf import udp_multicast_driver_pb2 as _udp_multicast_driver_pb2
from gateway.goby.acomms.protobuf import udp_peers_pb2 as _udp_peers_pb2
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class GobyDaemonConfig(_message.Message):
    __slots__ = ("app", "router_threads", "interprocess", "intervehicle", "hold")
    APP_FIELD_NUMBER: _ClassVar[int]
    ROUTER_THREADS_FIELD_NUMBER: _ClassVar[int]
    INTERPROCESS_FIELD_NUMBER: _ClassVar[int]
    INTERVEHICLE_FIELD_NUMBER: _ClassVar[int]
    HOLD_FIELD_NUMBER: _ClassVar[int]
    app: _app_config_pb2.AppConfig
    router_threads: int
    interprocess: _interprocess_config_pb2.InterProcessPortalConfig
    intervehicle: _intervehicle_pb2.PortalConfig
    hold: _interprocess_config_pb2.InterProcessManagerHold
    def __init__(self, app: _Optional[_Union[_app_config_pb2.AppConfig, _Mapping]] = ..., router_threads: _Optional[int] = ..., interprocess: _Optional[_Union[_interprocess_config_pb2.InterProcessPortalConfig, _Mapping]] = ..., intervehicle: _Optional[_Union[_intervehicle_pb2.PortalConfig, _Mapping]] = ..., hold: _Optional[_Union[_interprocess_config_pb2.InterProcessManagerHold, _Mapping]] = ...) -> None: ...
