from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from typing import ClassVar as _ClassVar

DESCRIPTOR: _descriptor.FileDescriptor

class Layer(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = ()
    LAYER_INTERTHREAD: _ClassVar[Layer]
    LAYER_INTERPROCESS: _ClassVar[Layer]
    LAYER_INTERMODULE: _ClassVar[Layer]
    LAYER_INTERVEHICLE: _ClassVar[Layer]
LAYER_INTERTHREAD: Layer
LAYER_INTERPROCESS: Layer
LAYER_INTERMODULE: Layer
LAYER_INTERVEHICLE: Layer
