"""Entries as values, DEBUG_TEXT lines and JSON objects (goby_log_tool's formats).

``EntryDecoder`` turns an entry's bytes into what its scheme holds: protobuf messages (PROTOBUF, from this
process's types or the descriptors the log carries; DCCL, through the DCCL codec), text (CSTR, without its NUL),
a JSON object (JSON: BSON bytes).  A type nobody describes, or bytes that do not parse, stay bytes; the first
entry of each such type is warned about by name.
"""

from __future__ import annotations

import base64
import json
import logging
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from google.protobuf import json_format
from google.protobuf import message as pb_message

from gateway.goby.log import bson
from gateway.goby.log.descriptors import LogDescriptorPool
from gateway.goby.log.entry import LogEntry
from gateway.goby.log.text_format import short_debug_string
from gateway.goby.portal.marshalling import Scheme
from gateway.goby.portal.timeutil import time_str

if TYPE_CHECKING:
    from gateway.goby.dccl import Codec

log = logging.getLogger(__name__)


@dataclass(slots=True)
class Decoded:
    """What an entry holds: ``messages`` (PROTOBUF/DCCL), ``text`` (CSTR), ``json`` (JSON), else ``error``."""

    messages: list[pb_message.Message] = field(default_factory=list)
    text: str | None = None
    json: Any = None
    error: str | None = None


class EntryDecoder:
    """Decode entries of one log (its descriptors in ``pool``); counts the entries it could not decode."""

    def __init__(self, pool: LogDescriptorPool) -> None:
        self._pool = pool
        self._codec: Codec | None = None
        self.warned: set[tuple[int, str]] = set()
        self.undecoded = 0
        self._protobuf: dict[str, type[pb_message.Message]] = {}  # PROTOBUF types that decoded: the fast path

    @property
    def pool(self) -> LogDescriptorPool:
        """The descriptors of the log being decoded."""
        return self._pool

    def _dccl(self) -> Codec:
        if self._codec is None:
            from gateway.goby.dccl import Codec

            self._codec = Codec()
        return self._codec

    def decode(self, entry: LogEntry) -> Decoded:
        if entry.scheme == Scheme.PROTOBUF:
            cls = self._protobuf.get(entry.type_name)
            if cls is not None:
                try:
                    return Decoded([cls.FromString(entry.data)])
                except Exception:  # noqa: BLE001, S110 - the full path below reports it
                    pass
        try:
            out = self._decode(entry)
        except Exception as exc:  # noqa: BLE001 - any failure of a codec on foreign bytes is reported, never raised
            out = Decoded(error=f"{type(exc).__name__}: {exc}")
        if out.error is not None:
            self.undecoded += 1
            key = (entry.scheme, entry.type_name)
            if key not in self.warned:
                self.warned.add(key)
                log.warning("entries of type %s (scheme %d) kept as bytes: %s", entry.type_name, entry.scheme,
                            out.error)
        return out

    def _decode(self, entry: LogEntry) -> Decoded:
        scheme = entry.scheme
        if scheme == Scheme.CSTR:
            raw = entry.data[:-1] if entry.data.endswith(b"\0") else entry.data
            return Decoded(text=raw.decode("utf-8", "backslashreplace"))
        if scheme == Scheme.JSON:
            return Decoded(json=bson.decode(entry.data))
        if scheme in (Scheme.PROTOBUF, Scheme.DCCL):
            cls = self._pool.message_class(entry.type_name)
            if cls is None:
                return Decoded(error=f"Failed to create Protobuf message of type: {entry.type_name}, reason: "
                                     f"unknown type (no descriptor in the log or this process)")
            if scheme == Scheme.PROTOBUF:
                msg = cls.FromString(entry.data)
                self._protobuf[entry.type_name] = cls
                return Decoded(messages=[msg])
            codec = self._dccl()
            codec.load(cls)
            return Decoded(messages=codec.decode_all(entry.data))
        return Decoded(error=f"No plugin available for scheme: {scheme}")


def scheme_name(scheme: int) -> str:
    """``PROTOBUF``, ``DCCL``...: a scheme's name, or its number when Goby does not define it."""
    try:
        return Scheme(scheme).name
    except ValueError:
        return str(scheme)


def _one_line(text: str) -> str:
    return text.replace("\\", "\\\\").replace("\n", "\\n").replace("\r", "\\r")


def debug_text_line(entry: LogEntry, value: Decoded) -> str:
    """goby_log_tool's DEBUG_TEXT line: ``scheme | group | type | time | value``."""
    if value.error is not None:
        body = f"Unable to parse message of {len(entry.data)} bytes. Reason: {value.error}"
    elif value.text is not None:
        body = _one_line(value.text)
    elif value.json is not None:
        body = json_dump(value.json)
    else:
        msgs = value.messages
        body = "".join((f"[{i}]" if len(msgs) > 1 else "") + short_debug_string(m) for i, m in enumerate(msgs))
    return f"{entry.scheme} | {entry.group} | {entry.type_name} | {time_str(entry.timestamp_micro)} | {body}"


def json_dump(obj: Any) -> str:
    """``nlohmann::json::dump()``: compact, keys sorted, UTF-8 kept."""
    return json.dumps(obj, separators=(",", ":"), sort_keys=True, ensure_ascii=False, allow_nan=False,
                      default=str)


def json_objects(entry: LogEntry, value: Decoded) -> list[dict[str, Any]]:
    """goby_log_tool's JSON objects for an entry (one per message; metadata in ``_scheme_``, ``_utime_``...)."""
    meta = {"_scheme_": entry.scheme, "_utime_": entry.timestamp_micro,
            "_strtime_": time_str(entry.timestamp_micro), "_group_": entry.group, "_type_": entry.type_name}
    if value.error is not None:
        return [{**meta, "_error_": "Could not parse message", "_reason_": value.error,
                 "_bytes_": base64.b64encode(entry.data).decode()}]
    if value.text is not None:
        return [{**meta, "_value_": value.text}]
    if value.json is not None:
        body = value.json if isinstance(value.json, dict) else {"_value_": value.json}
        return [{**body, **meta}]
    return [{**json_format.MessageToDict(m), **meta} for m in value.messages]
