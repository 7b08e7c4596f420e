"""``thread.intervehicle()``: intervehicle publish/subscribe for one thread (Goby3's ``InterVehicleForwarder``).

Like Goby, an application never touches a link: it sends DCCL-encoded publications
(``SerializerTransporterMessage``) and its Subscriptions to the vehicle's broker over interprocess, and gets back
received packets (``modem_data_in``), acks and expiries. Every callback runs on the owning thread, inside its poll,
never concurrently with ``loop()``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from google.protobuf.message import Message

from gateway.goby.dccl import DcclError
from gateway.goby.intervehicle import groups
from gateway.goby.intervehicle.errors import (
    IntervehicleError,
    InvalidPublicationError,
    InvalidSubscriptionError,
)
from gateway.goby.intervehicle.options import Publisher, Subscriber
from gateway.goby.intervehicle.protobuf.intervehicle_pb2 import (
    AckMessagePair,
    DCCLForwardedData,
    ExpireMessagePair,
    Subscription,
    SubscriptionReport,
)
from gateway.goby.intervehicle.protobuf.serializer_transporter_pb2 import SerializerTransporterMessage
from gateway.goby.intervehicle.serialization import StmKey, metadata_for, serialize_publication, stm_key
from gateway.goby.portal.context import ProcessContext
from gateway.goby.portal.group import BROADCAST_GROUP, Group, GroupLike, as_group
from gateway.goby.portal.interface_registry import InterfaceEntry
from gateway.goby.portal.interprocess import InterProcessPortal
from gateway.goby.portal.marshalling import Scheme

log = logging.getLogger(__name__)

LAYER = "intervehicle"
#: Pending acks older than the largest ttl (DCCL bound 86400 s) plus 1 s are forgotten (as Goby purges them).
PENDING_PURGE_US = 86_401_000_000


def _numeric_group(group: GroupLike, error: type[IntervehicleError], has_group_function: bool,
                   no_group_function: Callable[[Group], str]) -> tuple[Group, int]:
    """``group`` as a Group and its numeric id if intervehicle can carry it: it has a numeric id, and a group other
    than the broadcast one comes with a group function (DCCL carries no group); else ``error`` naming what is
    missing."""
    grp = as_group(group)
    if grp.numeric is None:
        raise error(f"intervehicle group {grp} needs a numeric id (e.g. \"{grp};1\")")
    if grp.numeric != BROADCAST_GROUP and not has_group_function:
        raise error(no_group_function(grp))
    return grp, grp.numeric


@dataclass(eq=False)
class _Pending:
    msg: Any
    on_ack: Callable[[Any, Any], None] | None
    on_expire: Callable[[Any, Any], None] | None
    serialize_time: int
    expired: bool = False
    acked_by: set[int] = field(default_factory=set)


@dataclass(eq=False)
class _Handler:
    group: Group
    msg_type: type[Message]
    callback: Callable[[Any], None]
    options: Subscriber


class InterVehicleForwarder:
    """Owned by one thread; not thread-safe (hand work over with ``call_soon``)."""

    def __init__(self, interprocess: InterProcessPortal, context: ProcessContext, thread_name: str) -> None:
        self._ip = interprocess
        self._ctx = context
        self._thread_name = thread_name
        self._handlers: dict[int, dict[str, _Handler]] = {}
        self._subscriptions: dict[tuple[int, str], Subscription] = {}
        self._pending: dict[StmKey, _Pending] = {}
        self._listening = False
        context.dccl.load(Subscription)

    # ------------------------------------------------------------------------------------------- publish
    def publish(self, group: GroupLike, msg: Message, publisher: Publisher | None = None) -> None:
        """Send ``msg`` (a DCCL message) to every remote subscriber of ``group``; also publish it on interprocess
        here (DCCL and PROTOBUF, as Goby does). Raises ``InvalidPublicationError`` for a group without a numeric
        id, or a non-broadcast group without ``publisher.set_group``."""
        publisher = publisher if publisher is not None else Publisher()
        grp, numeric = _numeric_group(group, InvalidPublicationError, publisher.set_group is not None, lambda grp: (
            f"publishing {msg.DESCRIPTOR.full_name} on intervehicle group {grp} (numeric {grp.numeric}) needs a "
            "Publisher with set_group: DCCL messages do not carry a group"))
        copy = type(msg)()
        copy.CopyFrom(msg)
        if publisher.set_group is not None:
            publisher.set_group(copy, grp)
        codec = self._ctx.dccl
        try:
            codec.load(type(copy))
            data = codec.encode(copy)
        except DcclError as exc:
            raise InvalidPublicationError(f"cannot DCCL-encode {msg.DESCRIPTOR.full_name} for {grp}: {exc}") from exc
        cfg = publisher.transporter_config()
        now_us = self._ctx.clock.now_micro()
        stm = serialize_publication(data, copy, str(grp), numeric, now_us, cfg)
        self._record("publish", grp, copy.DESCRIPTOR.full_name)
        if cfg.intervehicle.buffer.ack_required:
            self._listen()
            self._purge(now_us)
            self._pending[stm_key(stm)] = _Pending(copy, publisher.on_ack, publisher.on_expire, now_us)
        self._ip.publish(groups.modem_data_out, stm, record=False)
        if grp.name:
            self._ip.publish(grp, copy, scheme=Scheme.DCCL, record=False)
            self._ip.publish(grp, copy, scheme=Scheme.PROTOBUF, record=False)

    # ----------------------------------------------------------------------------------------- subscribe
    def subscribe(self, group: GroupLike, msg_type: type[Message], callback: Callable[[Any], None],
                  subscriber: Subscriber | None = None) -> None:
        """Call ``callback(msg)`` on the owning thread for each ``msg_type`` received over a link whose derived group
        (``subscriber.group(msg)``, else the broadcast group) equals ``group``; the Subscription is sent to
        ``cfg.intervehicle.publisher_id``. A second subscribe to the same (type, group) replaces the first."""
        subscriber = subscriber if subscriber is not None else Subscriber()
        grp, numeric = _numeric_group(group, InvalidSubscriptionError, subscriber.group is not None, lambda grp: (
            f"subscribing to {msg_type.DESCRIPTOR.full_name} on intervehicle group {grp} needs a Subscriber with "
            "a group function: DCCL messages do not carry a group"))
        cfg = subscriber.transporter_config()
        if cfg.intervehicle.broadcast and cfg.intervehicle.buffer.ack_required:
            raise InvalidSubscriptionError(f"subscription to {grp}: broadcast with ack_required is not allowed")
        try:
            dccl_id = self._ctx.dccl.load(msg_type).dccl_id
        except DcclError as exc:
            raise InvalidSubscriptionError(f"{msg_type.DESCRIPTOR.full_name} is not a DCCL message: {exc}") from exc
        if dccl_id is None:
            raise InvalidSubscriptionError(f"{msg_type.DESCRIPTOR.full_name} has no DCCL id")
        self._handlers.setdefault(dccl_id, {})[str(grp)] = _Handler(grp, msg_type, callback, subscriber)
        self._record("subscribe", grp, msg_type.DESCRIPTOR.full_name)
        sub = Subscription(api_version=groups.API_VERSION, action=Subscription.SUBSCRIBE, dccl_id=dccl_id,
                           group=numeric, time=self._ctx.clock.now_micro())
        sub.header.src = 0
        sub.header.dest.extend(cfg.intervehicle.publisher_id)
        sub.intervehicle.CopyFrom(cfg.intervehicle)
        self._subscriptions[(dccl_id, str(grp))] = sub
        self._listen()
        self._send_subscription(sub, subscriber)

    def _send_subscription(self, sub: Subscription, subscriber: Subscriber | None) -> None:
        sub.time = self._ctx.clock.now_micro()
        key = self._subscription_key(sub)
        if key is not None and subscriber is not None:
            self._pending[key] = _Pending(sub, subscriber.on_subscribed, subscriber.on_subscribe_expired, sub.time)
        handler = next((h for h in self._handlers.get(sub.dccl_id, {}).values()), None)
        outgoing = Subscription()
        outgoing.CopyFrom(sub)
        if handler is not None:
            outgoing.metadata.CopyFrom(metadata_for(handler.msg_type))
        self._ip.publish(groups.modem_subscription_forward_tx, outgoing, record=False)

    def resubscribe(self) -> int:
        """Send every subscription again (the vehicle's broker restarted); returns how many."""
        for (dccl_id, group_text), sub in self._subscriptions.items():
            handler = self._handlers.get(dccl_id, {}).get(group_text)
            self._send_subscription(sub, handler.options if handler is not None else None)
        return len(self._subscriptions)

    def _subscription_key(self, sub: Subscription) -> StmKey | None:
        """The identity of a Subscription as the link reports its ack/expire (src reset to 0, as Goby does)."""
        plain = Subscription()
        plain.CopyFrom(sub)
        plain.header.src = 0
        plain.ClearField("metadata")
        try:
            data = self._ctx.dccl.encode(plain)
        except DcclError:
            return None
        return (sub.time, int(Scheme.DCCL), Subscription.DESCRIPTOR.full_name, str(groups.subscription_forward),
                data)

    # ------------------------------------------------------------------------------------------ receive
    def _listen(self) -> None:
        if self._listening:
            return
        self._listening = True
        self._ip.subscribe(groups.modem_data_in, DCCLForwardedData, self._on_data_in, record=False)
        self._ip.subscribe(groups.modem_ack_in, AckMessagePair, self._on_ack, record=False)
        self._ip.subscribe(groups.modem_expire_in, ExpireMessagePair, self._on_expire, record=False)
        self._ip.subscribe(groups.subscription_report, SubscriptionReport, self._on_report, record=False)

    def _on_data_in(self, forwarded: DCCLForwardedData) -> None:
        for packet in forwarded.frame:
            handlers = self._handlers.get(packet.dccl_id)
            if not handlers:
                continue
            first = next(iter(handlers.values()))
            try:
                msg = self._ctx.dccl.decode(packet.data, first.msg_type)
            except DcclError as exc:
                log.error("%s: cannot decode DCCL id %d from modem %d: %s", self._thread_name, packet.dccl_id,
                          forwarded.header.src, exc)
                continue
            for handler in list(handlers.values()):
                derived = handler.options.group(msg) if handler.options.group is not None else Group("", 0)
                if derived != handler.group:
                    continue
                try:
                    handler.callback(msg)
                except Exception:
                    log.exception("%s: intervehicle subscriber callback for %s raised; continuing",
                                  self._thread_name, handler.group)
                if handler.options.republish and handler.group.name:
                    self._ip.publish(handler.group, msg, scheme=Scheme.PROTOBUF, record=False)
                    self._ip.publish(handler.group, msg, scheme=Scheme.DCCL, record=False)

    def _key_of(self, stm: SerializerTransporterMessage) -> StmKey:
        if stm.key.type == Subscription.DESCRIPTOR.full_name:
            try:
                sub = self._ctx.dccl.decode(stm.data, Subscription)
            except DcclError:
                return stm_key(stm)
            sub.time = stm.key.serialize_time
            key = self._subscription_key(sub)
            if key is not None:
                return key
        return stm_key(stm)

    def _on_ack(self, pair: AckMessagePair) -> None:
        """One ack per acking modem (a publication to several subscribers is acked by each), as Goby."""
        pending = self._pending.get(self._key_of(pair.serializer))
        if pending is None or pair.data.header.src in pending.acked_by:
            return
        pending.acked_by.add(pair.data.header.src)
        self._report(pending.on_ack, pending.msg, pair.data, "ack")

    def _on_expire(self, pair: ExpireMessagePair) -> None:
        pending = self._pending.get(self._key_of(pair.serializer))
        if pending is None or pending.expired:
            return
        pending.expired = True  # reported once; an ack from another link may still come
        self._report(pending.on_expire, pending.msg, pair.data, "expire")

    def _report(self, callback: Callable[[Any, Any], None] | None, msg: Any, data: Any, what: str) -> None:
        """Call a publisher's ack or expire callback, if it gave one; an exception in it is logged."""
        if callback is None:
            return
        try:
            callback(msg, data)
        except Exception:
            log.exception("%s: %s callback raised; continuing", self._thread_name, what)

    def _on_report(self, report: SubscriptionReport) -> None:
        """A report without ``changed`` announces a (re)started link: send our subscriptions again."""
        if not report.HasField("changed") and self._subscriptions:
            log.info("%s: link %d (re)started; sending %d subscription(s) again", self._thread_name,
                     report.link_modem_id, len(self._subscriptions))
            self.resubscribe()

    # ------------------------------------------------------------------------------------------- misc
    def _purge(self, now_us: int) -> None:
        old = [k for k, p in self._pending.items() if now_us - p.serialize_time > PENDING_PURGE_US]
        for k in old:
            del self._pending[k]

    def _record(self, direction: str, group: Group, type_name: str) -> None:
        self._ctx.registry.record(InterfaceEntry(LAYER, direction, str(group), "DCCL", type_name, self._thread_name,
                                                 self._ctx.application))

    @property
    def pending(self) -> int:
        """Publications (and subscriptions) waiting for an ack."""
        return len(self._pending)
