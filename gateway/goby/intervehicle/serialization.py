"""SerializerTransporterMessage helpers: build one for a publication, its identity (Goby's ``operator==``), and
the protobuf metadata (every ``FileDescriptorProto`` a type depends on) that lets the portal decode types it never
imported."""

from __future__ import annotations

import logging
from typing import Any

from google.protobuf import descriptor_pb2, descriptor_pool
from google.protobuf.descriptor import Descriptor, FileDescriptor
from google.protobuf.message import Message
from google.protobuf.message_factory import GetMessageClass

from gateway.goby.intervehicle.protobuf.serializer_transporter_pb2 import (
    SerializerProtobufMetadata,
    SerializerTransporterMessage,
)
from gateway.goby.portal.marshalling import Scheme
from util.descriptors import descriptor_of

log = logging.getLogger(__name__)

StmKey = tuple[int, int, str, str, bytes]


def stm_key(stm: SerializerTransporterMessage) -> StmKey:
    """What makes two SerializerTransporterMessages the same publication (Goby's ``operator==``)."""
    k = stm.key
    return (k.serialize_time, k.marshalling_scheme, k.type, k.group, stm.data)


def _files_in_order(fd: FileDescriptor, seen: set[str], out: list[FileDescriptor]) -> None:
    if fd.name in seen:
        return
    seen.add(fd.name)
    for dep in fd.dependencies:
        _files_in_order(dep, seen, out)
    out.append(fd)


_metadata_cache: dict[str, SerializerProtobufMetadata] = {}


def metadata_for(msg_type: type[Message] | Descriptor) -> SerializerProtobufMetadata:
    """The type's name and its file with every dependency, dependencies first (cached per type)."""
    descriptor = msg_type if isinstance(msg_type, Descriptor) else descriptor_of(msg_type)
    cached = _metadata_cache.get(descriptor.full_name)
    if cached is None:
        files: list[FileDescriptor] = []
        _files_in_order(descriptor.file, set(), files)
        cached = SerializerProtobufMetadata(protobuf_name=descriptor.full_name)
        for fd in files:
            proto = descriptor_pb2.FileDescriptorProto()
            fd.CopyToProto(proto)
            cached.file_descriptor.append(proto)
        _metadata_cache[descriptor.full_name] = cached
    return cached


def message_class(type_name: str, metadata: SerializerProtobufMetadata | None = None) -> type[Message] | None:
    """The class of ``type_name``: from the default pool, or built there from ``metadata``; None if unknown."""
    pool = descriptor_pool.Default()
    try:
        return GetMessageClass(pool.FindMessageTypeByName(type_name))
    except KeyError:
        pass
    if metadata is None or not metadata.file_descriptor:
        return None
    for proto in metadata.file_descriptor:
        try:
            pool.FindFileByName(proto.name)
        except KeyError:
            try:
                pool.Add(proto)
            except Exception as exc:  # noqa: BLE001 - a conflicting definition: report and give up on the type
                log.error("cannot load %s from the publisher's metadata (file %s): %s", type_name, proto.name, exc)
                return None
    try:
        return GetMessageClass(pool.FindMessageTypeByName(type_name))
    except KeyError:
        return None


def serialize_publication(data: bytes, msg: Any, group: str, group_numeric: int, serialize_time_us: int,
                          cfg: Any, with_metadata: bool = True) -> SerializerTransporterMessage:
    """The SerializerTransporterMessage an application sends on ``modem_data_out``."""
    stm = SerializerTransporterMessage(data=data)
    key = stm.key
    key.marshalling_scheme = Scheme.DCCL
    key.type = msg.DESCRIPTOR.full_name
    key.group = group
    key.group_numeric = group_numeric
    key.serialize_time = serialize_time_us
    key.cfg.CopyFrom(cfg)
    if with_metadata:
        key.metadata.CopyFrom(metadata_for(type(msg)))
    return stm
