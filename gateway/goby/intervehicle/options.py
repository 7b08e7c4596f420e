"""Goby3's ``Publisher<T>`` and ``Subscriber<T>`` option objects for intervehicle publish/subscribe."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from gateway.goby.intervehicle.protobuf.intervehicle_pb2 import AckData, ExpireData
from gateway.goby.intervehicle.protobuf.transporter_config_pb2 import TransporterConfig
from gateway.goby.portal.group import Group

AckCallback = Callable[[Any, AckData], None]
ExpireCallback = Callable[[Any, ExpireData], None]


@dataclass
class Publisher:
    """Options of one publication (Goby's ``Publisher<T>``).

    - ``cfg``: ``goby.middleware.protobuf.TransporterConfig`` (``intervehicle { buffer {...} }``);
    - ``set_group(msg, group)``: writes the group into the message before it is encoded (needed for any group
      but the broadcast group 0, since DCCL carries no group);
    - ``on_ack(msg, ack_data)`` / ``on_expire(msg, expire_data)``: run on the publishing thread. Giving
      ``on_ack`` sets ``buffer.ack_required`` unless the config sets it explicitly (as Goby's constructor does).
    """

    cfg: TransporterConfig | None = None
    set_group: Callable[[Any, Group], None] | None = None
    on_ack: AckCallback | None = None
    on_expire: ExpireCallback | None = None

    def transporter_config(self) -> TransporterConfig:
        """The effective config (a copy), with Goby's ack_required-from-callback rule applied."""
        cfg = TransporterConfig()
        if self.cfg is not None:
            cfg.CopyFrom(self.cfg)
        buffer = cfg.intervehicle.buffer
        if self.on_ack is not None and not buffer.HasField("ack_required"):
            buffer.ack_required = True
        return cfg


@dataclass
class Subscriber:
    """Options of one subscription (Goby's ``Subscriber<T>``).

    - ``cfg``: ``TransporterConfig`` whose ``intervehicle`` names ``publisher_id`` (modem ids the Subscription
      is sent to), ``broadcast`` and the ``buffer`` wishes for the publisher's sub-buffer;
    - ``group(msg) -> Group``: the group a received message belongs to (from its contents); without it every
      message matches the broadcast group 0 only;
    - ``on_subscribed(subscription, ack_data)`` / ``on_subscribe_expired(subscription, expire_data)``: the
      Subscription was acked by / expired before reaching the publisher (run on the subscribing thread);
    - ``republish``: also publish each accepted message on interprocess (PROTOBUF and DCCL) under the subscribed
      group, so interprocess subscribers and the web scope on this vehicle see it (our addition; Goby does not).
    """

    cfg: TransporterConfig | None = None
    group: Callable[[Any], Group] | None = None
    on_subscribed: AckCallback | None = None
    on_subscribe_expired: ExpireCallback | None = None
    republish: bool = field(default=True)

    def transporter_config(self) -> TransporterConfig:
        cfg = TransporterConfig()
        if self.cfg is not None:
            cfg.CopyFrom(self.cfg)
        return cfg
