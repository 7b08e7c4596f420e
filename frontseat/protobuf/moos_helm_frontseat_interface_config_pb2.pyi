from gateway.moos_gateway.protobuf import moos_gateway_config_pb2 as _moos_gateway_config_pb2
from frontseat.protobuf import frontseat_interface_config_pb2 as _frontseat_interface_config_pb2
from google.protobuf import descriptor as _descriptor
from typing import ClassVar as _ClassVar

DESCRIPTOR: _descriptor.FileDescriptor
MOOS_HELM_FIELD_NUMBER: _ClassVar[int]
moos_helm: _descriptor.FieldDescriptor
