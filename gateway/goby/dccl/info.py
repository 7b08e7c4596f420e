"""The size report of DCCL's ``Codec::info`` (what ``dccl --analyze`` prints), from a compiled layout.

Same layout and numbers as the C++ tool; DCCL's hash of the definition (``{0x...}`` after the name) is not
computed here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gateway.goby.dccl import arith
from gateway.goby.dccl.layout import FieldLayout

if TYPE_CHECKING:
    from gateway.goby.dccl.compiler import CompiledMessage

CONSOLE_WIDTH = 60
NAME_WIDTH = 40
INDENT = 8


def _guard(text: str, char: str) -> str:
    return char * ((CONSOLE_WIDTH - len(text)) // 2) if len(text) < CONSOLE_WIDTH else ""


def _dotted(label: str, value: object, width: int) -> str:
    return label + str(value).rjust(max(1, width), ".")


def _size_text(min_bits: int, max_bits: int) -> str:
    return str(max_bits) if min_bits == max_bits else f"{min_bits}-{max_bits}"


def _field_lines(layout: FieldLayout, depth: int) -> list[str]:
    fd = layout.descriptor
    name = f"{fd.number}. {fd.name}"
    if layout.repeated:
        low = f"{layout.min_repeat}-" if layout.context.options.HasField("min_repeat") else ""
        name += f"[{low}{layout.max_repeat}]"
    lines = []
    if layout.max_size:
        lines.append(" " * (INDENT * depth) + _dotted(name, _size_text(layout.min_size, layout.max_size),
                                                      NAME_WIDTH - len(name)) + f" {{{layout.codec_name}}}")
    for child in layout.children:
        lines.extend(_field_lines(child, depth + 1))
    return lines


def _part_lines(compiled: CompiledMessage, fields: list[FieldLayout]) -> list[str]:
    low, high = sum(f.min_size for f in fields), sum(f.max_size for f in fields)
    lines = []
    if high:
        name = compiled.name
        lines.append(_dotted(name, _size_text(low, high), NAME_WIDTH - len(name) + INDENT) + " {dccl.default3}")
    for layout in fields:
        lines.extend(_field_lines(layout, 1))
    return lines


def render_info(compiled: CompiledMessage) -> str:
    """The report for one loaded message type."""
    head_bits, body_bits, id_bits = compiled.head_bits, compiled.body_max_bits, compiled.id_bits
    bit_size = id_bits + head_bits + body_bits
    byte_size = arith.bits2bytes(id_bits + head_bits) + arith.bits2bytes(body_bits)
    title = (f"{compiled.dccl_id}: " if compiled.dccl_id is not None else "") + compiled.name
    guard = _guard(title, "=")
    pad = " " * INDENT
    lines = [
        f"{guard} {title} {guard}",
        f"Actual maximum size of message: {byte_size} bytes / {byte_size * 8} bits",
        pad + _dotted("dccl.id head", id_bits, NAME_WIDTH - len("dccl.id head")),
        pad + _dotted("user head", head_bits, NAME_WIDTH - len("user head")),
        pad + _dotted("body", body_bits, NAME_WIDTH - len("body")),
        pad + _dotted("padding to full byte", byte_size * 8 - bit_size, NAME_WIDTH - len("padding to full byte")),
        f"Allowed maximum size of message: {compiled.max_bytes} bytes / {compiled.max_bytes * 8} bits",
    ]
    header_guard = _guard("Header", "-")
    lines.append(f"{header_guard} Header {header_guard}")
    id_codec = "omit_id: true" if compiled.dccl_id is None else "dccl.default.id"
    lines.append(_dotted("dccl.id head", id_bits, NAME_WIDTH - len("dccl.id head") + INDENT) + f" {{{id_codec}}}")
    lines.extend(_part_lines(compiled, compiled.head))
    body_guard = _guard("Body", "-")
    lines.append(f"{body_guard} Body {body_guard}")
    lines.extend(_part_lines(compiled, compiled.body))
    return "\n".join(lines) + "\n"
