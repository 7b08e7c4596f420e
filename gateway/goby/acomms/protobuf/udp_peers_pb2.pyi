from gateway.goby.acomms.protobuf import driver_base_pb2 as _driver_base_pb2
from google.protobuf.internal import containers as _containers
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from collections.abc import Iterable as _Iterable
from typing import ClassVar as _ClassVar, Optional as _Optional

DESCRIPTOR: _descriptor.FileDescriptor
UDP_PEERS_FIELD_NUMBER: _ClassVar[int]
udp_peers: _descriptor.FieldDescriptor

class UDPPeers(_message.Message):
    __slots__ = ("peer_address",)
    PEER_ADDRESS_FIELD_NUMBER: _ClassVar[int]
    peer_address: _containers.RepeatedScalarFieldContainer[str]
    def __init__(self, peer_address: _Optional[_Iterable[str]] = ...) -> None: ...
