"""The prefixed techniques (5, 7, 8): ``@PB[full.Type.Name] `` before text format, hex or binary.

Why the prefix: a MOOS reader can tell which protobuf type a string holds without configuration
(``dynamic_parse``), and a typed reader can refuse the wrong type.
"""

from __future__ import annotations

from collections.abc import Callable

from google.protobuf import descriptor_pool as _descriptor_pool
from google.protobuf import message_factory
from google.protobuf.message import Message

from translators.techniques.errors import TechniqueError

MAGIC_PROTOBUF_HEADER = "@PB"

Parser = Callable[[str, Message], Message]


def prefix_for(msg: Message) -> str:
    """``@PB[<full name>] `` for ``msg``'s type (note the trailing space)."""
    return f"{MAGIC_PROTOBUF_HEADER}[{msg.DESCRIPTOR.full_name}] "


def split_prefix(value: str, technique_name: str) -> tuple[str, str] | None:
    """``(type name, body)`` if ``value`` carries the prefix, else None.

    As Goby: the name runs from index 4 to the first ``]``, and the body starts two characters after it.
    """
    header = MAGIC_PROTOBUF_HEADER
    if len(value) <= len(header) or not value.startswith(header):
        return None
    end = value.find("]")
    if end < 0:
        raise TechniqueError(f"Incorrectly formatted protobuf message passed to MOOSTranslation<{technique_name}>::parse.")
    return value[len(header) + 1 : end], value[end + 2 :]


def parse_prefixed(value: str, msg: Message, base_parse: Parser, technique_name: str) -> Message:
    """Parse a prefixed string into ``msg``; un-prefixed input is handed to ``base_parse`` as is (as Goby does).

    Raises TechniqueError if the prefix names another type than ``msg``'s.
    """
    split = split_prefix(value, technique_name)
    if split is None:
        return base_parse(value, msg)
    name, body = split
    expected = msg.DESCRIPTOR.full_name
    if name != expected:
        raise TechniqueError(
            f"Wrong Protobuf type passed to MOOSTranslation<{technique_name}>::parse. "
            f"Expected: {expected}, received: {name}"
        )
    if body:
        return base_parse(body, msg)
    msg.Clear()
    return msg


def new_message(name: str, pool: _descriptor_pool.DescriptorPool | None = None) -> Message:
    """A new, empty message of the named type from ``pool`` (default: the generated-code pool).

    Raises TechniqueError if the type is not known -- import its ``_pb2`` module first.
    """
    pool = pool or _descriptor_pool.Default()
    try:
        descriptor = pool.FindMessageTypeByName(name)
    except KeyError as exc:
        raise TechniqueError(f"Unknown Protobuf type: {name}; import its _pb2 module first") from exc
    return message_factory.GetMessageClass(descriptor)()
