from frontseat.protobuf import frontseat_config_pb2 as _frontseat_config_pb2
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from typing import ClassVar as _ClassVar, Optional as _Optional

DESCRIPTOR: _descriptor.FileDescriptor
BASIC_SIMULATOR_TUNING_FIELD_NUMBER: _ClassVar[int]
basic_simulator_tuning: _descriptor.FieldDescriptor

class BasicSimulatorTuning(_message.Message):
    __slots__ = ("data_timeout", "reconnect_interval")
    DATA_TIMEOUT_FIELD_NUMBER: _ClassVar[int]
    RECONNECT_INTERVAL_FIELD_NUMBER: _ClassVar[int]
    data_timeout: float
    reconnect_interval: float
    def __init__(self, data_timeout: _Optional[float] = ..., reconnect_interval: _Optional[float] = ...) -> None: ...
