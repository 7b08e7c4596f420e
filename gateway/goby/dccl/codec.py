"""The DCCL codec's API, shaped like the C++ ``dccl::Codec``: load message types, then encode and decode.

    codec = Codec()
    codec.load(NavigationReport)          # checks the definition as DCCL does; compiles it
    data = codec.encode(report)           # bytes, DCCL v3 wire format
    report = codec.decode(data)           # the type comes from the DCCL id

Thread safety: ``load`` takes a lock; encoding and decoding only read what ``load`` built, so any thread may
call them at once.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import TypeVar, overload

from google.protobuf.descriptor import Descriptor
from google.protobuf.message import Message

from gateway.goby.dccl import ids
from gateway.goby.dccl.bounds import FieldBounds, field_bounds
from gateway.goby.dccl.compiler import CompiledMessage, compile_message
from gateway.goby.dccl.errors import (
    DecodeError,
    DefinitionError,
    NotLoadedError,
    TrailingBytesError,
    UnknownIdError,
)
from gateway.goby.dccl.info import render_info
from gateway.goby.dccl.registry import CodecRegistry, default_registry
from util.descriptors import descriptor_of

MessageType = type[Message] | Descriptor
M = TypeVar("M", bound=Message)


def _descriptor(message_type: MessageType | Message) -> Descriptor:
    if isinstance(message_type, Descriptor):
        return message_type
    return descriptor_of(message_type)


class Codec:
    """Encodes and decodes the message types loaded into it.

    ``strict``: refuse out-of-range values and over-long strings/repeats (``OutOfRangeError``) instead of
    DCCL's default of sending them as "not present"/minimum/truncated. ``clock``: the receiver's wall clock
    for time fields (seconds since 1970; default ``time.time``, the real clock, as DCCL's).
    """

    def __init__(self, *, strict: bool = False, clock: Callable[[], float] | None = None,
                 registry: CodecRegistry | None = None) -> None:
        self.strict = strict
        self.clock = clock if clock is not None else time.time
        self.registry = registry if registry is not None else default_registry()
        self._by_id: dict[int, CompiledMessage] = {}
        self._by_class: dict[type, CompiledMessage] = {}
        self._by_name: dict[str, CompiledMessage] = {}
        self._other_strictness: dict[str, CompiledMessage] = {}
        self._lock = threading.Lock()

    # ------------------------------------------------------------------------------------------ loading
    def load(self, message_type: MessageType) -> CompiledMessage:
        """Check and compile a message type (once; loading it again is free). ``DefinitionError`` names the
        message and field DCCL would refuse, e.g. a missing bound or an encoding over ``max_bytes``."""
        desc = _descriptor(message_type)
        compiled = self._by_name.get(desc.full_name)
        if compiled is not None and compiled.descriptor is desc:
            return compiled
        with self._lock:
            compiled = compile_message(desc, self.registry, self.strict)
            if compiled.dccl_id is not None:
                other = self._by_id.get(compiled.dccl_id)
                if other is not None and other.name != compiled.name:
                    raise DefinitionError(desc.full_name, None, f"`dccl id` {compiled.dccl_id} is already in use "
                                          f"by Message {other.name}")
                self._by_id[compiled.dccl_id] = compiled
            self._by_class[compiled.message_class] = compiled
            self._by_name[desc.full_name] = compiled
            self._other_strictness.pop(desc.full_name, None)
            return compiled

    def unload(self, message_type: MessageType) -> None:
        """Forget a message type (its id can then be used by another)."""
        with self._lock:
            compiled = self._by_name.pop(_descriptor(message_type).full_name, None)
            if compiled is None:
                return
            self._by_class.pop(compiled.message_class, None)
            if compiled.dccl_id is not None:
                self._by_id.pop(compiled.dccl_id, None)

    def loaded(self) -> list[CompiledMessage]:
        """Every loaded message type, by DCCL id."""
        return sorted(self._by_name.values(), key=lambda c: (c.dccl_id is None, c.dccl_id or 0, c.name))

    def compiled(self, message_type: MessageType | Message) -> CompiledMessage:
        """The loaded form of a type (layout, sizes, generated ``source``); ``NotLoadedError`` if not loaded."""
        name = _descriptor(message_type).full_name
        compiled = self._by_name.get(name)
        if compiled is None:
            raise NotLoadedError(f"Message {name} has not been loaded. Call load() before using this type.")
        return compiled

    # ----------------------------------------------------------------------------------------- encoding
    def encode(self, msg: Message, *, strict: bool | None = None) -> bytes:
        """The DCCL bytes of ``msg`` (head then body). ``strict`` overrides the codec's setting for this call."""
        compiled = self._by_class.get(type(msg))
        if compiled is None:
            compiled = self.compiled(msg)
        if strict is not None and strict != self.strict:
            compiled = self._with_strictness(compiled)
        return compiled.encode(msg)

    def _with_strictness(self, compiled: CompiledMessage) -> CompiledMessage:
        other = self._other_strictness.get(compiled.name)
        if other is None:
            with self._lock:
                other = compile_message(compiled.descriptor, self.registry, not self.strict)
                self._other_strictness[compiled.name] = other
        return other

    def size(self, msg: Message) -> int:
        """Bytes ``encode(msg)`` gives."""
        return len(self.encode(msg))

    def max_size(self, message_type: MessageType) -> int:
        """Largest encoding in bytes, counting the id as its largest form (2 bytes), as DCCL's ``max_size``."""
        compiled = self.compiled(message_type)
        return compiled.byte_size(0 if compiled.dccl_id is None else ids.ID_MAX_BITS, compiled.body_max_bits)

    def min_size(self, message_type: MessageType) -> int:
        """Smallest encoding in bytes, counting the id as its smallest form (1 byte), as DCCL's ``min_size``."""
        compiled = self.compiled(message_type)
        return compiled.byte_size(0 if compiled.dccl_id is None else ids.ID_MIN_BITS, compiled.body_min_bits)

    def id(self, message_type: MessageType) -> int | None:
        """The DCCL id of a loaded type (``None`` with ``omit_id``)."""
        return self.compiled(message_type).dccl_id

    @staticmethod
    def id_from_encoded(data: bytes) -> int:
        """The DCCL id at the start of ``data`` (``TruncatedError`` if there are not enough bytes)."""
        return ids.decode_id(data)[0]

    # ----------------------------------------------------------------------------------------- decoding
    @overload
    def decode(self, data: bytes, message_type: type[M], *, now: float | None = None) -> M: ...

    @overload
    def decode(self, data: bytes, message_type: Descriptor | None = None, *, now: float | None = None) -> Message: ...

    def decode(self, data: bytes, message_type: MessageType | None = None, *, now: float | None = None) -> Message:
        """The one message in ``data``; trailing bytes are an error (``decode_prefix`` allows them).

        ``message_type`` is needed only for ``omit_id`` messages (otherwise it must match the id).
        ``now`` overrides the clock for time fields (seconds since 1970).
        """
        msg, end = self._decode_at(data, 0, message_type, now)
        if end != len(data):
            raise TrailingBytesError(msg.DESCRIPTOR.full_name, end, len(data))
        return msg

    def decode_prefix(self, data: bytes, message_type: MessageType | None = None, *,
                      now: float | None = None) -> tuple[Message, bytes]:
        """The first message in ``data`` and the bytes after it (DCCL's ``decode(std::string*)``)."""
        msg, end = self._decode_at(data, 0, message_type, now)
        return msg, bytes(data[end:])

    def decode_all(self, data: bytes, *, now: float | None = None) -> list[Message]:
        """Every message of several packed back to back (a modem frame), each found by its id."""
        out: list[Message] = []
        start = 0
        while start < len(data):
            try:
                msg, start = self._decode_at(data, start, None, now)
            except DecodeError as exc:
                exc.add_note(f"(message {len(out) + 1} of the packed data, at byte {start})")
                raise
            out.append(msg)
        return out

    def _decode_at(self, data: bytes, start: int, message_type: MessageType | None,
                   now: float | None) -> tuple[Message, int]:
        if message_type is None:
            dccl_id = ids.decode_id(data, start)[0]
            compiled = self._by_id.get(dccl_id)
            if compiled is None:
                raise UnknownIdError(dccl_id)
        else:
            compiled = self.compiled(message_type)
            if compiled.dccl_id is not None:
                received = ids.decode_id(data, start)[0]
                if received != compiled.dccl_id:
                    raise DecodeError(f"Received message with id {received} but decode was called with "
                                      f"{compiled.name} (id {compiled.dccl_id})")
        if compiled.needs_clock:
            clock_now = int(self.clock() if now is None else now)
        else:
            clock_now = 0
        return compiled.decode(data, start, clock_now)

    # ---------------------------------------------------------------------------------- introspection
    def bounds(self, message_type: MessageType) -> list[FieldBounds]:
        """Each field's bounds, step, enum values and limits, for building forms (head fields first)."""
        compiled = self.compiled(message_type)
        return [field_bounds(f, part) for part, fields in (("head", compiled.head), ("body", compiled.body))
                for f in fields]

    def info(self, message_type: MessageType) -> str:
        """The field-by-field size report of DCCL's ``Codec::info`` (``dccl --analyze``)."""
        return render_info(self.compiled(message_type))

    def source(self, message_type: MessageType) -> str:
        """The generated Python of a loaded type's encode and decode functions."""
        return self.compiled(message_type).source
