from frontseat.protobuf import frontseat_data_pb2 as _frontseat_data_pb2
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf.internal import python_message as _python_message
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class InterfaceState(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    INTERFACE_STANDBY: _ClassVar[InterfaceState]
    INTERFACE_LISTEN: _ClassVar[InterfaceState]
    INTERFACE_COMMAND: _ClassVar[InterfaceState]
    INTERFACE_HELM_ERROR: _ClassVar[InterfaceState]
    INTERFACE_FS_ERROR: _ClassVar[InterfaceState]

class FrontSeatState(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    FRONTSEAT_NOT_CONNECTED: _ClassVar[FrontSeatState]
    FRONTSEAT_IDLE: _ClassVar[FrontSeatState]
    FRONTSEAT_ACCEPTING_COMMANDS: _ClassVar[FrontSeatState]
    FRONTSEAT_IN_CONTROL: _ClassVar[FrontSeatState]

class HelmState(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    HELM_NOT_RUNNING: _ClassVar[HelmState]
    HELM_DRIVE: _ClassVar[HelmState]
    HELM_PARK: _ClassVar[HelmState]

class HelmError(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    ERROR_HELM_NONE: _ClassVar[HelmError]
    ERROR_HELM_NOT_RUNNING: _ClassVar[HelmError]
    ERROR_HELM_PARKED: _ClassVar[HelmError]

class FrontSeatError(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    ERROR_FRONTSEAT_NONE: _ClassVar[FrontSeatError]
    ERROR_FRONTSEAT_NOT_CONNECTED: _ClassVar[FrontSeatError]
    ERROR_FRONTSEAT_NOT_PROVIDING_DATA: _ClassVar[FrontSeatError]
    ERROR_FRONTSEAT_IGNORING_COMMANDS: _ClassVar[FrontSeatError]
INTERFACE_STANDBY: InterfaceState
INTERFACE_LISTEN: InterfaceState
INTERFACE_COMMAND: InterfaceState
INTERFACE_HELM_ERROR: InterfaceState
INTERFACE_FS_ERROR: InterfaceState
FRONTSEAT_NOT_CONNECTED: FrontSeatState
FRONTSEAT_IDLE: FrontSeatState
FRONTSEAT_ACCEPTING_COMMANDS: FrontSeatState
FRONTSEAT_IN_CONTROL: FrontSeatState
HELM_NOT_RUNNING: HelmState
HELM_DRIVE: HelmState
HELM_PARK: HelmState
ERROR_HELM_NONE: HelmError
ERROR_HELM_NOT_RUNNING: HelmError
ERROR_HELM_PARKED: HelmError
ERROR_FRONTSEAT_NONE: FrontSeatError
ERROR_FRONTSEAT_NOT_CONNECTED: FrontSeatError
ERROR_FRONTSEAT_NOT_PROVIDING_DATA: FrontSeatError
ERROR_FRONTSEAT_IGNORING_COMMANDS: FrontSeatError

class HelmStateReport(_message.Message):
    __slots__ = ("state",)
    STATE_FIELD_NUMBER: _ClassVar[int]
    state: HelmState
    def __init__(self, state: _Optional[_Union[HelmState, str]] = ...) -> None: ...

class InterfaceStatus(_message.Message):
    __slots__ = ("state", "frontseat_state", "helm_state", "helm_error", "frontseat_error")
    STATE_FIELD_NUMBER: _ClassVar[int]
    FRONTSEAT_STATE_FIELD_NUMBER: _ClassVar[int]
    HELM_STATE_FIELD_NUMBER: _ClassVar[int]
    HELM_ERROR_FIELD_NUMBER: _ClassVar[int]
    FRONTSEAT_ERROR_FIELD_NUMBER: _ClassVar[int]
    state: InterfaceState
    frontseat_state: FrontSeatState
    helm_state: HelmState
    helm_error: HelmError
    frontseat_error: FrontSeatError
    def __init__(self, state: _Optional[_Union[InterfaceState, str]] = ..., frontseat_state: _Optional[_Union[FrontSeatState, str]] = ..., helm_state: _Optional[_Union[HelmState, str]] = ..., helm_error: _Optional[_Union[HelmError, str]] = ..., frontseat_error: _Optional[_Union[FrontSeatError, str]] = ...) -> None: ...

class CommandRequest(_message.Message):
    __slots__ = ("desired_course", "response_requested", "request_id", "cancel_request_id")
    Extensions: _python_message._ExtensionDict
    DESIRED_COURSE_FIELD_NUMBER: _ClassVar[int]
    RESPONSE_REQUESTED_FIELD_NUMBER: _ClassVar[int]
    REQUEST_ID_FIELD_NUMBER: _ClassVar[int]
    CANCEL_REQUEST_ID_FIELD_NUMBER: _ClassVar[int]
    desired_course: _frontseat_data_pb2.DesiredCourse
    response_requested: bool
    request_id: int
    cancel_request_id: int
    def __init__(self, desired_course: _Optional[_Union[_frontseat_data_pb2.DesiredCourse, _Mapping]] = ..., response_requested: _Optional[bool] = ..., request_id: _Optional[int] = ..., cancel_request_id: _Optional[int] = ...) -> None: ...

class CommandResponse(_message.Message):
    __slots__ = ("request_successful", "request_id", "error_code", "error_string")
    Extensions: _python_message._ExtensionDict
    REQUEST_SUCCESSFUL_FIELD_NUMBER: _ClassVar[int]
    REQUEST_ID_FIELD_NUMBER: _ClassVar[int]
    ERROR_CODE_FIELD_NUMBER: _ClassVar[int]
    ERROR_STRING_FIELD_NUMBER: _ClassVar[int]
    request_successful: bool
    request_id: int
    error_code: int
    error_string: str
    def __init__(self, request_successful: _Optional[bool] = ..., request_id: _Optional[int] = ..., error_code: _Optional[int] = ..., error_string: _Optional[str] = ...) -> None: ...

class InterfaceData(_message.Message):
    __slots__ = ("node_status", "ctd_sample", "dccl_message")
    Extensions: _python_message._ExtensionDict
    NODE_STATUS_FIELD_NUMBER: _ClassVar[int]
    CTD_SAMPLE_FIELD_NUMBER: _ClassVar[int]
    DCCL_MESSAGE_FIELD_NUMBER: _ClassVar[int]
    node_status: _frontseat_data_pb2.NodeStatus
    ctd_sample: _frontseat_data_pb2.CTDSample
    dccl_message: bytes
    def __init__(self, node_status: _Optional[_Union[_frontseat_data_pb2.NodeStatus, _Mapping]] = ..., ctd_sample: _Optional[_Union[_frontseat_data_pb2.CTDSample, _Mapping]] = ..., dccl_message: _Optional[bytes] = ...) -> None: ...

class Raw(_message.Message):
    __slots__ = ("raw", "type", "description")
    Extensions: _python_message._ExtensionDict
    class RawType(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        RAW_ASCII: _ClassVar[Raw.RawType]
        RAW_BINARY: _ClassVar[Raw.RawType]
    RAW_ASCII: Raw.RawType
    RAW_BINARY: Raw.RawType
    RAW_FIELD_NUMBER: _ClassVar[int]
    TYPE_FIELD_NUMBER: _ClassVar[int]
    DESCRIPTION_FIELD_NUMBER: _ClassVar[int]
    raw: bytes
    type: Raw.RawType
    description: str
    def __init__(self, raw: _Optional[bytes] = ..., type: _Optional[_Union[Raw.RawType, str]] = ..., description: _Optional[str] = ...) -> None: ...
