from gateway.goby.protobuf import debug_logger_pb2 as _debug_logger_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class AppConfig(_message.Message):
    __slots__ = ("name", "binary", "glog_config", "simulation", "geodesy", "health_cfg", "tool_cfg", "debug_cfg")
    class SimulatorSettings(_message.Message):
        __slots__ = ("time",)
        class Time(_message.Message):
            __slots__ = ("use_sim_time", "warp_factor", "reference_microtime")
            USE_SIM_TIME_FIELD_NUMBER: _ClassVar[int]
            WARP_FACTOR_FIELD_NUMBER: _ClassVar[int]
            REFERENCE_MICROTIME_FIELD_NUMBER: _ClassVar[int]
            use_sim_time: bool
            warp_factor: int
            reference_microtime: int
            def __init__(self, use_sim_time: _Optional[bool] = ..., warp_factor: _Optional[int] = ..., reference_microtime: _Optional[int] = ...) -> None: ...
        TIME_FIELD_NUMBER: _ClassVar[int]
        time: AppConfig.SimulatorSettings.Time
        def __init__(self, time: _Optional[_Union[AppConfig.SimulatorSettings.Time, _Mapping]] = ...) -> None: ...
    class Geodesy(_message.Message):
        __slots__ = ("lat_origin", "lon_origin")
        LAT_ORIGIN_FIELD_NUMBER: _ClassVar[int]
        LON_ORIGIN_FIELD_NUMBER: _ClassVar[int]
        lat_origin: float
        lon_origin: float
        def __init__(self, lat_origin: _Optional[float] = ..., lon_origin: _Optional[float] = ...) -> None: ...
    class Health(_message.Message):
        __slots__ = ("run_health_monitor_thread",)
        RUN_HEALTH_MONITOR_THREAD_FIELD_NUMBER: _ClassVar[int]
        run_health_monitor_thread: bool
        def __init__(self, run_health_monitor_thread: _Optional[bool] = ...) -> None: ...
    class Tool(_message.Message):
        __slots__ = ("extra_cli_param",)
        EXTRA_CLI_PARAM_FIELD_NUMBER: _ClassVar[int]
        extra_cli_param: _containers.RepeatedScalarFieldContainer[str]
        def __init__(self, extra_cli_param: _Optional[_Iterable[str]] = ...) -> None: ...
    NAME_FIELD_NUMBER: _ClassVar[int]
    BINARY_FIELD_NUMBER: _ClassVar[int]
    GLOG_CONFIG_FIELD_NUMBER: _ClassVar[int]
    SIMULATION_FIELD_NUMBER: _ClassVar[int]
    GEODESY_FIELD_NUMBER: _ClassVar[int]
    HEALTH_CFG_FIELD_NUMBER: _ClassVar[int]
    TOOL_CFG_FIELD_NUMBER: _ClassVar[int]
    DEBUG_CFG_FIELD_NUMBER: _ClassVar[int]
    name: str
    binary: str
    glog_config: _debug_logger_pb2.GLogConfig
    simulation: AppConfig.SimulatorSettings
    geodesy: AppConfig.Geodesy
    health_cfg: AppConfig.Health
    tool_cfg: AppConfig.Tool
    debug_cfg: bool
    def __init__(self, name: _Optional[str] = ..., binary: _Optional[str] = ..., glog_config: _Optional[_Union[_debug_logger_pb2.GLogConfig, _Mapping]] = ..., simulation: _Optional[_Union[AppConfig.SimulatorSettings, _Mapping]] = ..., geodesy: _Optional[_Union[AppConfig.Geodesy, _Mapping]] = ..., health_cfg: _Optional[_Union[AppConfig.Health, _Mapping]] = ..., tool_cfg: _Optional[_Union[AppConfig.Tool, _Mapping]] = ..., debug_cfg: _Optional[bool] = ...) -> None: ...
