"""A log's entries as MCAP (https://mcap.dev), so a ``.goby`` log opens in Foxglove and any MCAP reader.

Written with the ``mcap`` library (the ``log`` extra; imported when an export starts):

- every protobuf type is a schema: name = the full type name, encoding ``protobuf``, data = a serialized
  ``FileDescriptorSet`` holding the type's file and every file it imports (imports first), as Foxglove wants;
- every (Goby group, scheme, type) is a channel: topic = the Goby group, metadata ``goby.scheme`` and
  ``goby.type``; PROTOBUF entries go in as they are (``message_encoding`` ``protobuf``), DCCL entries are decoded
  and each of their messages re-serialized as protobuf (same schema, ``goby.scheme`` = ``DCCL``);
- CSTR entries are ``json`` messages ``{"value": "<the text>"}`` under the JSON Schema ``goby.CSTR``; JSON
  entries (BSON in the log) are ``json`` messages under a ``jsonschema`` schema named after their type
  (``nlohmann::json``) that allows any object;
- an entry nobody can decode (a protobuf type with no descriptor in the log or this process, bytes the DCCL codec
  or BSON decoder refuse) is kept: its bytes go on a channel of its own with ``message_encoding``
  ``application/octet-stream`` and no schema, and one warning names its type;
- log time and publish time are the entry's timestamp in nanoseconds; ``sequence`` counts per channel.

Chunks are zstd-compressed when ``zstandard`` is installed (as the mcap library prefers), else lz4, else
uncompressed. A metadata record ``goby_log`` carries the input file's name and format version.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import IO, TYPE_CHECKING, Any, cast

from google.protobuf import descriptor_pb2
from google.protobuf.descriptor import Descriptor, FileDescriptor

from gateway.goby.log.entry import LogEntry
from gateway.goby.log.errors import import_optional
from gateway.goby.log.render import EntryDecoder, scheme_name
from gateway.goby.portal.marshalling import Scheme

if TYPE_CHECKING:
    from mcap.writer import Writer

log = logging.getLogger(__name__)

BYTES_ENCODING = "application/octet-stream"
CSTR_SCHEMA_NAME = "goby.CSTR"
CSTR_SCHEMA = {"title": "goby CSTR", "description": "a CSTR (text) publication of a Goby group", "type": "object",
               "properties": {"value": {"type": "string"}}, "required": ["value"]}
JSON_SCHEMA = {"description": "a JSON (BSON in the .goby log) publication of a Goby group", "type": "object"}
LIBRARY = "gateway goby-log-tool"


def import_mcap_writer() -> Any:
    """``mcap.writer``, or ``ExportUnavailable`` saying how to install it."""
    return import_optional("mcap.writer", "MCAP")


def file_descriptor_set(desc: Descriptor) -> bytes:
    """A ``FileDescriptorSet`` of ``desc``'s file and all its imports, each after its own imports."""
    files: list[FileDescriptor] = []
    seen: set[str] = set()

    def visit(file: FileDescriptor) -> None:
        if file.name in seen:
            return
        seen.add(file.name)
        for dependency in file.dependencies:
            visit(dependency)
        files.append(file)

    visit(desc.file)
    out = descriptor_pb2.FileDescriptorSet()
    for file in files:
        file.CopyToProto(out.file.add())
    return out.SerializeToString()


@dataclass
class McapStats:
    """What an export wrote: MCAP messages, and the entries kept as bytes per type."""

    messages: int = 0
    kept_as_bytes: dict[str, int] = field(default_factory=dict)


class McapExporter:
    """Write entries to an MCAP stream: :meth:`add` each, then :meth:`finish`."""

    def __init__(self, stream: IO[bytes], decoder: EntryDecoder, *, metadata: dict[str, str] | None = None,
                 chunk_size: int = 4 * 1024 * 1024) -> None:
        mcap_writer = import_mcap_writer()
        self._decoder = decoder
        self._pool = decoder.pool
        self._writer: Writer = mcap_writer.Writer(stream, chunk_size=chunk_size,
                                                  compression=_best_compression(mcap_writer))
        self._writer.start(profile="", library=LIBRARY)
        if metadata:
            self._writer.add_metadata("goby_log", metadata)
        self._schemas: dict[str, int] = {}
        # (scheme, group, type) -> (channel id, how to write: "raw", "dccl", "cstr", "json", "bytes")
        self._channels: dict[tuple[int, str, str], tuple[int, str]] = {}
        self._bytes_channels: dict[tuple[int, str, str], int] = {}
        self._sequence: dict[int, int] = {}
        self.stats = McapStats()

    # ------------------------------------------------------------------------------------------ schemas
    def _protobuf_schema(self, type_name: str) -> int | None:
        sid = self._schemas.get(type_name)
        if sid is None:
            cls = self._pool.message_class(type_name)
            if cls is None:
                return None
            sid = self._writer.register_schema(type_name, "protobuf", file_descriptor_set(cast(Descriptor,
                                                                                               cls.DESCRIPTOR)))
            self._schemas[type_name] = sid
        return sid

    def _json_schema(self, name: str, schema: dict[str, Any]) -> int:
        key = "jsonschema:" + name
        sid = self._schemas.get(key)
        if sid is None:
            sid = self._writer.register_schema(name, "jsonschema", json.dumps(schema).encode())
            self._schemas[key] = sid
        return sid

    def _channel(self, entry: LogEntry) -> tuple[int, str]:
        key = (entry.scheme, entry.group, entry.type_name)
        found = self._channels.get(key)
        if found is not None:
            return found
        scheme, type_name = entry.scheme, entry.type_name
        meta = {"goby.scheme": scheme_name(scheme), "goby.type": type_name}
        if scheme in (Scheme.PROTOBUF, Scheme.DCCL):
            sid = self._protobuf_schema(type_name)
            if sid is None:
                found = (-1, "bytes")
            else:
                cid = self._writer.register_channel(entry.group, "protobuf", sid, meta)
                found = (cid, "raw" if scheme == Scheme.PROTOBUF else "dccl")
        elif scheme == Scheme.CSTR:
            cid = self._writer.register_channel(entry.group, "json", self._json_schema(CSTR_SCHEMA_NAME, CSTR_SCHEMA),
                                                meta)
            found = (cid, "cstr")
        elif scheme == Scheme.JSON:
            cid = self._writer.register_channel(entry.group, "json", self._json_schema(type_name, JSON_SCHEMA), meta)
            found = (cid, "json")
        else:
            found = (-1, "bytes")
        self._channels[key] = found
        return found

    def _bytes_channel(self, entry: LogEntry, reason: str) -> int:
        key = (entry.scheme, entry.group, entry.type_name)
        cid = self._bytes_channels.get(key)
        if cid is None:
            meta = {"goby.scheme": scheme_name(entry.scheme), "goby.type": entry.type_name, "goby.undecoded": reason}
            cid = self._writer.register_channel(entry.group, BYTES_ENCODING, 0, meta)
            self._bytes_channels[key] = cid
        if entry.type_name not in self.stats.kept_as_bytes:
            log.warning("MCAP: entries of type %s (scheme %s) on %s kept as bytes (%s): %s", entry.type_name,
                        scheme_name(entry.scheme), entry.group, BYTES_ENCODING, reason)
        self.stats.kept_as_bytes[entry.type_name] = self.stats.kept_as_bytes.get(entry.type_name, 0) + 1
        return cid

    # ----------------------------------------------------------------------------------------- messages
    def _put(self, cid: int, ns: int, data: bytes) -> None:
        seq = self._sequence.get(cid, 0)
        self._sequence[cid] = seq + 1
        self._writer.add_message(cid, ns, data, ns, seq)
        self.stats.messages += 1

    def add(self, entry: LogEntry) -> None:
        cid, how = self._channel(entry)
        ns = entry.timestamp_micro * 1000
        if how == "raw":
            seq = self._sequence.get(cid, 0)
            self._sequence[cid] = seq + 1
            self._writer.add_message(cid, ns, entry.data, ns, seq)
            self.stats.messages += 1
            return
        if how == "bytes":
            why = ("no descriptor for this type in the log or this process" if entry.scheme in
                   (Scheme.PROTOBUF, Scheme.DCCL) else f"no MCAP form for scheme {entry.scheme}")
            self._put(self._bytes_channel(entry, why), ns, entry.data)
            return
        value = self._decoder.decode(entry)
        if value.error is not None:
            self._put(self._bytes_channel(entry, value.error), ns, entry.data)
        elif how == "dccl":
            for msg in value.messages:
                self._put(cid, ns, msg.SerializeToString())
        elif how == "cstr":
            self._put(cid, ns, json.dumps({"value": value.text}, ensure_ascii=False).encode())
        else:
            body = value.json if isinstance(value.json, dict) else {"value": value.json}
            self._put(cid, ns, json.dumps(body, ensure_ascii=False, default=str).encode())

    def add_all(self, entries: Iterable[LogEntry]) -> int:
        n = 0
        for entry in entries:
            self.add(entry)
            n += 1
        return n

    def finish(self) -> McapStats:
        self._writer.finish()
        return self.stats


def _best_compression(mcap_writer: Any) -> Any:
    types = mcap_writer.CompressionType
    for name, module in (("ZSTD", "zstandard"), ("LZ4", "lz4.frame")):
        try:
            __import__(module)
        except ImportError:
            continue
        return getattr(types, name)
    return types.NONE
