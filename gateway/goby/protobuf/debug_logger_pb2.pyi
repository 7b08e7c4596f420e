from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class GLogConfig(_message.Message):
    __slots__ = ("tty_verbosity", "show_gui", "file_log", "show_dccl_log")
    class Verbosity(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        QUIET: _ClassVar[GLogConfig.Verbosity]
        WARN: _ClassVar[GLogConfig.Verbosity]
        VERBOSE: _ClassVar[GLogConfig.Verbosity]
        DEBUG1: _ClassVar[GLogConfig.Verbosity]
        DEBUG2: _ClassVar[GLogConfig.Verbosity]
        DEBUG3: _ClassVar[GLogConfig.Verbosity]
    QUIET: GLogConfig.Verbosity
    WARN: GLogConfig.Verbosity
    VERBOSE: GLogConfig.Verbosity
    DEBUG1: GLogConfig.Verbosity
    DEBUG2: GLogConfig.Verbosity
    DEBUG3: GLogConfig.Verbosity
    class FileLog(_message.Message):
        __slots__ = ("file_name", "file_dir", "verbosity", "log_rotate_sec", "omit")
        class Omit(_message.Message):
            __slots__ = ("file_timestamp", "latest_symlink")
            FILE_TIMESTAMP_FIELD_NUMBER: _ClassVar[int]
            LATEST_SYMLINK_FIELD_NUMBER: _ClassVar[int]
            file_timestamp: bool
            latest_symlink: bool
            def __init__(self, file_timestamp: _Optional[bool] = ..., latest_symlink: _Optional[bool] = ...) -> None: ...
        FILE_NAME_FIELD_NUMBER: _ClassVar[int]
        FILE_DIR_FIELD_NUMBER: _ClassVar[int]
        VERBOSITY_FIELD_NUMBER: _ClassVar[int]
        LOG_ROTATE_SEC_FIELD_NUMBER: _ClassVar[int]
        OMIT_FIELD_NUMBER: _ClassVar[int]
        file_name: str
        file_dir: str
        verbosity: GLogConfig.Verbosity
        log_rotate_sec: int
        omit: GLogConfig.FileLog.Omit
        def __init__(self, file_name: _Optional[str] = ..., file_dir: _Optional[str] = ..., verbosity: _Optional[_Union[GLogConfig.Verbosity, str]] = ..., log_rotate_sec: _Optional[int] = ..., omit: _Optional[_Union[GLogConfig.FileLog.Omit, _Mapping]] = ...) -> None: ...
    TTY_VERBOSITY_FIELD_NUMBER: _ClassVar[int]
    SHOW_GUI_FIELD_NUMBER: _ClassVar[int]
    FILE_LOG_FIELD_NUMBER: _ClassVar[int]
    SHOW_DCCL_LOG_FIELD_NUMBER: _ClassVar[int]
    tty_verbosity: GLogConfig.Verbosity
    show_gui: bool
    file_log: GLogConfig.FileLog
    show_dccl_log: bool
    def __init__(self, tty_verbosity: _Optional[_Union[GLogConfig.Verbosity, str]] = ..., show_gui: _Optional[bool] = ..., file_log: _Optional[_Union[GLogConfig.FileLog, _Mapping]] = ..., show_dccl_log: _Optional[bool] = ...) -> None: ...
