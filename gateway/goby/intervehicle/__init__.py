"""Goby3's intervehicle layer: ``thread.intervehicle().publish/subscribe`` with Goby's ``Publisher``/``Subscriber``
options, Subscription forwarding (DCCL id 3), and the links (DynamicBuffer, TDMA MAC, modem drivers) hosted by
``goby-broker``'s ``intervehicle {}`` block. See docs/intervehicle.md."""

from gateway.goby.intervehicle.errors import (
    IntervehicleConfigError,
    IntervehicleError,
    InvalidPublicationError,
    InvalidSubscriptionError,
)
from gateway.goby.intervehicle.options import Publisher, Subscriber
from gateway.goby.intervehicle.protobuf.intervehicle_pb2 import AckData, ExpireData
from gateway.goby.intervehicle.protobuf.transporter_config_pb2 import TransporterConfig

__all__ = [
    "AckData",
    "ExpireData",
    "IntervehicleConfigError",
    "IntervehicleError",
    "InvalidPublicationError",
    "InvalidSubscriptionError",
    "Publisher",
    "Subscriber",
    "TransporterConfig",
]
