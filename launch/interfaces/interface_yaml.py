"""Read and write interface YAML files in the schema goby_clang_tool emits (block style, Goby's key order).

We write the text ourselves rather than through PyYAML's dumper so the layout matches Goby's files
line for line (sequence indentation, key order, quoting of values with spaces); reading uses PyYAML.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from launch.errors import LaunchError
from launch.interfaces.model import LAYERS, ApplicationInterface, PubSubEntry, ThreadInfo
from launch.textfile import read_text


class InterfaceFileError(LaunchError, ValueError):
    """An interface YAML file that cannot be understood; the message names the file and the problem."""


def _scalar(value: str | bool) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    text = str(value)
    needs_quotes = " " in text or text == "" or text[0] in "&*!|>'\"%@`#{}[],?:-" or ": " in text
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"' if needs_quotes else text


def _entry_lines(entry: PubSubEntry, indent: str, with_thread: bool) -> list[str]:
    fields: list[tuple[str, str | bool]] = [("group", entry.group), ("scheme", entry.scheme), ("type", entry.type)]
    if entry.direction == "subscribes":
        fields.append(("necessity", entry.necessity))
    if with_thread:
        fields.append(("thread", entry.thread))
    if entry.inner:
        fields.append(("inner", True))
    if entry.is_regex:
        fields.append(("is_regex", True))
    lines = []
    for i, (key, value) in enumerate(fields):
        lead = indent + ("- " if i == 0 else "  ")
        lines.append(f"{lead}{key}: {_scalar(value)}")
    return lines


def _direction_lines(direction: str, entries: list[PubSubEntry], indent: str, with_thread: bool) -> list[str]:
    """``publishes:``/``subscribes:`` and its entries one level deeper, or ``[]`` when there are none."""
    if not entries:
        return [f"{indent}{direction}: []"]
    lines = [f"{indent}{direction}:"]
    for entry in entries:
        lines.extend(_entry_lines(entry, indent + "  ", with_thread))
    return lines


def dumps(interface: ApplicationInterface) -> str:
    """The interface as YAML text, layers outermost first, entries sorted as Goby sorts them."""
    lines = [f"application: {_scalar(interface.application)}"]
    for layer in interface.used_layers():
        lines.append(f"{layer}:")
        if layer != "interthread":
            for direction in ("publishes", "subscribes"):
                lines.extend(_direction_lines(direction, interface.layer_entries(layer, direction), "  ", True))
            continue
        lines.append("  threads:")
        for name in sorted(interface.threads):
            info = interface.threads[name]
            lines.append(f"    - name: {_scalar(info.name)}")
            lines.append(f"      known: {_scalar(info.known)}")
            if info.bases:
                lines.append("      bases:")
                lines.extend(f"        - {_scalar(base)}" for base in info.bases)
            for direction in ("publishes", "subscribes"):
                entries = [e for e in interface.layer_entries("interthread", direction) if e.thread == name]
                lines.extend(_direction_lines(direction, entries, "      ", False))
    return "\n".join(lines) + "\n"


def _entries_from(raw: object, layer: str, direction: str, thread: str | None, where: str) -> list[PubSubEntry]:
    if raw is None:
        return []
    if not isinstance(raw, list):
        raise InterfaceFileError(f"{where}: {layer}.{direction} must be a sequence")
    entries = []
    for item in raw:
        if not isinstance(item, dict) or not {"group", "scheme", "type"} <= item.keys():
            raise InterfaceFileError(f"{where}: each {layer}.{direction} entry needs group, scheme and type: {item!r}")
        entries.append(
            PubSubEntry(
                layer=layer,
                thread=str(item.get("thread", thread or "")),
                group=str(item["group"]),
                scheme=str(item["scheme"]),
                type=str(item["type"]),
                direction=direction,
                necessity=str(item.get("necessity", "optional")),
                inner=str(item.get("inner", "false")).lower() == "true",
                is_regex=str(item.get("is_regex", "false")).lower() == "true",
            )
        )
    return entries


def loads(text: str, where: str = "<string>") -> ApplicationInterface:
    """Parse interface YAML text; ``where`` names the source in error messages."""
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise InterfaceFileError(f"{where}: not valid YAML: {exc}") from exc
    if not isinstance(data, dict) or "application" not in data:
        raise InterfaceFileError(f"{where}: an interface file must be a mapping with an 'application' key")
    interface = ApplicationInterface(str(data["application"]))
    for layer in LAYERS:
        section = data.get(layer)
        if section is None:
            continue
        if not isinstance(section, dict):
            raise InterfaceFileError(f"{where}: '{layer}' must be a mapping")
        if layer == "interthread":
            for thread in section.get("threads") or []:
                name = str(thread["name"])
                interface.threads[name] = ThreadInfo(
                    name, str(thread.get("known", "true")).lower() == "true", [str(b) for b in thread.get("bases") or []]
                )
                for direction in ("publishes", "subscribes"):
                    interface.entries.update(_entries_from(thread.get(direction), layer, direction, name, where))
            continue
        for direction in ("publishes", "subscribes"):
            for entry in _entries_from(section.get(direction), layer, direction, None, where):
                interface.entries.add(entry)
                interface.threads.setdefault(entry.thread, ThreadInfo(entry.thread))
    return interface


def load(path: str | Path) -> ApplicationInterface:
    """Read an interface file."""
    path = Path(path)
    return loads(read_text(path, InterfaceFileError, "{path}: cannot read: {reason}"), str(path))
