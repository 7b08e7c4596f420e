"""A log's protobuf entries as HDF5, in the layout of Goby3's ``goby_log_tool --format HDF5``
(``src/middleware/log/hdf5/hdf5.{h,cpp}``, ``hdf5_protobuf_values.h``), written with h5py.

Layout, as Goby's ``hdf5::Writer`` makes it:

- one HDF5 group per Goby group (``/<group>``, the group's ``/`` making nested HDF5 groups) and in it one per
  message type (``/<group>/<full type name>``); its entries are sorted by time (equal times keep the log's order);
- in each type's group ``_utime_`` (uint64 µs), ``_datenum_`` (double, MATLAB datenum) and ``_scheme_`` (int32),
  one row per message, and one dataset per field (then per extension) named after the field;
- a scalar field is a dataset of shape ``(n,)`` (int32, int64, uint32, uint64, float32, float64; bool as uint8;
  enums as int32 with ``enum_names``/``enum_values`` attributes); an unset optional field holds the type's *empty*
  value (the integer type's maximum, 255 for bool, NaN); a repeated field adds a dimension as long as the longest
  repetition, padded with the empty value;
- a string or bytes field is int8 characters of shape ``(..., longest)``, zero-padded, plus ``<name>_size``
  (uint32, the length of each value);
- a message field is a child group (``<field name>``, the full name for an extension) holding its fields'
  datasets with the parent's dimensions (plus one for a repeated message field);
- every dataset carries a ``default_value`` attribute (the field's default).

Like Goby, only PROTOBUF and DCCL entries become rows (each DCCL message of an entry its own row); CSTR and JSON
entries have no HDF5 form and are counted as left out. ``hdf5_chunk_length`` writes a collection each time it
reaches that many messages into chunked, extendable datasets (``hdf5_compression_level``: deflate), so memory
stays bounded; ``write_hdf5_zero_length_dim = false`` writes empty datasets as HDF5 null dataspaces.

Where Goby would recurse forever (a message type that contains itself), the recursion stops at the first level
where no message actually sets the field.  h5py is imported when an export starts (the ``log`` extra).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

from google.protobuf import message_factory
from google.protobuf.descriptor import Descriptor, FieldDescriptor

from gateway.goby.log.entry import LogEntry
from gateway.goby.log.errors import import_optional
from gateway.goby.log.render import EntryDecoder, scheme_name
from gateway.goby.portal.marshalling import Scheme

if TYPE_CHECKING:
    import h5py
    import numpy as np
    from google.protobuf.message import Message

log = logging.getLogger(__name__)

#: Goby's datenum of the Unix epoch (``datenum(1970, 1, 1, 0, 0, 0)``) and seconds per day.
DATENUM_UNIX_EPOCH = 719529.0
SECONDS_PER_DAY = 86400.0
FILE_DESCRIPTOR_PROTO = "google.protobuf.FileDescriptorProto"


def import_h5py() -> Any:
    """h5py, or ``ExportUnavailable`` saying how to install it."""
    return import_optional("h5py", "HDF5")


@dataclass(frozen=True, slots=True)
class _Kind:
    """How one protobuf C++ type is stored: numpy dtype and the empty value of missing values."""

    dtype: str
    empty: Any


_CPP = FieldDescriptor
_KINDS: dict[int, _Kind] = {
    _CPP.CPPTYPE_INT32: _Kind("<i4", 2**31 - 1),
    _CPP.CPPTYPE_ENUM: _Kind("<i4", 2**31 - 1),
    _CPP.CPPTYPE_INT64: _Kind("<i8", 2**63 - 1),
    _CPP.CPPTYPE_UINT32: _Kind("<u4", 2**32 - 1),
    _CPP.CPPTYPE_UINT64: _Kind("<u8", 2**64 - 1),
    _CPP.CPPTYPE_BOOL: _Kind("u1", 255),
    _CPP.CPPTYPE_FLOAT: _Kind("<f4", math.nan),
    _CPP.CPPTYPE_DOUBLE: _Kind("<f8", math.nan),
}


@dataclass(slots=True)
class _Row:
    utime: int
    scheme: int
    message: Message


@dataclass(slots=True)
class _Collection:
    """The messages of one type on one group (Goby's ``MessageCollection``)."""

    path: str
    rows: list[_Row] = field(default_factory=list)


@dataclass
class Hdf5Stats:
    """What an export wrote: messages (rows) per HDF5 group, and entries left out per reason."""

    rows: dict[str, int] = field(default_factory=dict)
    left_out: dict[str, int] = field(default_factory=dict)


def _value_getter(fd: FieldDescriptor) -> Callable[[Message], Any]:
    extension: Any = fd
    if fd.is_extension:
        return lambda m: m.Extensions[extension]
    name = fd.name
    if fd.message_type is not None and fd.message_type.GetOptions().map_entry:
        entry_cls = message_factory.GetMessageClass(fd.message_type)

        def map_entries(m: Message) -> list[Message]:
            out = []
            for key, value in getattr(m, name).items():
                entry = entry_cls(key=key)
                if isinstance(value, object) and hasattr(value, "DESCRIPTOR"):
                    entry.value.CopyFrom(value)  # type: ignore[attr-defined]
                else:
                    entry.value = value  # type: ignore[attr-defined]
                out.append(entry)
            return out

        return map_entries
    return lambda m: getattr(m, name)


def _presence(fd: FieldDescriptor) -> Callable[[Message], bool]:
    """C++ ``HasField`` for a singular field (without presence: the value is not the type's zero)."""
    extension: Any = fd
    if fd.is_extension:
        return lambda m: m.HasExtension(extension)
    name = fd.name
    if fd.has_presence:
        return lambda m: m.HasField(name)
    zero = fd.default_value
    return lambda m: getattr(m, name) != zero


def _default(fd: FieldDescriptor) -> Any:
    """``FieldDescriptor::default_value_*()``: a repeated field's is its type's zero (an enum's first value)."""
    if fd.cpp_type == _CPP.CPPTYPE_ENUM and fd.enum_type is not None:
        if fd.is_repeated:
            return fd.enum_type.values[0].number
        return int(fd.default_value)
    if fd.is_repeated:
        return {_CPP.CPPTYPE_STRING: "", _CPP.CPPTYPE_BOOL: False}.get(fd.cpp_type, 0)
    return fd.default_value


def _extensions(desc: Descriptor) -> list[FieldDescriptor]:
    try:
        found = list(desc.file.pool.FindAllExtensions(desc))
    except (KeyError, TypeError, AttributeError):
        return []
    return sorted(found, key=lambda f: f.number)


class Hdf5Writer:
    """Goby's ``hdf5::Writer`` on an open ``h5py.File``: :meth:`add` messages, then :meth:`finish`."""

    def __init__(self, h5file: h5py.File, *, zero_length_dim: bool = True, chunk_length: int | None = None,
                 compression_level: int | None = None) -> None:
        import numpy  # noqa: PLC0415 - comes with h5py

        self._np = numpy
        self._h5py = import_h5py()
        self._file = h5file
        self._zero_length_dim = zero_length_dim
        self._chunk_length = chunk_length if chunk_length and chunk_length > 0 else None
        self._compression = compression_level
        self._final = False
        self._channels: dict[str, dict[str, _Collection]] = {}
        self.rows: dict[str, int] = {}
        self._warned_fdp = False

    # ---------------------------------------------------------------------------------------- collecting
    def add(self, group: str, utime: int, scheme: int, message: Message) -> None:
        channel = group.strip().strip("/").strip()
        type_name = message.DESCRIPTOR.full_name
        collections = self._channels.setdefault(channel, {})
        collection = collections.get(type_name)
        if collection is None:
            parts = [p for p in channel.split("/") if p]
            collection = collections[type_name] = _Collection("/".join([*parts, type_name]))
        collection.rows.append(_Row(utime, scheme, message))
        self.rows[collection.path] = self.rows.get(collection.path, 0) + 1
        if self._chunk_length is not None and len(collection.rows) >= self._chunk_length:
            self._write_collection(collection)
            collection.rows.clear()

    def finish(self) -> None:
        """Write everything still collected (Goby's final ``write()``)."""
        self._final = True
        for channel in sorted(self._channels):
            for type_name in sorted(self._channels[channel]):
                collection = self._channels[channel][type_name]
                if collection.rows:
                    self._write_collection(collection)
                    collection.rows.clear()

    # ------------------------------------------------------------------------------------------- writing
    def _write_collection(self, collection: _Collection) -> None:
        rows = sorted(collection.rows, key=lambda r: r.utime)  # a multimap on time: stable for equal times
        np = self._np
        utime = np.array([r.utime for r in rows], dtype="<u8")
        seconds = utime // 1_000_000
        datenum = (DATENUM_UNIX_EPOCH + seconds.astype("<f8") / SECONDS_PER_DAY
                   + (utime - seconds * 1_000_000).astype("<f8") / 1e6 / SECONDS_PER_DAY)
        n = len(rows)
        self._write_array(collection.path, "_utime_", utime, [n], 0, "<u8")
        self._write_array(collection.path, "_datenum_", datenum, [n], 0.0, "<f8")
        self._write_array(collection.path, "_scheme_", np.array([r.scheme for r in rows], dtype="<i4"), [n], 0,
                          "<i4")
        messages: list[Message | None] = [r.message for r in rows]
        desc = cast(Descriptor, rows[0].message.DESCRIPTOR)
        for fd in [*desc.fields, *_extensions(desc)]:
            self._write_field(collection.path, fd, messages, [n], (desc.full_name,))

    def _write_field(self, group: str, fd: FieldDescriptor, messages: Sequence[Message | None], hs: list[int],
                     chain: tuple[str, ...]) -> None:
        if fd.cpp_type == _CPP.CPPTYPE_MESSAGE and fd.message_type is not None:
            if fd.message_type.full_name == FILE_DESCRIPTOR_PROTO:
                if not self._warned_fdp:
                    self._warned_fdp = True
                    log.warning("Omitting google.protobuf.FileDescriptorProto")
                return
            self._write_embedded(group, fd, messages, hs, chain)
        elif fd.cpp_type == _CPP.CPPTYPE_STRING:
            self._write_strings(group, fd, messages, hs)
        else:
            self._write_scalars(group, fd, messages, hs)
            if fd.cpp_type == _CPP.CPPTYPE_ENUM:
                self._write_enum_attributes(group, fd)

    def _write_scalars(self, group: str, fd: FieldDescriptor, messages: Sequence[Message | None],
                       hs: list[int]) -> None:
        kind = _KINDS[fd.cpp_type]
        get = _value_getter(fd)
        if fd.is_repeated:
            longest = max((len(get(m)) for m in messages if m is not None), default=0)
            values: list[Any] = [kind.empty] * (len(messages) * longest)
            for i, m in enumerate(messages):
                if m is not None:
                    for j, v in enumerate(get(m)):
                        values[i * longest + j] = v
            shape = [*hs, longest]
        else:
            has = _presence(fd)
            optional = not fd.is_required
            values = [kind.empty if m is None or (optional and not has(m)) else get(m) for m in messages]
            shape = hs
        array = self._np.array(values, dtype=kind.dtype).reshape(shape) if values else \
            self._np.zeros(shape, dtype=kind.dtype)
        self._write_array(group, fd.name, array, shape, _default(fd), kind.dtype, kind.empty)

    def _write_strings(self, group: str, fd: FieldDescriptor, messages: Sequence[Message | None],
                       hs: list[int]) -> None:
        get = _value_getter(fd)
        if fd.is_repeated:
            longest = max((len(get(m)) for m in messages if m is not None), default=0)
            values: list[bytes] = [b""] * (len(messages) * longest)
            for i, m in enumerate(messages):
                if m is not None:
                    for j, v in enumerate(get(m)):
                        values[i * longest + j] = _raw(v)
            outer = [*hs, longest]
        else:  # Goby's string retrieve ignores presence: an unset field gives its default
            values = [b"" if m is None else _raw(get(m)) for m in messages]
            outer = hs
        np = self._np
        sizes = np.array([len(v) for v in values], dtype="<u4").reshape(outer)
        width = int(sizes.max()) if sizes.size else 0
        chars = np.frombuffer(b"".join(v.ljust(width, b"\0") for v in values), dtype="i1").reshape([*outer, width])
        dataset = self._write_array(group, fd.name, chars, [*outer, width], None, "i1", 0, string_chunks=True)
        self._write_array(group, fd.name + "_size", sizes, outer, 0, "<u4", 0)
        if dataset is not None and "default_value" not in dataset.attrs:
            default = _raw(_default(fd))
            tid = self._h5py.h5t.C_S1.copy()
            tid.set_size(len(default) + 1)
            tid.set_strpad(self._h5py.h5t.STR_NULLTERM)
            space = self._h5py.h5s.create_simple((1,))
            attr = self._h5py.h5a.create(dataset.id, b"default_value", tid, space)
            attr.write(np.array([default], dtype=f"S{len(default) + 1}"))

    def _write_embedded(self, group: str, fd: FieldDescriptor, messages: Sequence[Message | None], hs: list[int],
                        chain: tuple[str, ...]) -> None:
        sub_desc = fd.message_type
        if sub_desc is None:
            return
        get = _value_getter(fd)
        sub_group = f"{group}/{fd.full_name if fd.is_extension else fd.name}"
        if not any(m is not None for m in messages):
            return  # Goby recurses only when a message requires it
        if fd.is_repeated:
            longest = max((len(get(m)) for m in messages if m is not None), default=0)
            if longest == 0 and sub_desc.full_name in chain:
                return
            subs: list[Message | None] = [None] * (len(messages) * longest)
            for i, m in enumerate(messages):
                if m is not None:
                    for j, v in enumerate(get(m)):
                        subs[i * longest + j] = v
            sub_hs = [*hs, longest]
        else:
            if sub_desc.full_name in chain:
                has = _presence(fd)
                if not any(m is not None and has(m) for m in messages):
                    return  # a type inside itself, set nowhere: Goby would recurse without end
            subs = [None if m is None else get(m) for m in messages]  # an unset message reads as its default
            sub_hs = hs
        for sub_fd in [*sub_desc.fields, *_extensions(sub_desc)]:
            self._write_field(sub_group, sub_fd, subs, sub_hs, (*chain, sub_desc.full_name))

    def _write_enum_attributes(self, group: str, fd: FieldDescriptor) -> None:
        dataset = self._file[group][fd.name]
        if fd.enum_type is None or ("enum_names" in dataset.attrs and "enum_values" in dataset.attrs):
            return
        values = fd.enum_type.values
        dataset.attrs.create("enum_names", [v.name for v in values],
                             dtype=self._h5py.string_dtype(encoding="ascii"))
        dataset.attrs.create("enum_values", self._np.array([v.number for v in values], dtype="<i4"))

    def _write_array(self, group: str, name: str, data: np.ndarray, shape: list[int], default: Any, dtype: str,
                     empty: Any = None, *, string_chunks: bool = False) -> h5py.Dataset | None:
        """Goby's ``write_vector``: create (or extend, when chunked) ``group/name`` and write ``data``."""
        grp = self._file.require_group(group)
        dataset: h5py.Dataset | None = grp.get(name)
        if dataset is None:
            chunked = self._chunk_length is not None and not self._final
            if not data.size and not self._zero_length_dim:
                dataset = grp.create_dataset(name, data=self._h5py.Empty(dtype))
            elif chunked:
                chunks = [max(1, s) for s in shape]
                chunks[0] = max(1, self._chunk_length or 1)
                if string_chunks:
                    chunks[-1] = 256
                dataset = grp.create_dataset(
                    name, shape=tuple(shape), dtype=dtype, maxshape=tuple(None for _ in shape), chunks=tuple(chunks),
                    fillvalue=empty, compression="gzip" if self._compression is not None else None,
                    compression_opts=self._compression)
                dataset[...] = data
            else:
                dataset = grp.create_dataset(name, data=data, dtype=dtype)
        else:
            old = dataset.shape
            if old is None or len(old) != len(shape):
                log.warning("%s/%s: cannot extend a dataset of shape %s with %s; rows left out", group, name, old,
                            shape)
                return dataset
            new = [max(a, b) for a, b in zip(old, shape, strict=True)]
            new[0] = old[0] + shape[0]
            dataset.resize(tuple(new))
            if data.size:
                index = (slice(old[0], old[0] + shape[0]), *(slice(0, s) for s in shape[1:]))
                dataset[index] = data
        if default is not None and "default_value" not in dataset.attrs:
            dataset.attrs.create("default_value", self._np.array([default], dtype=dtype))
        return dataset


def _raw(value: str | bytes) -> bytes:
    return value.encode("utf-8", "surrogateescape") if isinstance(value, str) else bytes(value)


def export_hdf5(entries: Iterable[LogEntry], decoder: EntryDecoder, path: str, *, zero_length_dim: bool = True,
                chunk_length: int | None = None, compression_level: int | None = None) -> Hdf5Stats:
    """Write the PROTOBUF and DCCL entries of ``entries`` to the HDF5 file ``path`` (created or truncated).

    Entries of other schemes, and entries that do not decode (the decoder warns once per type), are counted in
    ``left_out``. Raises ``ExportUnavailable`` without h5py and ``OSError`` when ``path`` cannot be written.
    """
    h5py = import_h5py()
    stats = Hdf5Stats()
    with h5py.File(path, "w") as h5file:
        writer = Hdf5Writer(h5file, zero_length_dim=zero_length_dim, chunk_length=chunk_length,
                            compression_level=compression_level)
        for entry in entries:
            if entry.scheme not in (Scheme.PROTOBUF, Scheme.DCCL):
                reason = f"scheme {scheme_name(entry.scheme)} has no HDF5 form"
                stats.left_out[reason] = stats.left_out.get(reason, 0) + 1
                continue
            value = decoder.decode(entry)
            if value.error is not None:
                reason = f"{entry.type_name} does not decode"
                stats.left_out[reason] = stats.left_out.get(reason, 0) + 1
                continue
            for msg in value.messages:
                writer.add(entry.group, entry.timestamp_micro, entry.scheme, msg)
        writer.finish()
        stats.rows = dict(writer.rows)
    for reason, count in sorted(stats.left_out.items()):
        log.warning("HDF5: %d entr%s left out: %s", count, "y" if count == 1 else "ies", reason)
    return stats
