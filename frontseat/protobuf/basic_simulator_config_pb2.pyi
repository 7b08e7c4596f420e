from frontseat.protobuf import frontseat_config_pb2 as _frontseat_config_pb2
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor
BASIC_SIMULATOR_CONFIG_FIELD_NUMBER: _ClassVar[int]
basic_simulator_config: _descriptor.FieldDescriptor

class BasicSimulatorFrontSeatConfig(_message.Message):
    __slots__ = ("tcp_address", "tcp_port", "start")
    class StartParams(_message.Message):
        __slots__ = ("lat", "lon", "duration", "control_freq", "vehicle")
        class VehicleConfig(_message.Message):
            __slots__ = ("accel", "hdg_rate", "z_rate")
            ACCEL_FIELD_NUMBER: _ClassVar[int]
            HDG_RATE_FIELD_NUMBER: _ClassVar[int]
            Z_RATE_FIELD_NUMBER: _ClassVar[int]
            accel: float
            hdg_rate: float
            z_rate: float
            def __init__(self, accel: _Optional[float] = ..., hdg_rate: _Optional[float] = ..., z_rate: _Optional[float] = ...) -> None: ...
        LAT_FIELD_NUMBER: _ClassVar[int]
        LON_FIELD_NUMBER: _ClassVar[int]
        DURATION_FIELD_NUMBER: _ClassVar[int]
        CONTROL_FREQ_FIELD_NUMBER: _ClassVar[int]
        VEHICLE_FIELD_NUMBER: _ClassVar[int]
        lat: float
        lon: float
        duration: int
        control_freq: int
        vehicle: BasicSimulatorFrontSeatConfig.StartParams.VehicleConfig
        def __init__(self, lat: _Optional[float] = ..., lon: _Optional[float] = ..., duration: _Optional[int] = ..., control_freq: _Optional[int] = ..., vehicle: _Optional[_Union[BasicSimulatorFrontSeatConfig.StartParams.VehicleConfig, _Mapping]] = ...) -> None: ...
    TCP_ADDRESS_FIELD_NUMBER: _ClassVar[int]
    TCP_PORT_FIELD_NUMBER: _ClassVar[int]
    START_FIELD_NUMBER: _ClassVar[int]
    tcp_address: str
    tcp_port: int
    start: BasicSimulatorFrontSeatConfig.StartParams
    def __init__(self, tcp_address: _Optional[str] = ..., tcp_port: _Optional[int] = ..., start: _Optional[_Union[BasicSimulatorFrontSeatConfig.StartParams, _Mapping]] = ...) -> None: ...
