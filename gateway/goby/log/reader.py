"""``LogReader``: the entries of a ``.goby`` log, resynchronising at the next ``GBY3`` after anything it cannot use.

Like Goby3's ``LogEntry::parse``: index entries (schemes 0xFFFF/0xFFFE) name groups and types and are not
yielded; protobuf descriptor entries feed :attr:`LogReader.descriptors` and are not yielded either (Goby's log
plugins consume them through a filter hook); a data entry whose index was never declared gets Goby's
``_unknown<N>_`` name.  Unlike Goby, a log of a newer version is refused (Goby reads it as its own version), and
every span of bytes that is not a whole valid entry is reported in :attr:`LogReader.skipped` with its offset: a
truncated entry, a CRC mismatch, bytes between entries, an entry of a scheme Goby does not define.

The file is memory-mapped: a corrupted size never allocates more than the file holds, and reading is slices.
"""

from __future__ import annotations

import logging
import mmap
import os
import zlib
from collections.abc import Callable, Iterator
from typing import Any

from gateway.goby.log.descriptors import FILE_DESCRIPTOR_GROUP, FILE_DESCRIPTOR_TYPE, LogDescriptorPool
from gateway.goby.log.entry import (
    CRC,
    CURRENT_VERSION,
    HEADER,
    HEADER_V2,
    LEGACY_SCHEME,
    MAGIC,
    SCHEME_GROUP_INDEX,
    SCHEME_PREFIX,
    SCHEME_TYPE_INDEX,
    VERSION,
    VERSION_ADD_SCHEME_TO_GROUP_TYPE_MAPPING,
    VERSION_ADD_TIMESTAMP,
    LogEntry,
    SkippedSpan,
    fixed_size,
)
from gateway.goby.log.errors import LogFormatError, NewerVersionError
from gateway.goby.portal.marshalling import Scheme

log = logging.getLogger(__name__)

#: Schemes Goby3 defines (marshalling/interface.h); entries of any other scheme are reported as skipped.
KNOWN_SCHEMES = frozenset(int(s) for s in Scheme if s >= 0)
#: An entry of a log still being written that claims more than this is taken as a corrupt size (a follower cannot
#: wait for the rest of the file to tell).
MAX_ENTRY_BYTES = 256 * 1024 * 1024


def read_version(head: bytes, where: str) -> int:
    """The format version from a log's first 4 bytes (1 when it starts with ``GBY3``: no version header)."""
    if len(head) < VERSION.size:
        raise LogFormatError(f"{where}: not a .goby log: {len(head)} byte(s), shorter than the version header")
    if head[:4] == MAGIC:
        return 1
    (version,) = VERSION.unpack_from(head)
    if version > CURRENT_VERSION:
        raise NewerVersionError(
            f"{where}: log format version {version} is newer than this reader's ({CURRENT_VERSION}): "
            f"use a newer goby-log-tool (or this is not a .goby log)", version)
    if version == 0:
        raise LogFormatError(f"{where}: not a .goby log: version 0 in the header")
    return version


class EntryParser:
    """The data entries in a log's bytes, resynchronising at the next ``GBY3`` after anything it cannot use: one
    parser for a finished file (:class:`LogReader`, ``final=True``: what the end cuts off is reported) and for one
    still being written (:class:`gateway.goby.log.follow.LogFollower`, ``final=False``: an incomplete last entry
    waits for more bytes). The index tables and descriptors carry over from one call of :meth:`entries` to the next.
    """

    def __init__(self, version: int, name: str, skip: Callable[[SkippedSpan], None], descriptors: LogDescriptorPool,
                 include_descriptors: bool = False) -> None:
        self.version = version
        self.name = name
        self.descriptors = descriptors
        self.include_descriptors = include_descriptors
        self.unknown_indexes: set[tuple[str, int]] = set()
        self.position = 0  # where the last entries() call stopped, in its buffer: the next unread byte
        self._report = skip
        self._groups: dict[int, dict[int, str]] = {}
        self._types: dict[int, dict[int, str]] = {}
        # (scheme, group index, type index) -> (group, type, is a descriptor entry); cleared by index entries
        self._resolved: dict[tuple[int, int, int], tuple[str, str, bool]] = {}

    def entries(self, buf: bytes | mmap.mmap, start: int, final: bool, base: int = 0) -> Iterator[LogEntry]:
        """The data entries of ``buf`` from ``start``; offsets (entries' and skipped spans') are ``base`` + index.

        Not ``final``: bytes that may be the start of an entry still being written end the call, with
        :attr:`position` at them; an entry claiming more than :data:`MAX_ENTRY_BYTES` is taken as corrupt.
        """
        n = len(buf)
        version = self.version
        timestamped = version >= VERSION_ADD_TIMESTAMP
        header = HEADER if timestamped else HEADER_V2
        hsize = header.size
        minimum = fixed_size(version)
        scheme_mapped = version >= VERSION_ADD_SCHEME_TO_GROUP_TYPE_MAPPING
        groups, types, resolved = self._groups, self._types, self._resolved
        crc32 = zlib.crc32
        unpack_header = header.unpack_from
        unpack_crc = CRC.unpack_from
        known = KNOWN_SCHEMES
        skip = self._skip
        head = b""
        fields: tuple[Any, ...] = ()
        p = self.position = start
        while p < n:
            if p + hsize + CRC.size <= n:
                head = buf[p:p + hsize]
                fields = unpack_header(head)
                magic = fields[0] == MAGIC
            else:
                magic = buf[p:p + 4] == MAGIC
            if not magic:
                q = buf.find(MAGIC, p)
                if q < 0:
                    if not final:  # keep what may be the start of the next GBY3
                        keep = max(p, n - 3)
                        if keep > p:
                            skip(base + p, keep - p, "bytes between entries that are not an entry")
                        self.position = keep
                    elif MAGIC.startswith(bytes(buf[p:n])):
                        skip(base + p, n - p, "truncated entry at the end of the file (a part of its GBY3)")
                    else:
                        skip(base + p, n - p, "no entry (GBY3) in the bytes up to the end of the file")
                    return
                skip(base + p, q - p, "bytes between entries that are not an entry")
                p = self.position = q
                if p + hsize + CRC.size <= n:
                    head = buf[p:p + hsize]
                    fields = unpack_header(head)
            if p + hsize + CRC.size > n:
                if final:
                    skip(base + p, n - p, "truncated entry at the end of the file (its header is incomplete)")
                return
            size = fields[1]
            end = p + 8 + size
            if size < minimum or (not final and size > MAX_ENTRY_BYTES):
                q = buf.find(MAGIC, p + 4)
                q = n if q < 0 else q
                skip(base + p, q - p, f"invalid entry size {size} (at least {minimum})" if size < minimum
                     else f"invalid entry size {size} (more than {MAX_ENTRY_BYTES})")
                p = self.position = q
                continue
            if end > n:
                if not final:
                    return  # the rest is still being written
                q = buf.find(MAGIC, p + 4)
                if q < 0:
                    skip(base + p, n - p, f"truncated entry at the end of the file ({size + 8} bytes long, "
                                          f"{n - p} present)")
                    return
                skip(base + p, q - p, f"entry size {size} runs past the end of the file (corrupt size)")
                p = self.position = q
                continue
            data = buf[p + hsize:end - 4]
            (given,) = unpack_crc(buf, end - 4)
            calculated = crc32(data, crc32(head))
            if calculated != given:
                nxt = end if (end == n or buf[end:end + 4] == MAGIC) else buf.find(MAGIC, p + 4)
                nxt = n if nxt < 0 else nxt
                skip(base + p, nxt - p, f"CRC mismatch (given 0x{given:08x}, calculated 0x{calculated:08x})")
                p = self.position = nxt
                continue
            scheme, group_index, type_index = fields[2], fields[3], fields[4]
            offset = p
            p = self.position = end
            names = resolved.get((scheme, group_index, type_index))
            if names is None:
                if scheme == SCHEME_GROUP_INDEX or scheme == SCHEME_TYPE_INDEX:
                    if scheme_mapped:
                        if len(data) < SCHEME_PREFIX.size:
                            skip(base + offset, end - offset, "index entry without its scheme")
                            continue
                        (owner,) = SCHEME_PREFIX.unpack_from(data)
                        name = bytes(data[2:]).decode("utf-8", "surrogateescape")
                    else:
                        owner, name = LEGACY_SCHEME, bytes(data).decode("utf-8", "surrogateescape")
                    if scheme == SCHEME_GROUP_INDEX:
                        groups.setdefault(owner, {})[group_index] = name
                    else:
                        types.setdefault(owner, {})[type_index] = name
                    resolved.clear()
                    continue
                if scheme not in known:
                    skip(base + offset, end - offset, f"entry of unknown scheme {scheme}")
                    continue
                key = scheme if scheme_mapped else LEGACY_SCHEME
                type_name = types.get(key, {}).get(type_index)
                if type_name is None:
                    type_name = f"_unknown{type_index}_"
                    self._unknown("type", type_index)
                group = groups.get(key, {}).get(group_index)
                if group is None:
                    group = f"_unknown{group_index}_"
                    self._unknown("group", group_index)
                names = resolved[(scheme, group_index, type_index)] = (
                    group, type_name,
                    scheme == Scheme.PROTOBUF and type_name == FILE_DESCRIPTOR_TYPE and group == FILE_DESCRIPTOR_GROUP)
            if names[2]:
                self.descriptors.add_file(data)
                if not self.include_descriptors:
                    continue
            yield LogEntry(scheme, names[0], names[1], fields[5] if timestamped else 0, data, base + offset)

    def _skip(self, offset: int, length: int, reason: str) -> None:
        self._report(SkippedSpan(offset, length, reason))

    def _unknown(self, what: str, index: int) -> None:
        if (what, index) not in self.unknown_indexes:
            self.unknown_indexes.add((what, index))
            log.warning("%s: no %s entry in file for %s index: %d", self.name, what, what, index)


class LogReader:
    """Iterate over a log's data entries; ``skipped`` lists what could not be read (filled while iterating).

    ``on_skip(span)`` is called for each skipped span as it is found (default: a warning on this module's logger).
    Use as a context manager or call :meth:`close`.
    """

    def __init__(self, source: str | os.PathLike[str] | bytes, *, include_descriptors: bool = False,
                 on_skip: Callable[[SkippedSpan], None] | None = None) -> None:
        self._mmap: mmap.mmap | None = None
        self.name = "<bytes>"
        if isinstance(source, bytes | bytearray | memoryview):
            self._buf: bytes | mmap.mmap = bytes(source)
        else:
            self.name = str(source)
            try:
                with open(source, "rb") as f:
                    size = os.fstat(f.fileno()).st_size
                    self._buf = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) if size else b""
            except OSError as exc:
                raise LogFormatError(f"cannot read {self.name}: {exc.strerror or exc}") from None
            if isinstance(self._buf, mmap.mmap):
                self._mmap = self._buf
        self.version = read_version(bytes(self._buf[:4]), self.name) if len(self._buf) else CURRENT_VERSION
        self.include_descriptors = include_descriptors
        self.descriptors = LogDescriptorPool()
        self.skipped: list[SkippedSpan] = []
        self._on_skip = on_skip or (lambda span: log.warning("%s: %s", self.name, span))
        self._parser = EntryParser(self.version, self.name, self._skip, self.descriptors, include_descriptors)

    @property
    def size(self) -> int:
        return len(self._buf)

    @property
    def unknown_indexes(self) -> set[tuple[str, int]]:
        """(``"group"``/``"type"``, index) of every data entry whose index entry the log lacks."""
        return self._parser.unknown_indexes

    def _skip(self, span: SkippedSpan) -> None:
        self.skipped.append(span)
        self._on_skip(span)

    def __iter__(self) -> Iterator[LogEntry]:
        if len(self._buf):
            yield from self._parser.entries(self._buf, 0 if self.version == 1 else VERSION.size, final=True)

    def close(self) -> None:
        if self._mmap is not None:
            self._mmap.close()
            self._mmap = None
            self._buf = b""

    def __enter__(self) -> LogReader:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
