"""DCCL (Dynamic Compact Control Language) v3 in pure Python: the wire format Goby3 sends between vehicles.

``Codec`` loads protobuf message types carrying DCCL's options (``dccl/option_extensions.proto``), checks them
as the C++ ``dccl::Codec`` does, compiles each into specialised encode/decode functions, and produces DCCL's
exact bytes. See docs/dccl.md.
"""

from gateway.goby.dccl.bounds import FieldBounds, numeric_bounds
from gateway.goby.dccl.codec import Codec
from gateway.goby.dccl.compiler import CompiledMessage
from gateway.goby.dccl.errors import (
    DcclError,
    DecodeError,
    DefinitionError,
    EncodeError,
    MissingFieldError,
    NotLoadedError,
    OutOfRangeError,
    TrailingBytesError,
    TruncatedError,
    UnknownIdError,
)
from gateway.goby.dccl.field_codec import Bits, FieldCodec, FieldContext
from gateway.goby.dccl.registry import CodecRegistry

__all__ = [
    "Bits",
    "Codec",
    "CodecRegistry",
    "CompiledMessage",
    "DcclError",
    "DecodeError",
    "DefinitionError",
    "EncodeError",
    "FieldBounds",
    "FieldCodec",
    "FieldContext",
    "MissingFieldError",
    "NotLoadedError",
    "OutOfRangeError",
    "TrailingBytesError",
    "TruncatedError",
    "UnknownIdError",
    "numeric_bounds",
]
