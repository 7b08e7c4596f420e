"""Protobuf descriptors in a log: which ``FileDescriptorProto``s Goby writes for a type, and the pool a reader
builds from them.

Writing follows ``ProtobufPluginBase::add_new_protobuf_type`` (Goby3's protobuf_log_plugin.h): the first time a
type index is written for a PROTOBUF or DCCL type, its file is written (dependencies first, each file once per
scheme's plugin), then the files of the extensions of that type, then the same for every message-typed field,
recursively.  Each file is an entry of scheme PROTOBUF, type ``google.protobuf.FileDescriptorProto``, on the group
``goby::log::ProtobufFileDescriptor``.  Goby looks types up in the C++ generated pool; here it is the Python
default pool (the project's protos and whatever ``load_shared_library`` imported).
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from google.protobuf import message as pb_message
from google.protobuf.descriptor import Descriptor, FieldDescriptor, FileDescriptor

log = logging.getLogger(__name__)

FILE_DESCRIPTOR_GROUP = "goby::log::ProtobufFileDescriptor"
FILE_DESCRIPTOR_TYPE = "google.protobuf.FileDescriptorProto"

#: Writes one FileDescriptorProto entry (serialized bytes) through the log writer, which may call back in.
EmitFile = Callable[[bytes], None]


def file_descriptor_bytes(file: FileDescriptor) -> bytes:
    """``FileDescriptor::CopyTo`` then serialize: the file's definition without source info."""
    proto = descriptor_pb2.FileDescriptorProto()
    file.CopyToProto(proto)
    return proto.SerializeToString()


class DescriptorRecorder:
    """One scheme's plugin state on the writing side (Goby keeps one per PROTOBUF and DCCL plugin)."""

    def __init__(self, emit: EmitFile, pool: descriptor_pool.DescriptorPool | None = None) -> None:
        self._emit = emit
        self._pool = pool or descriptor_pool.Default()
        self._written_files: set[str] = set()
        self._written_types: set[str] = set()
        self.unknown_types: set[str] = set()

    def new_type(self, type_name: str) -> None:
        """The hook run when a type index is written: record the type's files (if the type is known here)."""
        try:
            desc = self._pool.FindMessageTypeByName(type_name)
        except KeyError:
            if type_name not in self.unknown_types:
                self.unknown_types.add(type_name)
                log.warning("Unknown protobuf type: %s (its descriptor is not in the log; import its module with "
                            "load_shared_library)", type_name)
            return
        self._add_type(desc)

    def _add_file(self, file: FileDescriptor) -> None:
        if file.name in self._written_files:
            return
        for dependency in file.dependencies:
            self._add_file(dependency)
        log.debug("inserting file descriptor proto for %s", file.name)
        self._written_files.add(file.name)
        self._emit(file_descriptor_bytes(file))

    def _add_type(self, desc: Descriptor) -> None:
        if desc.full_name in self._written_types:
            return
        self._add_file(desc.file)
        extensions: list[FieldDescriptor] = list(self._pool.FindAllExtensions(desc))
        for extension in extensions:
            self._add_file(extension.file)  # type: ignore[attr-defined]  # FieldDescriptor.file exists at run time
        self._written_types.add(desc.full_name)
        for field in desc.fields:
            if field.message_type is not None:
                self._add_type(field.message_type)


class LogDescriptorPool:
    """The reading side: the files a log carries, in a pool of their own, and the message classes a reader uses.

    Files are collected as they are read and built on first lookup, each after its dependencies (Goby writes a
    file's dependencies first, but the recursion through FileDescriptorProto itself puts descriptor.proto after
    files that import it).  Types the process knows (its generated code: the project's protos and loaded
    modules) are used first, so a DCCL type decodes with the codec's compiled options; types only the log knows
    come from the log's files.
    """

    def __init__(self) -> None:
        self._pool = descriptor_pool.DescriptorPool()
        self._files: dict[str, descriptor_pb2.FileDescriptorProto] = {}
        self._pending: list[str] = []
        self._built: set[str] = set()
        self._classes: dict[str, type[pb_message.Message] | None] = {}
        self.failed_files: dict[str, str] = {}

    def add_file(self, data: bytes) -> None:
        """Add one FileDescriptorProto entry's bytes (repeats are ignored, as Goby's reader does)."""
        proto = descriptor_pb2.FileDescriptorProto()
        try:
            proto.ParseFromString(data)
        except pb_message.DecodeError as exc:
            self.failed_files.setdefault("<unparseable>", f"unparseable FileDescriptorProto: {exc}")
            return
        if proto.name in self._files:
            return
        self._files[proto.name] = proto
        self._pending.append(proto.name)
        self._classes = {name: cls for name, cls in self._classes.items() if cls is not None}

    @property
    def file_names(self) -> list[str]:
        """The files the log carried, in the order they were read."""
        return list(self._files)

    def _build(self, name: str, chain: tuple[str, ...] = ()) -> bool:
        if name in self._built:
            return True
        if name in self.failed_files:
            return False
        proto = self._files.get(name)
        if proto is None or name in chain:
            why = "not in the log" if proto is None else "an import cycle"
            self.failed_files[name] = why
            return False
        for dependency in proto.dependency:
            if not self._build(dependency, (*chain, name)):
                self._fail(name, f"its import {dependency} cannot be built")
                return False
        try:
            self._pool.Add(proto)
        except (TypeError, ValueError, KeyError) as exc:  # a conflicting or malformed definition
            self._fail(name, str(exc))
            return False
        self._built.add(name)
        return True

    def _fail(self, name: str, why: str) -> None:
        self.failed_files[name] = why
        log.warning("cannot use the descriptor of %s from the log: %s", name, why)

    def message_class(self, type_name: str) -> type[pb_message.Message] | None:
        """The class for a protobuf type name, or None when neither this process nor the log describes it."""
        if type_name in self._classes:
            return self._classes[type_name]
        if self._pending:
            pending, self._pending = self._pending, []
            for name in pending:
                self._build(name)
        cls: type[pb_message.Message] | None = None
        for pool in (descriptor_pool.Default(), self._pool):
            try:
                desc = pool.FindMessageTypeByName(type_name)
            except KeyError:
                continue
            cls = message_factory.GetMessageClass(desc)
            break
        if cls is not None or not self._pending:
            self._classes[type_name] = cls
        return cls
