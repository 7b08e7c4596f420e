"""Goby3's log format (version 3), the byte layout only: pure functions of bytes (as Goby3's
``src/middleware/log/log_entry.{h,cpp}``).

A log is a 4-byte big-endian version number followed by entries::

    [GBY3][size: 4][scheme: 2][group index: 2][type index: 2][timestamp: 8][data][crc32: 4]

``size`` counts everything after itself (scheme to CRC); the timestamp (µs since the epoch) exists from version
3 on; the CRC-32 (boost's ``crc_32_type``, the same polynomial as zlib's) covers the magic word up to the data.
Integers are big-endian.  Scheme 0xFFFF declares a group index and 0xFFFE a type index: their data is the
2-byte scheme the name belongs to followed by the name (version 1 had the name only, one mapping for all schemes).
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass

MAGIC = b"GBY3"
CURRENT_VERSION = 3
#: Version features (log_entry.cpp ``VersionFeatures``).
VERSION_ADD_VERSION_NUMBER = 2
VERSION_ADD_SCHEME_TO_GROUP_TYPE_MAPPING = 2
VERSION_ADD_TIMESTAMP = 3

SCHEME_GROUP_INDEX = 0xFFFF
SCHEME_TYPE_INDEX = 0xFFFE
#: The scheme index entries of version 1 map names under (Goby's ``NULL_SCHEME``).
LEGACY_SCHEME = -1
MAX_INDEX = 0xFFFF  # group and type indexes are 16-bit; Goby starts both counters at 1

VERSION = struct.Struct(">I")
HEADER = struct.Struct(">4sIHHHQ")  # magic, size, scheme, group index, type index, timestamp
HEADER_V2 = struct.Struct(">4sIHHH")  # versions 1 and 2: no timestamp
CRC = struct.Struct(">I")
SCHEME_PREFIX = struct.Struct(">H")


def fixed_size(version: int) -> int:
    """The smallest ``size`` an entry of ``version`` can have (no data)."""
    return 2 + 2 + 2 + 4 + (8 if version >= VERSION_ADD_TIMESTAMP else 0)


def version_header(version: int = CURRENT_VERSION) -> bytes:
    """The 4 bytes a log starts with (none for version 1)."""
    return VERSION.pack(version) if version >= VERSION_ADD_VERSION_NUMBER else b""


def encode_record(scheme: int, group_index: int, type_index: int, timestamp_micro: int, data: bytes,
                  version: int = CURRENT_VERSION) -> bytes:
    """One entry's bytes, exactly as ``LogEntry::_serialize`` writes them."""
    if version >= VERSION_ADD_TIMESTAMP:
        head = HEADER.pack(MAGIC, HEADER.size - 8 + len(data) + CRC.size, scheme, group_index, type_index,
                           timestamp_micro & 0xFFFF_FFFF_FFFF_FFFF)
    else:
        head = HEADER_V2.pack(MAGIC, HEADER_V2.size - 8 + len(data) + CRC.size, scheme, group_index, type_index)
    return b"".join((head, data, CRC.pack(zlib.crc32(data, zlib.crc32(head)))))


def index_data(scheme: int, name: str, version: int = CURRENT_VERSION) -> bytes:
    """The data of a group or type index entry: the 2-byte scheme, then the name."""
    raw = name.encode("utf-8", "surrogateescape")
    if version < VERSION_ADD_SCHEME_TO_GROUP_TYPE_MAPPING:
        return raw
    return SCHEME_PREFIX.pack(scheme & 0xFFFF) + raw


@dataclass(slots=True)
class LogEntry:
    """One data entry of a log, with its names resolved; ``offset`` is where its ``GBY3`` starts in the file.

    Not frozen: a reader makes one per entry, and a frozen dataclass costs several times as much to construct.
    """

    scheme: int
    group: str
    type_name: str
    timestamp_micro: int
    data: bytes
    offset: int = -1


@dataclass(frozen=True, slots=True)
class SkippedSpan:
    """Bytes of a log the reader could not use: ``length`` bytes from ``offset``, and why."""

    offset: int
    length: int
    reason: str

    def __str__(self) -> str:
        return f"skipped {self.length} byte(s) at offset {self.offset}: {self.reason}"
