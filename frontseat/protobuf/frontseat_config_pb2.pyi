from gateway.goby.protobuf import geographic_pb2 as _geographic_pb2
from frontseat.protobuf import frontseat_data_pb2 as _frontseat_data_pb2
from google.protobuf.internal import python_message as _python_message
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class Config(_message.Message):
    __slots__ = ("name", "origin", "type", "require_helm", "helm_running_timeout", "frontseat_connected_timeout", "status_period", "exit_on_error", "sim_warp_factor")
    Extensions: _python_message._ExtensionDict
    NAME_FIELD_NUMBER: _ClassVar[int]
    ORIGIN_FIELD_NUMBER: _ClassVar[int]
    TYPE_FIELD_NUMBER: _ClassVar[int]
    REQUIRE_HELM_FIELD_NUMBER: _ClassVar[int]
    HELM_RUNNING_TIMEOUT_FIELD_NUMBER: _ClassVar[int]
    FRONTSEAT_CONNECTED_TIMEOUT_FIELD_NUMBER: _ClassVar[int]
    STATUS_PERIOD_FIELD_NUMBER: _ClassVar[int]
    EXIT_ON_ERROR_FIELD_NUMBER: _ClassVar[int]
    SIM_WARP_FACTOR_FIELD_NUMBER: _ClassVar[int]
    name: str
    origin: _geographic_pb2.LatLonPoint
    type: _frontseat_data_pb2.VehicleType
    require_helm: bool
    helm_running_timeout: float
    frontseat_connected_timeout: float
    status_period: int
    exit_on_error: bool
    sim_warp_factor: int
    def __init__(self, name: _Optional[str] = ..., origin: _Optional[_Union[_geographic_pb2.LatLonPoint, _Mapping]] = ..., type: _Optional[_Union[_frontseat_data_pb2.VehicleType, str]] = ..., require_helm: _Optional[bool] = ..., helm_running_timeout: _Optional[float] = ..., frontseat_connected_timeout: _Optional[float] = ..., status_period: _Optional[int] = ..., exit_on_error: _Optional[bool] = ..., sim_warp_factor: _Optional[int] = ...) -> None: ...
