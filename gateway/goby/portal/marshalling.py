"""Marshalling schemes with Goby's numeric ids, and protobuf/DCCL/string (de)serialization.

Wire type names: protobuf messages use the descriptor's ``full_name`` (under PROTOBUF and DCCL alike); strings
use ``CSTR`` and travel with a trailing NUL, as in Goby's ``cstr.h``. A DCCL-annotated protobuf message travels as
PROTOBUF on interprocess unless published with ``scheme=Scheme.DCCL``; then the payload is exactly its DCCL bytes
(Goby's ``SerializerParserHelper<T, DCCL>``), encoded by the process's DCCL codec, which loads each type on first
use as Goby's does.
"""

from __future__ import annotations

import enum
from typing import TYPE_CHECKING, Any

from google.protobuf import descriptor_pool, message_factory
from google.protobuf import message as pb_message

from gateway.goby.portal.errors import MarshallingError

if TYPE_CHECKING:
    from gateway.goby.dccl import Codec as DcclCodec


class Scheme(enum.IntEnum):
    """Goby's ``MarshallingScheme`` ids."""

    ALL_SCHEMES = -2
    NULL_SCHEME = -1
    CSTR = 0
    PROTOBUF = 1
    DCCL = 2
    CXX_OBJECT = 5
    MAVLINK = 6
    JSON = 7


def scheme_to_string(scheme: int) -> str:
    """The scheme's name as it appears in identifiers; unknown ids print as decimal (Goby's ``to_string``)."""
    try:
        return Scheme(scheme).name
    except ValueError:
        return str(scheme)


def scheme_from_string(text: str) -> int:
    """Inverse of :func:`scheme_to_string`; raises ``MarshallingError`` for text that is neither."""
    try:
        return int(Scheme[text])
    except KeyError:
        pass
    try:
        return int(text)
    except ValueError:
        raise MarshallingError(f"unknown marshalling scheme {text!r}") from None


def is_dccl(msg_type: type) -> bool:
    """True for protobuf messages carrying DCCL options (``dccl.msg`` id) — Goby's default scheme for them is DCCL."""
    if not issubclass(msg_type, pb_message.Message):
        return False
    options = msg_type.DESCRIPTOR.GetOptions()
    return any(field.full_name == "dccl.msg" for field, _ in options.ListFields())


def default_scheme(msg_type: type) -> int:
    """Goby's ``scheme<T>()``: DCCL for DCCL-annotated protobuf, PROTOBUF for other protobuf, CSTR for str.

    Interprocess replaces DCCL by PROTOBUF (``interprocess_scheme``), as Goby's interprocess transporter does.
    """
    if issubclass(msg_type, pb_message.Message):
        return Scheme.DCCL if is_dccl(msg_type) else Scheme.PROTOBUF
    if issubclass(msg_type, (str, bytes)):
        return Scheme.CSTR
    raise MarshallingError(f"no marshalling scheme for {msg_type.__qualname__}: use a protobuf message or str")


def interprocess_scheme(msg_type: type) -> int:
    """The scheme a type travels with on interprocess by default: DCCL becomes PROTOBUF (an explicit scheme
    is kept)."""
    scheme = default_scheme(msg_type)
    return Scheme.PROTOBUF if scheme == Scheme.DCCL else scheme


def type_name(msg_type: type, scheme: int) -> str:
    """The type name carried in identifiers for ``msg_type`` under ``scheme``."""
    if scheme == Scheme.CSTR:
        return "CSTR"
    if scheme in (Scheme.PROTOBUF, Scheme.DCCL) and issubclass(msg_type, pb_message.Message):
        return msg_type.DESCRIPTOR.full_name
    raise MarshallingError(f"cannot name {msg_type.__qualname__} under scheme {scheme_to_string(scheme)}")


def serialize(msg: Any, scheme: int, dccl: DcclCodec | None = None) -> bytes:
    """Encode ``msg`` for the wire under ``scheme`` (DCCL needs the process's codec, ``dccl``)."""
    if scheme == Scheme.DCCL and isinstance(msg, pb_message.Message) and dccl is not None:
        from gateway.goby.dccl import DcclError

        try:
            dccl.load(type(msg))
            return dccl.encode(msg)
        except DcclError as exc:
            raise MarshallingError(f"cannot DCCL-encode {msg.DESCRIPTOR.full_name}: {exc}") from exc
    if scheme == Scheme.CSTR:
        data = msg.encode() if isinstance(msg, str) else bytes(msg)
        return data + b"\0"
    if scheme == Scheme.PROTOBUF and isinstance(msg, pb_message.Message):
        try:
            return msg.SerializeToString()
        except pb_message.EncodeError as exc:
            raise MarshallingError(f"cannot serialize {msg.DESCRIPTOR.full_name}: {exc}") from exc
    raise MarshallingError(f"cannot serialize {type(msg).__qualname__} as {scheme_to_string(scheme)}")


def parse(data: bytes, scheme: int, msg_type: type, dccl: DcclCodec | None = None) -> Any:
    """Decode a payload into ``msg_type`` (``str`` for CSTR, drops the trailing NUL as Goby does; DCCL needs the
    process's codec, ``dccl``)."""
    if scheme == Scheme.CSTR:
        raw = data[:-1] if data.endswith(b"\0") else data
        if issubclass(msg_type, bytes):
            return raw
        try:
            return raw.decode()
        except UnicodeDecodeError as exc:
            raise MarshallingError(f"CSTR payload is not UTF-8: {exc}") from exc
    if scheme in (Scheme.PROTOBUF, Scheme.DCCL) and issubclass(msg_type, pb_message.Message):
        if scheme == Scheme.DCCL:
            if dccl is None:
                raise MarshallingError(f"no DCCL codec to decode {msg_type.DESCRIPTOR.full_name} with")
            from gateway.goby.dccl import DcclError

            try:
                dccl.load(msg_type)
                return dccl.decode(data, msg_type)
            except DcclError as exc:
                raise MarshallingError(f"cannot DCCL-decode {msg_type.DESCRIPTOR.full_name}: {exc}") from exc
        msg = msg_type()
        try:
            msg.ParseFromString(data)
        except pb_message.DecodeError as exc:
            raise MarshallingError(f"cannot parse {msg_type.DESCRIPTOR.full_name}: {exc}") from exc
        return msg
    raise MarshallingError(f"cannot parse {scheme_to_string(scheme)} payload into {msg_type.__qualname__}")


def message_class(full_name: str) -> type[pb_message.Message] | None:
    """The generated class for a protobuf full name, if it has been imported in this process."""
    try:
        descriptor = descriptor_pool.Default().FindMessageTypeByName(full_name)
    except KeyError:
        return None
    return message_factory.GetMessageClass(descriptor)


def parse_dynamic(data: bytes, scheme: int, name: str, dccl: DcclCodec | None = None) -> Any:
    """Decode a payload whose type is known only by name (regex subscriptions).

    Returns ``str`` for CSTR, the protobuf message when its type is known in this process (for DCCL, also given a
    codec), else the raw bytes.
    """
    if scheme == Scheme.CSTR:
        return parse(data, scheme, str)
    if scheme == Scheme.PROTOBUF or (scheme == Scheme.DCCL and dccl is not None):
        cls = message_class(name)
        if cls is not None:
            return parse(data, scheme, cls, dccl)
    return data
