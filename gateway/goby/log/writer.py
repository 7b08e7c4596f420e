"""``LogWriter``: entries into a ``.goby`` byte stream exactly as Goby3's ``LogEntry::serialize`` and the logger's
protobuf/DCCL plugins write them.

The first entry of a (scheme, group) writes a group index entry, the first of a (scheme, type) a type index
entry (both counters start at 1 and are shared by all schemes, and both index entries carry the data entry's
timestamp); a new PROTOBUF or DCCL type then writes its descriptors (:mod:`gateway.goby.log.descriptors`) before
its data.  The writer only produces bytes: ``sink`` receives each entry with its index and descriptor entries in
one call, so a file holds whole entries as long as each ``sink`` call lands whole.
"""

from __future__ import annotations

from collections.abc import Callable

from gateway.goby.log.descriptors import FILE_DESCRIPTOR_GROUP, FILE_DESCRIPTOR_TYPE, DescriptorRecorder
from gateway.goby.log.entry import (
    CURRENT_VERSION,
    MAX_INDEX,
    SCHEME_GROUP_INDEX,
    SCHEME_TYPE_INDEX,
    encode_record,
    index_data,
    version_header,
)
from gateway.goby.log.errors import LogWriteError
from gateway.goby.portal.marshalling import Scheme

Sink = Callable[[bytes], object]  # e.g. bytearray.extend, a file's write


class LogWriter:
    """Serialize entries of one log; ``clock()`` gives µs since the epoch (descriptor entries are stamped with it)."""

    def __init__(self, sink: Sink, clock: Callable[[], int], *, describe_protobuf: bool = True) -> None:
        self._sink = sink
        self._clock = clock
        self._parts: list[bytes] = [version_header(CURRENT_VERSION)]
        self._groups: dict[int, dict[str, int]] = {}
        self._types: dict[int, dict[str, int]] = {}
        self._next_group = 1
        self._next_type = 1
        self._recorders: dict[int, DescriptorRecorder] = {}
        if describe_protobuf:
            for scheme in (Scheme.PROTOBUF, Scheme.DCCL):
                self._recorders[scheme] = DescriptorRecorder(self._write_file_descriptor)
        self.entries = 0  # data entries written (descriptor entries included)

    def write(self, data: bytes, scheme: int, type_name: str, group: str, timestamp_micro: int | None = None) -> None:
        """Write one entry (and the index/descriptor entries it needs) to the sink in one call.

        Raises ``LogWriteError`` when the 16-bit group or type index is exhausted (nothing is written then).
        """
        ts = self._clock() if timestamp_micro is None else timestamp_micro
        self._serialize(bytes(data), int(scheme), type_name, group, ts)
        chunk = b"".join(self._parts)
        self._parts.clear()
        self._sink(chunk)

    def _serialize(self, data: bytes, scheme: int, type_name: str, group: str, ts: int) -> None:
        groups = self._groups.setdefault(scheme, {})
        types = self._types.setdefault(scheme, {})
        group_index = groups.get(group)
        type_index = types.get(type_name)
        if (group_index is None and self._next_group > MAX_INDEX) or (type_index is None and self._next_type > MAX_INDEX):
            self._parts.clear()
            raise LogWriteError(f"more than {MAX_INDEX} distinct groups or types in one log: cannot index "
                                f"{group!r} / {type_name!r} (rotate the log)")
        if group_index is None:
            group_index = groups[group] = self._next_group
            self._next_group += 1
            self._parts.append(encode_record(SCHEME_GROUP_INDEX, group_index, 0, ts, index_data(scheme, group)))
        if type_index is None:
            type_index = types[type_name] = self._next_type
            self._next_type += 1
            self._parts.append(encode_record(SCHEME_TYPE_INDEX, 0, type_index, ts, index_data(scheme, type_name)))
            recorder = self._recorders.get(scheme)
            if recorder is not None:
                recorder.new_type(type_name)
        self._parts.append(encode_record(scheme, group_index, type_index, ts, data))
        self.entries += 1

    def _write_file_descriptor(self, data: bytes) -> None:
        # a LogEntry made (and so stamped) now, serialized through the same path: it may index its group and
        # type and, through the PROTOBUF recorder, describe FileDescriptorProto itself first
        self._serialize(data, Scheme.PROTOBUF, FILE_DESCRIPTOR_TYPE, FILE_DESCRIPTOR_GROUP, self._clock())

    @property
    def unknown_types(self) -> set[str]:
        """Protobuf types written without a descriptor (not known to this process)."""
        return {name for recorder in self._recorders.values() for name in recorder.unknown_types}
