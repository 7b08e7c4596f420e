from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as _option_extensions_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class Placeholder(_message.Message):
    __slots__ = ("a",)
    A_FIELD_NUMBER: _ClassVar[int]
    a: int
    def __init__(self, a: _Optional[int] = ...) -> None: ...

class DynamicBufferConfig(_message.Message):
    __slots__ = ("ack_required", "blackout_time", "max_queue", "newest_first", "ttl", "value_base")
    ACK_REQUIRED_FIELD_NUMBER: _ClassVar[int]
    BLACKOUT_TIME_FIELD_NUMBER: _ClassVar[int]
    MAX_QUEUE_FIELD_NUMBER: _ClassVar[int]
    NEWEST_FIRST_FIELD_NUMBER: _ClassVar[int]
    TTL_FIELD_NUMBER: _ClassVar[int]
    VALUE_BASE_FIELD_NUMBER: _ClassVar[int]
    ack_required: bool
    blackout_time: float
    max_queue: int
    newest_first: bool
    ttl: float
    value_base: float
    def __init__(self, ack_required: _Optional[bool] = ..., blackout_time: _Optional[float] = ..., max_queue: _Optional[int] = ..., newest_first: _Optional[bool] = ..., ttl: _Optional[float] = ..., value_base: _Optional[float] = ...) -> None: ...

class TransporterConfig(_message.Message):
    __slots__ = ("publisher_id", "subscriber_uuid", "buffer", "broadcast")
    PUBLISHER_ID_FIELD_NUMBER: _ClassVar[int]
    SUBSCRIBER_UUID_FIELD_NUMBER: _ClassVar[int]
    BUFFER_FIELD_NUMBER: _ClassVar[int]
    BROADCAST_FIELD_NUMBER: _ClassVar[int]
    publisher_id: _containers.RepeatedScalarFieldContainer[int]
    subscriber_uuid: int
    buffer: DynamicBufferConfig
    broadcast: bool
    def __init__(self, publisher_id: _Optional[_Iterable[int]] = ..., subscriber_uuid: _Optional[int] = ..., buffer: _Optional[_Union[DynamicBufferConfig, _Mapping]] = ..., broadcast: _Optional[bool] = ...) -> None: ...

class Header(_message.Message):
    __slots__ = ("src", "dest", "modem_msg")
    SRC_FIELD_NUMBER: _ClassVar[int]
    DEST_FIELD_NUMBER: _ClassVar[int]
    MODEM_MSG_FIELD_NUMBER: _ClassVar[int]
    src: int
    dest: _containers.RepeatedScalarFieldContainer[int]
    modem_msg: Placeholder
    def __init__(self, src: _Optional[int] = ..., dest: _Optional[_Iterable[int]] = ..., modem_msg: _Optional[_Union[Placeholder, _Mapping]] = ...) -> None: ...

class Subscription(_message.Message):
    __slots__ = ("api_version", "header", "time", "action", "dccl_id", "group", "intervehicle", "metadata")
    class Action(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        SUBSCRIBE: _ClassVar[Subscription.Action]
        UNSUBSCRIBE: _ClassVar[Subscription.Action]
    SUBSCRIBE: Subscription.Action
    UNSUBSCRIBE: Subscription.Action
    API_VERSION_FIELD_NUMBER: _ClassVar[int]
    HEADER_FIELD_NUMBER: _ClassVar[int]
    TIME_FIELD_NUMBER: _ClassVar[int]
    ACTION_FIELD_NUMBER: _ClassVar[int]
    DCCL_ID_FIELD_NUMBER: _ClassVar[int]
    GROUP_FIELD_NUMBER: _ClassVar[int]
    INTERVEHICLE_FIELD_NUMBER: _ClassVar[int]
    METADATA_FIELD_NUMBER: _ClassVar[int]
    api_version: int
    header: Header
    time: int
    action: Subscription.Action
    dccl_id: int
    group: int
    intervehicle: TransporterConfig
    metadata: Placeholder
    def __init__(self, api_version: _Optional[int] = ..., header: _Optional[_Union[Header, _Mapping]] = ..., time: _Optional[int] = ..., action: _Optional[_Union[Subscription.Action, str]] = ..., dccl_id: _Optional[int] = ..., group: _Optional[int] = ..., intervehicle: _Optional[_Union[TransporterConfig, _Mapping]] = ..., metadata: _Optional[_Union[Placeholder, _Mapping]] = ...) -> None: ...

class Everything(_message.Message):
    __slots__ = ("d", "f", "i32", "i64", "u32", "u64", "s32", "flag", "packed", "unpacked", "text", "blob", "var_blob", "var_text", "present", "present_text", "fixed", "fixed_text", "time_us", "time_us_p", "time_s", "other_id", "skipped")
    class Colour(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        RED: _ClassVar[Everything.Colour]
        GREEN: _ClassVar[Everything.Colour]
        BLUE: _ClassVar[Everything.Colour]
    RED: Everything.Colour
    GREEN: Everything.Colour
    BLUE: Everything.Colour
    D_FIELD_NUMBER: _ClassVar[int]
    F_FIELD_NUMBER: _ClassVar[int]
    I32_FIELD_NUMBER: _ClassVar[int]
    I64_FIELD_NUMBER: _ClassVar[int]
    U32_FIELD_NUMBER: _ClassVar[int]
    U64_FIELD_NUMBER: _ClassVar[int]
    S32_FIELD_NUMBER: _ClassVar[int]
    FLAG_FIELD_NUMBER: _ClassVar[int]
    PACKED_FIELD_NUMBER: _ClassVar[int]
    UNPACKED_FIELD_NUMBER: _ClassVar[int]
    TEXT_FIELD_NUMBER: _ClassVar[int]
    BLOB_FIELD_NUMBER: _ClassVar[int]
    VAR_BLOB_FIELD_NUMBER: _ClassVar[int]
    VAR_TEXT_FIELD_NUMBER: _ClassVar[int]
    PRESENT_FIELD_NUMBER: _ClassVar[int]
    PRESENT_TEXT_FIELD_NUMBER: _ClassVar[int]
    FIXED_FIELD_NUMBER: _ClassVar[int]
    FIXED_TEXT_FIELD_NUMBER: _ClassVar[int]
    TIME_US_FIELD_NUMBER: _ClassVar[int]
    TIME_US_P_FIELD_NUMBER: _ClassVar[int]
    TIME_S_FIELD_NUMBER: _ClassVar[int]
    OTHER_ID_FIELD_NUMBER: _ClassVar[int]
    SKIPPED_FIELD_NUMBER: _ClassVar[int]
    d: float
    f: float
    i32: int
    i64: int
    u32: int
    u64: int
    s32: int
    flag: bool
    packed: Everything.Colour
    unpacked: Everything.Colour
    text: str
    blob: bytes
    var_blob: bytes
    var_text: str
    present: int
    present_text: str
    fixed: float
    fixed_text: str
    time_us: int
    time_us_p: int
    time_s: float
    other_id: int
    skipped: float
    def __init__(self, d: _Optional[float] = ..., f: _Optional[float] = ..., i32: _Optional[int] = ..., i64: _Optional[int] = ..., u32: _Optional[int] = ..., u64: _Optional[int] = ..., s32: _Optional[int] = ..., flag: _Optional[bool] = ..., packed: _Optional[_Union[Everything.Colour, str]] = ..., unpacked: _Optional[_Union[Everything.Colour, str]] = ..., text: _Optional[str] = ..., blob: _Optional[bytes] = ..., var_blob: _Optional[bytes] = ..., var_text: _Optional[str] = ..., present: _Optional[int] = ..., present_text: _Optional[str] = ..., fixed: _Optional[float] = ..., fixed_text: _Optional[str] = ..., time_us: _Optional[int] = ..., time_us_p: _Optional[int] = ..., time_s: _Optional[float] = ..., other_id: _Optional[int] = ..., skipped: _Optional[float] = ...) -> None: ...

class Layout(_message.Message):
    __slots__ = ("head_a", "head_pair", "body_inner", "plain_inner", "many", "values", "words", "ok", "ratio")
    class Inner(_message.Message):
        __slots__ = ("a", "b", "c")
        A_FIELD_NUMBER: _ClassVar[int]
        B_FIELD_NUMBER: _ClassVar[int]
        C_FIELD_NUMBER: _ClassVar[int]
        a: int
        b: int
        c: _containers.RepeatedScalarFieldContainer[bool]
        def __init__(self, a: _Optional[int] = ..., b: _Optional[int] = ..., c: _Optional[_Iterable[bool]] = ...) -> None: ...
    class Pair(_message.Message):
        __slots__ = ("a", "b")
        A_FIELD_NUMBER: _ClassVar[int]
        B_FIELD_NUMBER: _ClassVar[int]
        a: int
        b: int
        def __init__(self, a: _Optional[int] = ..., b: _Optional[int] = ...) -> None: ...
    HEAD_A_FIELD_NUMBER: _ClassVar[int]
    HEAD_PAIR_FIELD_NUMBER: _ClassVar[int]
    BODY_INNER_FIELD_NUMBER: _ClassVar[int]
    PLAIN_INNER_FIELD_NUMBER: _ClassVar[int]
    MANY_FIELD_NUMBER: _ClassVar[int]
    VALUES_FIELD_NUMBER: _ClassVar[int]
    WORDS_FIELD_NUMBER: _ClassVar[int]
    OK_FIELD_NUMBER: _ClassVar[int]
    RATIO_FIELD_NUMBER: _ClassVar[int]
    head_a: int
    head_pair: Layout.Pair
    body_inner: Layout.Inner
    plain_inner: Layout.Inner
    many: _containers.RepeatedCompositeFieldContainer[Layout.Inner]
    values: _containers.RepeatedScalarFieldContainer[float]
    words: _containers.RepeatedScalarFieldContainer[str]
    ok: bool
    ratio: float
    def __init__(self, head_a: _Optional[int] = ..., head_pair: _Optional[_Union[Layout.Pair, _Mapping]] = ..., body_inner: _Optional[_Union[Layout.Inner, _Mapping]] = ..., plain_inner: _Optional[_Union[Layout.Inner, _Mapping]] = ..., many: _Optional[_Iterable[_Union[Layout.Inner, _Mapping]]] = ..., values: _Optional[_Iterable[float]] = ..., words: _Optional[_Iterable[str]] = ..., ok: _Optional[bool] = ..., ratio: _Optional[float] = ...) -> None: ...

class BenchNested(_message.Message):
    __slots__ = ("vehicle", "time", "depth", "active", "pose", "status")
    class Pose(_message.Message):
        __slots__ = ("x", "y", "heading")
        X_FIELD_NUMBER: _ClassVar[int]
        Y_FIELD_NUMBER: _ClassVar[int]
        HEADING_FIELD_NUMBER: _ClassVar[int]
        x: float
        y: float
        heading: float
        def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., heading: _Optional[float] = ...) -> None: ...
    class Status(_message.Message):
        __slots__ = ("mode", "battery", "note")
        class Mode(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
            __slots__ = ()
            IDLE: _ClassVar[BenchNested.Status.Mode]
            SURVEY: _ClassVar[BenchNested.Status.Mode]
            TRANSIT: _ClassVar[BenchNested.Status.Mode]
            RECOVER: _ClassVar[BenchNested.Status.Mode]
        IDLE: BenchNested.Status.Mode
        SURVEY: BenchNested.Status.Mode
        TRANSIT: BenchNested.Status.Mode
        RECOVER: BenchNested.Status.Mode
        MODE_FIELD_NUMBER: _ClassVar[int]
        BATTERY_FIELD_NUMBER: _ClassVar[int]
        NOTE_FIELD_NUMBER: _ClassVar[int]
        mode: BenchNested.Status.Mode
        battery: int
        note: str
        def __init__(self, mode: _Optional[_Union[BenchNested.Status.Mode, str]] = ..., battery: _Optional[int] = ..., note: _Optional[str] = ...) -> None: ...
    VEHICLE_FIELD_NUMBER: _ClassVar[int]
    TIME_FIELD_NUMBER: _ClassVar[int]
    DEPTH_FIELD_NUMBER: _ClassVar[int]
    ACTIVE_FIELD_NUMBER: _ClassVar[int]
    POSE_FIELD_NUMBER: _ClassVar[int]
    STATUS_FIELD_NUMBER: _ClassVar[int]
    vehicle: int
    time: float
    depth: float
    active: bool
    pose: BenchNested.Pose
    status: BenchNested.Status
    def __init__(self, vehicle: _Optional[int] = ..., time: _Optional[float] = ..., depth: _Optional[float] = ..., active: _Optional[bool] = ..., pose: _Optional[_Union[BenchNested.Pose, _Mapping]] = ..., status: _Optional[_Union[BenchNested.Status, _Mapping]] = ...) -> None: ...
