from gateway.goby.protobuf import geographic_pb2 as _geographic_pb2
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf.internal import python_message as _python_message
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class VehicleType(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    UNKNOWN: _ClassVar[VehicleType]
    AUV: _ClassVar[VehicleType]
    GLIDER: _ClassVar[VehicleType]
    USV: _ClassVar[VehicleType]
    USV_POWERED: _ClassVar[VehicleType]
    USV_SAILING: _ClassVar[VehicleType]
    ROV: _ClassVar[VehicleType]
    TARGET: _ClassVar[VehicleType]
    BUOY: _ClassVar[VehicleType]
    MOORING: _ClassVar[VehicleType]
    MOORING_SUBSURFACE: _ClassVar[VehicleType]
    MOORING_SURFACE: _ClassVar[VehicleType]
    SHIP: _ClassVar[VehicleType]
    OTHER: _ClassVar[VehicleType]
UNKNOWN: VehicleType
AUV: VehicleType
GLIDER: VehicleType
USV: VehicleType
USV_POWERED: VehicleType
USV_SAILING: VehicleType
ROV: VehicleType
TARGET: VehicleType
BUOY: VehicleType
MOORING: VehicleType
MOORING_SUBSURFACE: VehicleType
MOORING_SURFACE: VehicleType
SHIP: VehicleType
OTHER: VehicleType

class NodeStatus(_message.Message):
    __slots__ = ("time", "name", "type", "global_fix", "local_fix", "pose", "speed", "source")
    Extensions: _python_message._ExtensionDict
    TIME_FIELD_NUMBER: _ClassVar[int]
    NAME_FIELD_NUMBER: _ClassVar[int]
    TYPE_FIELD_NUMBER: _ClassVar[int]
    GLOBAL_FIX_FIELD_NUMBER: _ClassVar[int]
    LOCAL_FIX_FIELD_NUMBER: _ClassVar[int]
    POSE_FIELD_NUMBER: _ClassVar[int]
    SPEED_FIELD_NUMBER: _ClassVar[int]
    SOURCE_FIELD_NUMBER: _ClassVar[int]
    time: float
    name: str
    type: VehicleType
    global_fix: _geographic_pb2.LatLonPoint
    local_fix: CartesianCoordinate
    pose: EulerAngles
    speed: Speed
    source: Source
    def __init__(self, time: _Optional[float] = ..., name: _Optional[str] = ..., type: _Optional[_Union[VehicleType, str]] = ..., global_fix: _Optional[_Union[_geographic_pb2.LatLonPoint, _Mapping]] = ..., local_fix: _Optional[_Union[CartesianCoordinate, _Mapping]] = ..., pose: _Optional[_Union[EulerAngles, _Mapping]] = ..., speed: _Optional[_Union[Speed, _Mapping]] = ..., source: _Optional[_Union[Source, _Mapping]] = ...) -> None: ...

class DesiredCourse(_message.Message):
    __slots__ = ("time", "heading", "speed", "depth", "pitch", "roll", "z_rate", "altitude")
    Extensions: _python_message._ExtensionDict
    TIME_FIELD_NUMBER: _ClassVar[int]
    HEADING_FIELD_NUMBER: _ClassVar[int]
    SPEED_FIELD_NUMBER: _ClassVar[int]
    DEPTH_FIELD_NUMBER: _ClassVar[int]
    PITCH_FIELD_NUMBER: _ClassVar[int]
    ROLL_FIELD_NUMBER: _ClassVar[int]
    Z_RATE_FIELD_NUMBER: _ClassVar[int]
    ALTITUDE_FIELD_NUMBER: _ClassVar[int]
    time: float
    heading: float
    speed: float
    depth: float
    pitch: float
    roll: float
    z_rate: float
    altitude: float
    def __init__(self, time: _Optional[float] = ..., heading: _Optional[float] = ..., speed: _Optional[float] = ..., depth: _Optional[float] = ..., pitch: _Optional[float] = ..., roll: _Optional[float] = ..., z_rate: _Optional[float] = ..., altitude: _Optional[float] = ...) -> None: ...

class Source(_message.Message):
    __slots__ = ("position", "depth", "speed", "heading")
    Extensions: _python_message._ExtensionDict
    class Sensor(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        GPS: _ClassVar[Source.Sensor]
        USBL: _ClassVar[Source.Sensor]
        LBL: _ClassVar[Source.Sensor]
        INERTIAL_NAVIGATION_SYSTEM: _ClassVar[Source.Sensor]
        PRESSURE: _ClassVar[Source.Sensor]
        DVL: _ClassVar[Source.Sensor]
        RPM_LOOKUP: _ClassVar[Source.Sensor]
        MAGNETIC_COMPASS: _ClassVar[Source.Sensor]
    GPS: Source.Sensor
    USBL: Source.Sensor
    LBL: Source.Sensor
    INERTIAL_NAVIGATION_SYSTEM: Source.Sensor
    PRESSURE: Source.Sensor
    DVL: Source.Sensor
    RPM_LOOKUP: Source.Sensor
    MAGNETIC_COMPASS: Source.Sensor
    POSITION_FIELD_NUMBER: _ClassVar[int]
    DEPTH_FIELD_NUMBER: _ClassVar[int]
    SPEED_FIELD_NUMBER: _ClassVar[int]
    HEADING_FIELD_NUMBER: _ClassVar[int]
    position: Source.Sensor
    depth: Source.Sensor
    speed: Source.Sensor
    heading: Source.Sensor
    def __init__(self, position: _Optional[_Union[Source.Sensor, str]] = ..., depth: _Optional[_Union[Source.Sensor, str]] = ..., speed: _Optional[_Union[Source.Sensor, str]] = ..., heading: _Optional[_Union[Source.Sensor, str]] = ...) -> None: ...

class CartesianCoordinate(_message.Message):
    __slots__ = ("x", "y", "z")
    Extensions: _python_message._ExtensionDict
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    z: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., z: _Optional[float] = ...) -> None: ...

class EulerAngles(_message.Message):
    __slots__ = ("roll", "pitch", "heading", "course_over_ground", "roll_rate", "pitch_rate", "heading_rate")
    Extensions: _python_message._ExtensionDict
    ROLL_FIELD_NUMBER: _ClassVar[int]
    PITCH_FIELD_NUMBER: _ClassVar[int]
    HEADING_FIELD_NUMBER: _ClassVar[int]
    COURSE_OVER_GROUND_FIELD_NUMBER: _ClassVar[int]
    ROLL_RATE_FIELD_NUMBER: _ClassVar[int]
    PITCH_RATE_FIELD_NUMBER: _ClassVar[int]
    HEADING_RATE_FIELD_NUMBER: _ClassVar[int]
    roll: float
    pitch: float
    heading: float
    course_over_ground: float
    roll_rate: float
    pitch_rate: float
    heading_rate: float
    def __init__(self, roll: _Optional[float] = ..., pitch: _Optional[float] = ..., heading: _Optional[float] = ..., course_over_ground: _Optional[float] = ..., roll_rate: _Optional[float] = ..., pitch_rate: _Optional[float] = ..., heading_rate: _Optional[float] = ...) -> None: ...

class Speed(_message.Message):
    __slots__ = ("over_ground", "over_water")
    Extensions: _python_message._ExtensionDict
    OVER_GROUND_FIELD_NUMBER: _ClassVar[int]
    OVER_WATER_FIELD_NUMBER: _ClassVar[int]
    over_ground: float
    over_water: float
    def __init__(self, over_ground: _Optional[float] = ..., over_water: _Optional[float] = ...) -> None: ...

class CTDSample(_message.Message):
    __slots__ = ("time", "conductivity", "temperature", "pressure", "salinity", "sound_speed", "density", "global_fix", "salinity_algorithm", "sound_speed_algorithm", "density_algorithm")
    Extensions: _python_message._ExtensionDict
    class SalinityAlgorithm(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        SAL_ALGORITHM_UNKNOWN: _ClassVar[CTDSample.SalinityAlgorithm]
        UNESCO_44_PREKIN_AND_LEWIS_1980: _ClassVar[CTDSample.SalinityAlgorithm]
    SAL_ALGORITHM_UNKNOWN: CTDSample.SalinityAlgorithm
    UNESCO_44_PREKIN_AND_LEWIS_1980: CTDSample.SalinityAlgorithm
    class SoundSpeedAlgorithm(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        SS_ALGORITHM_UNKNOWN: _ClassVar[CTDSample.SoundSpeedAlgorithm]
        UNESCO_44_CHEN_AND_MILLERO_1977: _ClassVar[CTDSample.SoundSpeedAlgorithm]
        MACKENZIE_1981: _ClassVar[CTDSample.SoundSpeedAlgorithm]
        DEL_GROSSO_1974: _ClassVar[CTDSample.SoundSpeedAlgorithm]
    SS_ALGORITHM_UNKNOWN: CTDSample.SoundSpeedAlgorithm
    UNESCO_44_CHEN_AND_MILLERO_1977: CTDSample.SoundSpeedAlgorithm
    MACKENZIE_1981: CTDSample.SoundSpeedAlgorithm
    DEL_GROSSO_1974: CTDSample.SoundSpeedAlgorithm
    class DensityAlgorithm(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        DENSITY_ALGORITHM_UNKNOWN: _ClassVar[CTDSample.DensityAlgorithm]
        UNESCO_38_MILLERO_AND_POISSON_1981: _ClassVar[CTDSample.DensityAlgorithm]
    DENSITY_ALGORITHM_UNKNOWN: CTDSample.DensityAlgorithm
    UNESCO_38_MILLERO_AND_POISSON_1981: CTDSample.DensityAlgorithm
    TIME_FIELD_NUMBER: _ClassVar[int]
    CONDUCTIVITY_FIELD_NUMBER: _ClassVar[int]
    TEMPERATURE_FIELD_NUMBER: _ClassVar[int]
    PRESSURE_FIELD_NUMBER: _ClassVar[int]
    SALINITY_FIELD_NUMBER: _ClassVar[int]
    SOUND_SPEED_FIELD_NUMBER: _ClassVar[int]
    DENSITY_FIELD_NUMBER: _ClassVar[int]
    GLOBAL_FIX_FIELD_NUMBER: _ClassVar[int]
    SALINITY_ALGORITHM_FIELD_NUMBER: _ClassVar[int]
    SOUND_SPEED_ALGORITHM_FIELD_NUMBER: _ClassVar[int]
    DENSITY_ALGORITHM_FIELD_NUMBER: _ClassVar[int]
    time: float
    conductivity: float
    temperature: float
    pressure: float
    salinity: float
    sound_speed: float
    density: float
    global_fix: _geographic_pb2.LatLonPoint
    salinity_algorithm: CTDSample.SalinityAlgorithm
    sound_speed_algorithm: CTDSample.SoundSpeedAlgorithm
    density_algorithm: CTDSample.DensityAlgorithm
    def __init__(self, time: _Optional[float] = ..., conductivity: _Optional[float] = ..., temperature: _Optional[float] = ..., pressure: _Optional[float] = ..., salinity: _Optional[float] = ..., sound_speed: _Optional[float] = ..., density: _Optional[float] = ..., global_fix: _Optional[_Union[_geographic_pb2.LatLonPoint, _Mapping]] = ..., salinity_algorithm: _Optional[_Union[CTDSample.SalinityAlgorithm, str]] = ..., sound_speed_algorithm: _Optional[_Union[CTDSample.SoundSpeedAlgorithm, str]] = ..., density_algorithm: _Optional[_Union[CTDSample.DensityAlgorithm, str]] = ...) -> None: ...

class DatumUpdate(_message.Message):
    __slots__ = ("datum",)
    DATUM_FIELD_NUMBER: _ClassVar[int]
    datum: _geographic_pb2.LatLonPoint
    def __init__(self, datum: _Optional[_Union[_geographic_pb2.LatLonPoint, _Mapping]] = ...) -> None: ...
