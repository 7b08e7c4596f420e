from gateway.goby.protobuf import app_config_pb2 as _app_config_pb2
from gateway.goby.protobuf import layer_pb2 as _layer_pb2
from gateway.goby.protobuf import interprocess_config_pb2 as _interprocess_config_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf.internal import python_message as _python_message
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable, Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class LiaisonConfig(_message.Message):
    __slots__ = ("app", "interprocess", "http_address", "http_port", "docroot", "additional_wt_http_params", "update_freq", "load_shared_library", "load_proto_file", "load_proto_dir", "start_paused", "upper_right_logo", "upper_right_logo_link", "add_home_tab", "add_scope_tab", "add_commander_tab", "pb_commander_config", "pb_scope_config")
    Extensions: _python_message._ExtensionDict
    APP_FIELD_NUMBER: _ClassVar[int]
    INTERPROCESS_FIELD_NUMBER: _ClassVar[int]
    HTTP_ADDRESS_FIELD_NUMBER: _ClassVar[int]
    HTTP_PORT_FIELD_NUMBER: _ClassVar[int]
    DOCROOT_FIELD_NUMBER: _ClassVar[int]
    ADDITIONAL_WT_HTTP_PARAMS_FIELD_NUMBER: _ClassVar[int]
    UPDATE_FREQ_FIELD_NUMBER: _ClassVar[int]
    LOAD_SHARED_LIBRARY_FIELD_NUMBER: _ClassVar[int]
    LOAD_PROTO_FILE_FIELD_NUMBER: _ClassVar[int]
    LOAD_PROTO_DIR_FIELD_NUMBER: _ClassVar[int]
    START_PAUSED_FIELD_NUMBER: _ClassVar[int]
    UPPER_RIGHT_LOGO_FIELD_NUMBER: _ClassVar[int]
    UPPER_RIGHT_LOGO_LINK_FIELD_NUMBER: _ClassVar[int]
    ADD_HOME_TAB_FIELD_NUMBER: _ClassVar[int]
    ADD_SCOPE_TAB_FIELD_NUMBER: _ClassVar[int]
    ADD_COMMANDER_TAB_FIELD_NUMBER: _ClassVar[int]
    PB_COMMANDER_CONFIG_FIELD_NUMBER: _ClassVar[int]
    PB_SCOPE_CONFIG_FIELD_NUMBER: _ClassVar[int]
    app: _app_config_pb2.AppConfig
    interprocess: _interprocess_config_pb2.InterProcessPortalConfig
    http_address: str
    http_port: int
    docroot: str
    additional_wt_http_params: str
    update_freq: float
    load_shared_library: _containers.RepeatedScalarFieldContainer[str]
    load_proto_file: _containers.RepeatedScalarFieldContainer[str]
    load_proto_dir: _containers.RepeatedScalarFieldContainer[str]
    start_paused: bool
    upper_right_logo: str
    upper_right_logo_link: str
    add_home_tab: bool
    add_scope_tab: bool
    add_commander_tab: bool
    pb_commander_config: ProtobufCommanderConfig
    pb_scope_config: ProtobufScopeConfig
    def __init__(self, app: _Optional[_Union[_app_config_pb2.AppConfig, _Mapping]] = ..., interprocess: _Optional[_Union[_interprocess_config_pb2.InterProcessPortalConfig, _Mapping]] = ..., http_address: _Optional[str] = ..., http_port: _Optional[int] = ..., docroot: _Optional[str] = ..., additional_wt_http_params: _Optional[str] = ..., update_freq: _Optional[float] = ..., load_shared_library: _Optional[_Iterable[str]] = ..., load_proto_file: _Optional[_Iterable[str]] = ..., load_proto_dir: _Optional[_Iterable[str]] = ..., start_paused: _Optional[bool] = ..., upper_right_logo: _Optional[str] = ..., upper_right_logo_link: _Optional[str] = ..., add_home_tab: _Optional[bool] = ..., add_scope_tab: _Optional[bool] = ..., add_commander_tab: _Optional[bool] = ..., pb_commander_config: _Optional[_Union[ProtobufCommanderConfig, _Mapping]] = ..., pb_scope_config: _Optional[_Union[ProtobufScopeConfig, _Mapping]] = ...) -> None: ...

class ProtobufCommanderConfig(_message.Message):
    __slots__ = ("load_protobuf", "value_width_pixels", "modify_width_pixels", "external_data_width_pixels", "sqlite3_database", "database_pool_size", "database_view_height", "database_width", "modal_dimensions", "notify_subscribe", "external_database_width")
    class Column(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        COLUMN_COMMENT: _ClassVar[ProtobufCommanderConfig.Column]
        COLUMN_NAME: _ClassVar[ProtobufCommanderConfig.Column]
        COLUMN_GROUP: _ClassVar[ProtobufCommanderConfig.Column]
        COLUMN_LAYER: _ClassVar[ProtobufCommanderConfig.Column]
        COLUMN_IP: _ClassVar[ProtobufCommanderConfig.Column]
        COLUMN_TIME: _ClassVar[ProtobufCommanderConfig.Column]
        COLUMN_LAST_ACK: _ClassVar[ProtobufCommanderConfig.Column]
        COLUMN_MAX: _ClassVar[ProtobufCommanderConfig.Column]
    COLUMN_COMMENT: ProtobufCommanderConfig.Column
    COLUMN_NAME: ProtobufCommanderConfig.Column
    COLUMN_GROUP: ProtobufCommanderConfig.Column
    COLUMN_LAYER: ProtobufCommanderConfig.Column
    COLUMN_IP: ProtobufCommanderConfig.Column
    COLUMN_TIME: ProtobufCommanderConfig.Column
    COLUMN_LAST_ACK: ProtobufCommanderConfig.Column
    COLUMN_MAX: ProtobufCommanderConfig.Column
    class ExternalDataColumn(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        EXTERNAL_DATA_COLUMN_NAME: _ClassVar[ProtobufCommanderConfig.ExternalDataColumn]
        EXTERNAL_DATA_COLUMN_GROUP: _ClassVar[ProtobufCommanderConfig.ExternalDataColumn]
        EXTERNAL_DATA_COLUMN_TIME: _ClassVar[ProtobufCommanderConfig.ExternalDataColumn]
        EXTERNAL_DATA_COLUMN_VALUE: _ClassVar[ProtobufCommanderConfig.ExternalDataColumn]
        EXTERNAL_DATA_COLUMN_MAX: _ClassVar[ProtobufCommanderConfig.ExternalDataColumn]
    EXTERNAL_DATA_COLUMN_NAME: ProtobufCommanderConfig.ExternalDataColumn
    EXTERNAL_DATA_COLUMN_GROUP: ProtobufCommanderConfig.ExternalDataColumn
    EXTERNAL_DATA_COLUMN_TIME: ProtobufCommanderConfig.ExternalDataColumn
    EXTERNAL_DATA_COLUMN_VALUE: ProtobufCommanderConfig.ExternalDataColumn
    EXTERNAL_DATA_COLUMN_MAX: ProtobufCommanderConfig.ExternalDataColumn
    class LoadProtobuf(_message.Message):
        __slots__ = ("name", "publish_to", "external_data")
        class GroupLayer(_message.Message):
            __slots__ = ("group", "group_numeric", "group_numeric_field_name", "layer")
            GROUP_FIELD_NUMBER: _ClassVar[int]
            GROUP_NUMERIC_FIELD_NUMBER: _ClassVar[int]
            GROUP_NUMERIC_FIELD_NAME_FIELD_NUMBER: _ClassVar[int]
            LAYER_FIELD_NUMBER: _ClassVar[int]
            group: str
            group_numeric: int
            group_numeric_field_name: str
            layer: _layer_pb2.Layer
            def __init__(self, group: _Optional[str] = ..., group_numeric: _Optional[int] = ..., group_numeric_field_name: _Optional[str] = ..., layer: _Optional[_Union[_layer_pb2.Layer, str]] = ...) -> None: ...
        class ExternalData(_message.Message):
            __slots__ = ("name", "group", "translate")
            class Translation(_message.Message):
                __slots__ = ("to",)
                FROM_FIELD_NUMBER: _ClassVar[int]
                TO_FIELD_NUMBER: _ClassVar[int]
                to: str
                def __init__(self, to: _Optional[str] = ..., **kwargs) -> None: ...
            NAME_FIELD_NUMBER: _ClassVar[int]
            GROUP_FIELD_NUMBER: _ClassVar[int]
            TRANSLATE_FIELD_NUMBER: _ClassVar[int]
            name: str
            group: str
            translate: _containers.RepeatedCompositeFieldContainer[ProtobufCommanderConfig.LoadProtobuf.ExternalData.Translation]
            def __init__(self, name: _Optional[str] = ..., group: _Optional[str] = ..., translate: _Optional[_Iterable[_Union[ProtobufCommanderConfig.LoadProtobuf.ExternalData.Translation, _Mapping]]] = ...) -> None: ...
        NAME_FIELD_NUMBER: _ClassVar[int]
        PUBLISH_TO_FIELD_NUMBER: _ClassVar[int]
        EXTERNAL_DATA_FIELD_NUMBER: _ClassVar[int]
        name: str
        publish_to: _containers.RepeatedCompositeFieldContainer[ProtobufCommanderConfig.LoadProtobuf.GroupLayer]
        external_data: _containers.RepeatedCompositeFieldContainer[ProtobufCommanderConfig.LoadProtobuf.ExternalData]
        def __init__(self, name: _Optional[str] = ..., publish_to: _Optional[_Iterable[_Union[ProtobufCommanderConfig.LoadProtobuf.GroupLayer, _Mapping]]] = ..., external_data: _Optional[_Iterable[_Union[ProtobufCommanderConfig.LoadProtobuf.ExternalData, _Mapping]]] = ...) -> None: ...
    class DatabaseColumnWidthPixels(_message.Message):
        __slots__ = ("comment_width", "name_width", "group_width", "layer_width", "ip_width", "time_width", "last_ack_width")
        COMMENT_WIDTH_FIELD_NUMBER: _ClassVar[int]
        NAME_WIDTH_FIELD_NUMBER: _ClassVar[int]
        GROUP_WIDTH_FIELD_NUMBER: _ClassVar[int]
        LAYER_WIDTH_FIELD_NUMBER: _ClassVar[int]
        IP_WIDTH_FIELD_NUMBER: _ClassVar[int]
        TIME_WIDTH_FIELD_NUMBER: _ClassVar[int]
        LAST_ACK_WIDTH_FIELD_NUMBER: _ClassVar[int]
        comment_width: int
        name_width: int
        group_width: int
        layer_width: int
        ip_width: int
        time_width: int
        last_ack_width: int
        def __init__(self, comment_width: _Optional[int] = ..., name_width: _Optional[int] = ..., group_width: _Optional[int] = ..., layer_width: _Optional[int] = ..., ip_width: _Optional[int] = ..., time_width: _Optional[int] = ..., last_ack_width: _Optional[int] = ...) -> None: ...
    class ModalDialogDimensions(_message.Message):
        __slots__ = ("width", "height")
        WIDTH_FIELD_NUMBER: _ClassVar[int]
        HEIGHT_FIELD_NUMBER: _ClassVar[int]
        width: int
        height: int
        def __init__(self, width: _Optional[int] = ..., height: _Optional[int] = ...) -> None: ...
    class NotificationSubscription(_message.Message):
        __slots__ = ("type_regex", "group_regex", "background_color")
        class Color(_message.Message):
            __slots__ = ("r", "g", "b", "a")
            R_FIELD_NUMBER: _ClassVar[int]
            G_FIELD_NUMBER: _ClassVar[int]
            B_FIELD_NUMBER: _ClassVar[int]
            A_FIELD_NUMBER: _ClassVar[int]
            r: int
            g: int
            b: int
            a: int
            def __init__(self, r: _Optional[int] = ..., g: _Optional[int] = ..., b: _Optional[int] = ..., a: _Optional[int] = ...) -> None: ...
        TYPE_REGEX_FIELD_NUMBER: _ClassVar[int]
        GROUP_REGEX_FIELD_NUMBER: _ClassVar[int]
        BACKGROUND_COLOR_FIELD_NUMBER: _ClassVar[int]
        type_regex: str
        group_regex: str
        background_color: ProtobufCommanderConfig.NotificationSubscription.Color
        def __init__(self, type_regex: _Optional[str] = ..., group_regex: _Optional[str] = ..., background_color: _Optional[_Union[ProtobufCommanderConfig.NotificationSubscription.Color, _Mapping]] = ...) -> None: ...
    class DatabaseExternalDataColumnWidthPixels(_message.Message):
        __slots__ = ("name_width", "group_width", "time_width", "value_width")
        NAME_WIDTH_FIELD_NUMBER: _ClassVar[int]
        GROUP_WIDTH_FIELD_NUMBER: _ClassVar[int]
        TIME_WIDTH_FIELD_NUMBER: _ClassVar[int]
        VALUE_WIDTH_FIELD_NUMBER: _ClassVar[int]
        name_width: int
        group_width: int
        time_width: int
        value_width: int
        def __init__(self, name_width: _Optional[int] = ..., group_width: _Optional[int] = ..., time_width: _Optional[int] = ..., value_width: _Optional[int] = ...) -> None: ...
    LOAD_PROTOBUF_FIELD_NUMBER: _ClassVar[int]
    VALUE_WIDTH_PIXELS_FIELD_NUMBER: _ClassVar[int]
    MODIFY_WIDTH_PIXELS_FIELD_NUMBER: _ClassVar[int]
    EXTERNAL_DATA_WIDTH_PIXELS_FIELD_NUMBER: _ClassVar[int]
    SQLITE3_DATABASE_FIELD_NUMBER: _ClassVar[int]
    DATABASE_POOL_SIZE_FIELD_NUMBER: _ClassVar[int]
    DATABASE_VIEW_HEIGHT_FIELD_NUMBER: _ClassVar[int]
    DATABASE_WIDTH_FIELD_NUMBER: _ClassVar[int]
    MODAL_DIMENSIONS_FIELD_NUMBER: _ClassVar[int]
    NOTIFY_SUBSCRIBE_FIELD_NUMBER: _ClassVar[int]
    EXTERNAL_DATABASE_WIDTH_FIELD_NUMBER: _ClassVar[int]
    load_protobuf: _containers.RepeatedCompositeFieldContainer[ProtobufCommanderConfig.LoadProtobuf]
    value_width_pixels: int
    modify_width_pixels: int
    external_data_width_pixels: int
    sqlite3_database: str
    database_pool_size: int
    database_view_height: int
    database_width: ProtobufCommanderConfig.DatabaseColumnWidthPixels
    modal_dimensions: ProtobufCommanderConfig.ModalDialogDimensions
    notify_subscribe: _containers.RepeatedCompositeFieldContainer[ProtobufCommanderConfig.NotificationSubscription]
    external_database_width: ProtobufCommanderConfig.DatabaseExternalDataColumnWidthPixels
    def __init__(self, load_protobuf: _Optional[_Iterable[_Union[ProtobufCommanderConfig.LoadProtobuf, _Mapping]]] = ..., value_width_pixels: _Optional[int] = ..., modify_width_pixels: _Optional[int] = ..., external_data_width_pixels: _Optional[int] = ..., sqlite3_database: _Optional[str] = ..., database_pool_size: _Optional[int] = ..., database_view_height: _Optional[int] = ..., database_width: _Optional[_Union[ProtobufCommanderConfig.DatabaseColumnWidthPixels, _Mapping]] = ..., modal_dimensions: _Optional[_Union[ProtobufCommanderConfig.ModalDialogDimensions, _Mapping]] = ..., notify_subscribe: _Optional[_Iterable[_Union[ProtobufCommanderConfig.NotificationSubscription, _Mapping]]] = ..., external_database_width: _Optional[_Union[ProtobufCommanderConfig.DatabaseExternalDataColumnWidthPixels, _Mapping]] = ...) -> None: ...

class ProtobufScopeConfig(_message.Message):
    __slots__ = ("column_width", "sort_by_column", "sort_ascending", "scope_height", "history_height", "group_regex_filter_expression", "type_regex_filter_expression", "history", "max_history_items", "max_message_size_bytes")
    class Column(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = ()
        COLUMN_GROUP: _ClassVar[ProtobufScopeConfig.Column]
        COLUMN_TYPE: _ClassVar[ProtobufScopeConfig.Column]
        COLUMN_VALUE: _ClassVar[ProtobufScopeConfig.Column]
        COLUMN_TIME: _ClassVar[ProtobufScopeConfig.Column]
        COLUMN_MAX: _ClassVar[ProtobufScopeConfig.Column]
    COLUMN_GROUP: ProtobufScopeConfig.Column
    COLUMN_TYPE: ProtobufScopeConfig.Column
    COLUMN_VALUE: ProtobufScopeConfig.Column
    COLUMN_TIME: ProtobufScopeConfig.Column
    COLUMN_MAX: ProtobufScopeConfig.Column
    class ColumnWidthPixels(_message.Message):
        __slots__ = ("group_width", "type_width", "value_width", "time_width")
        GROUP_WIDTH_FIELD_NUMBER: _ClassVar[int]
        TYPE_WIDTH_FIELD_NUMBER: _ClassVar[int]
        VALUE_WIDTH_FIELD_NUMBER: _ClassVar[int]
        TIME_WIDTH_FIELD_NUMBER: _ClassVar[int]
        group_width: int
        type_width: int
        value_width: int
        time_width: int
        def __init__(self, group_width: _Optional[int] = ..., type_width: _Optional[int] = ..., value_width: _Optional[int] = ..., time_width: _Optional[int] = ...) -> None: ...
    class HistoryConfig(_message.Message):
        __slots__ = ("group",)
        GROUP_FIELD_NUMBER: _ClassVar[int]
        group: str
        def __init__(self, group: _Optional[str] = ...) -> None: ...
    COLUMN_WIDTH_FIELD_NUMBER: _ClassVar[int]
    SORT_BY_COLUMN_FIELD_NUMBER: _ClassVar[int]
    SORT_ASCENDING_FIELD_NUMBER: _ClassVar[int]
    SCOPE_HEIGHT_FIELD_NUMBER: _ClassVar[int]
    HISTORY_HEIGHT_FIELD_NUMBER: _ClassVar[int]
    GROUP_REGEX_FILTER_EXPRESSION_FIELD_NUMBER: _ClassVar[int]
    TYPE_REGEX_FILTER_EXPRESSION_FIELD_NUMBER: _ClassVar[int]
    HISTORY_FIELD_NUMBER: _ClassVar[int]
    MAX_HISTORY_ITEMS_FIELD_NUMBER: _ClassVar[int]
    MAX_MESSAGE_SIZE_BYTES_FIELD_NUMBER: _ClassVar[int]
    column_width: ProtobufScopeConfig.ColumnWidthPixels
    sort_by_column: ProtobufScopeConfig.Column
    sort_ascending: bool
    scope_height: int
    history_height: int
    group_regex_filter_expression: str
    type_regex_filter_expression: str
    history: _containers.RepeatedCompositeFieldContainer[ProtobufScopeConfig.HistoryConfig]
    max_history_items: int
    max_message_size_bytes: int
    def __init__(self, column_width: _Optional[_Union[ProtobufScopeConfig.ColumnWidthPixels, _Mapping]] = ..., sort_by_column: _Optional[_Union[ProtobufScopeConfig.Column, str]] = ..., sort_ascending: _Optional[bool] = ..., scope_height: _Optional[int] = ..., history_height: _Optional[int] = ..., group_regex_filter_expression: _Optional[str] = ..., type_regex_filter_expression: _Optional[str] = ..., history: _Optional[_Iterable[_Union[ProtobufScopeConfig.HistoryConfig, _Mapping]]] = ..., max_history_items: _Optional[int] = ..., max_message_size_bytes: _Optional[int] = ...) -> None: ...
