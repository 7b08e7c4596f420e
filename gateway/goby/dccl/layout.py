"""A message type's DCCL layout: which fields go in the head and which in the body, in what order, with which
codec, and how many bits each can take. Built once at ``load``, where every check DCCL makes is made.

Rules (DCCL's ``DefaultMessageCodec`` v3 and ``MessageStack``): fields in declaration order; ``omit`` fields
never sent; a field is in the head if ``in_head``, except inside an embedded message whose field says
``in_head`` explicitly (true or false), where all of it follows that field; required fields, and elements of
repeated ones, have no "not present" value; an optional embedded message has a presence bit.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from google.protobuf import message_factory
from google.protobuf.descriptor import Descriptor, FieldDescriptor

from gateway.goby.dccl import arith
from gateway.goby.dccl.errors import DefinitionError
from gateway.goby.dccl.field_codec import CodecBase, FieldContext, InlineCodec
from gateway.goby.dccl.registry import CodecRegistry, MessageCodec
from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as dccl_options
from util.descriptors import message_type_of

HEAD, BODY = "head", "body"
SUPPORTED_VERSION = 3


def message_options(descriptor: Descriptor) -> dccl_options.DCCLMessageOptions:
    """The ``(dccl.msg)`` options of a message type (empty if it has none)."""
    return descriptor.GetOptions().Extensions[dccl_options.msg]


def field_options(descriptor: FieldDescriptor) -> dccl_options.DCCLFieldOptions:
    """The ``(dccl.field)`` options of a field (empty if it has none)."""
    return descriptor.GetOptions().Extensions[dccl_options.field]


@dataclass
class FieldLayout:
    """One field of one part: its codec (or its embedded fields) and sizes in bits."""

    descriptor: FieldDescriptor
    context: FieldContext
    codec_name: str
    codec: CodecBase | None  # None for an embedded message
    children: list[FieldLayout] = field(default_factory=list)
    message_class: Any = None  # embedded message class
    repeated: bool = False
    min_repeat: int = 0
    max_repeat: int = 0
    element_min: int = 0
    element_max: int = 0

    @property
    def name(self) -> str:
        return self.descriptor.name

    @property
    def is_message(self) -> bool:
        return self.codec is None

    @property
    def presence_bit(self) -> bool:
        """An optional (not repeated, not required) embedded message."""
        return self.is_message and not self.repeated and not self.context.required

    @property
    def prefix_bits(self) -> int:
        return arith.ceil_log2(self.max_repeat - self.min_repeat + 1) if self.repeated else 0

    @property
    def min_size(self) -> int:
        if self.repeated:
            return self.prefix_bits + self.min_repeat * self.element_min
        return 1 if self.presence_bit else self.element_min

    @property
    def max_size(self) -> int:
        if self.repeated:
            return self.prefix_bits + self.max_repeat * self.element_max
        return self.element_max + (1 if self.presence_bit else 0)

    @property
    def empty_size(self) -> int:
        """Zero bits of one missing element (padding up to ``min_repeat``)."""
        if self.codec is not None:
            return self.codec.empty_size
        return self.element_min

    @property
    def variable(self) -> bool:
        """Whether the compiled code moves the bit position by a run-time amount for this field."""
        if self.repeated or self.presence_bit:
            return True
        if self.codec is None:
            return any(child.variable for child in self.children)
        return not isinstance(self.codec, InlineCodec) or self.codec.variable


class LayoutBuilder:
    """Builds and checks the head and body layouts of one root message type."""

    def __init__(self, root: Descriptor, registry: CodecRegistry, strict: bool) -> None:
        self.root = root
        self.registry = registry
        self.strict = strict
        options = message_options(root)
        self.codec_version = options.codec_version
        self.group = options.codec_group if options.HasField("codec_group") else f"dccl.default{self.codec_version}"

    def fail(self, reason: str, path: str | None = None) -> DefinitionError:
        return DefinitionError(self.root.full_name, path, reason)

    def build(self) -> tuple[list[FieldLayout], list[FieldLayout]]:
        """(head fields, body fields) after checking the root's own codec."""
        options = message_options(self.root)
        name = options.codec if options.HasField("codec") else self.group
        try:
            found, codec = self.registry.find(FieldDescriptor.TYPE_MESSAGE, name, self.codec_version,
                                              self.root.full_name)
        except LookupError as exc:
            raise self.fail(str(exc)) from None
        if not isinstance(codec, MessageCodec):
            raise self.fail(f"codec `{found}` for the whole message is not supported here (only DCCL's default "
                            "message codec)")
        stack = [self.root.full_name]
        return self.part(self.root, HEAD, None, "", stack), self.part(self.root, BODY, None, "", stack)

    def part(self, desc: Descriptor, part: str, inherited: str | None, prefix: str,
             stack: list[str]) -> list[FieldLayout]:
        """The fields of ``desc`` that go in ``part`` (``inherited``: the part an embedding field fixed)."""
        if desc.oneofs:
            raise self.fail(f"DCCL Codec Version {self.codec_version} does not support 'oneof' declarations",
                            prefix.rstrip(".") or None)
        out = []
        for fd in desc.fields:
            options = field_options(fd)
            if options.omit:
                continue
            in_part = (inherited == part) if inherited else (options.in_head == (part == HEAD))
            if in_part:
                out.append(self.field(fd, options, part, inherited, prefix + fd.name, stack))
        return out

    def field(self, fd: FieldDescriptor, options: dccl_options.DCCLFieldOptions, part: str,
              inherited: str | None, path: str, stack: list[str]) -> FieldLayout:
        if options.HasField("dynamic_conditions"):
            raise self.fail("(dccl.field).dynamic_conditions (DCCL4) are not supported", path)
        repeated = fd.is_repeated
        sub = message_type_of(fd) if fd.type == FieldDescriptor.TYPE_MESSAGE else None
        context = FieldContext(
            descriptor=fd, options=options, message=self.root.full_name, path=path,
            codec_version=self.codec_version, required=fd.is_required or repeated,
            strict=self.strict,
        )
        if options.HasField("codec"):
            name = options.codec
        elif sub is not None and message_options(sub).HasField("codec"):
            name = message_options(sub).codec
        else:
            name = self.group
        try:
            found, factory = self.registry.find(fd.type, name, self.codec_version,
                                                sub.full_name if sub is not None else "")
        except LookupError as exc:
            raise self.fail(str(exc), path) from None
        layout = FieldLayout(fd, context, found, None, repeated=repeated)
        if repeated:
            self.check_repeat(options, path)
            layout.min_repeat, layout.max_repeat = options.min_repeat, options.max_repeat
        if isinstance(factory, MessageCodec):
            if sub is None:
                raise self.fail(f"codec `{found}` is for messages", path)
            if sub.full_name in stack:
                raise self.fail(f"{sub.full_name} contains itself: a recursive message has no maximum size", path)
            child_part = (HEAD if options.in_head else BODY) if options.HasField("in_head") else inherited
            layout.children = self.part(sub, part, child_part, path + ".", [*stack, sub.full_name])
            layout.message_class = message_factory.GetMessageClass(sub)
            layout.element_min = sum(c.min_size for c in layout.children)
            layout.element_max = sum(c.max_size for c in layout.children)
        else:
            codec = factory(context)
            if not isinstance(codec, CodecBase):
                raise self.fail(f"codec `{found}` did not build a field codec", path)
            codec.name = found
            codec.validate()
            layout.codec = codec
            layout.element_min, layout.element_max = codec.min_size, codec.max_size
        if options.in_head and layout.min_size != layout.max_size:
            raise self.fail("Variable size codec used in header - header fields must be encoded with fixed "
                            "size codec.", path)
        return layout

    def check_repeat(self, options: dccl_options.DCCLFieldOptions, path: str) -> None:
        if not options.HasField("max_repeat"):
            raise self.fail("Missing (dccl.field).max_repeat option on `repeated` field", path)
        if options.max_repeat < 1:
            raise self.fail("(dccl.field).max_repeat must not be less than 1", path)
        if options.max_repeat < options.min_repeat:
            raise self.fail("(dccl.field).max_repeat must not be less than (dccl.field).min_repeat", path)


def check_message_options(root: Descriptor) -> dccl_options.DCCLMessageOptions:
    """DCCL's message-level checks at load (id, max_bytes, codec_version), with its wording."""
    options = message_options(root)
    name = root.full_name
    if not options.HasField("id") and not options.omit_id:
        raise DefinitionError(name, None, "Missing message option `(dccl.msg).id`. Specify a unique id (e.g. 3) "
                              "in the body of your .proto message using \"option (dccl.msg).id = 3\"")
    if not options.HasField("max_bytes"):
        raise DefinitionError(name, None, "Missing message option `(dccl.msg).max_bytes`. Specify a maximum "
                              "(encoded) message size in bytes (e.g. 32) in the body of your .proto message "
                              "using \"option (dccl.msg).max_bytes = 32\"")
    if not options.HasField("codec_version"):
        raise DefinitionError(name, None, f"No (dccl.msg).codec_version set for DCCL Message '{name}'. Set "
                              "'option (dccl.msg).codec_version = 3' in the message definition.")
    if options.codec_version != SUPPORTED_VERSION:
        raise DefinitionError(name, None, f"(dccl.msg).codec_version {options.codec_version} is not supported: "
                              f"this codec implements DCCL's version {SUPPORTED_VERSION} codecs")
    return options


def walk(fields: list[FieldLayout]) -> list[FieldLayout]:
    """Every field, embedded ones after their message field, depth first."""
    out = []
    for layout in fields:
        out.append(layout)
        out.extend(walk(layout.children))
    return out
