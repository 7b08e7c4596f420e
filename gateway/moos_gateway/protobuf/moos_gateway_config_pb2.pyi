from gateway.goby.protobuf import app_config_pb2 as _app_config_pb2
from gateway.goby.protobuf import interprocess_config_pb2 as _interprocess_config_pb2
from gateway.moos_gateway.protobuf import translator_pb2 as _translator_pb2
from google.protobuf.internal import python_message as _python_message
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Mapping as _Mapping
from typing import ClassVar as _ClassVar, Optional as _Optional, Union as _Union

DESCRIPTOR: _descriptor.FileDescriptor

class GobyMOOSGatewayConfig(_message.Message):
    __slots__ = ("app", "interprocess", "moos", "poll_frequency")
    Extensions: _python_message._ExtensionDict
    class MOOSConfig(_message.Message):
        __slots__ = ("server", "port", "use_binary_protobuf", "moos_parser_technique")
        SERVER_FIELD_NUMBER: _ClassVar[int]
        PORT_FIELD_NUMBER: _ClassVar[int]
        USE_BINARY_PROTOBUF_FIELD_NUMBER: _ClassVar[int]
        MOOS_PARSER_TECHNIQUE_FIELD_NUMBER: _ClassVar[int]
        server: str
        port: int
        use_binary_protobuf: bool
        moos_parser_technique: _translator_pb2.TranslatorEntry.ParserSerializerTechnique
        def __init__(self, server: _Optional[str] = ..., port: _Optional[int] = ..., use_binary_protobuf: _Optional[bool] = ..., moos_parser_technique: _Optional[_Union[_translator_pb2.TranslatorEntry.ParserSerializerTechnique, str]] = ...) -> None: ...
    APP_FIELD_NUMBER: _ClassVar[int]
    INTERPROCESS_FIELD_NUMBER: _ClassVar[int]
    MOOS_FIELD_NUMBER: _ClassVar[int]
    POLL_FREQUENCY_FIELD_NUMBER: _ClassVar[int]
    app: _app_config_pb2.AppConfig
    interprocess: _interprocess_config_pb2.InterProcessPortalConfig
    moos: GobyMOOSGatewayConfig.MOOSConfig
    poll_frequency: float
    def __init__(self, app: _Optional[_Union[_app_config_pb2.AppConfig, _Mapping]] = ..., interprocess: _Optional[_Union[_interprocess_config_pb2.InterProcessPortalConfig, _Mapping]] = ..., moos: _Optional[_Union[GobyMOOSGatewayConfig.MOOSConfig, _Mapping]] = ..., poll_frequency: _Optional[float] = ...) -> None: ...
