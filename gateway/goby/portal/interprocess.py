"""One thread's interprocess transporter: its own PUB and SUB sockets on the broker (our forwarder design).

Every thread that uses interprocess owns a PUB (connected to the broker's XSUB) and a SUB (connected to its
XPUB); callbacks run on that thread inside its poll.  The first portal in a process (the application's main
thread) runs Goby's hold handshake with the manager; until the hold is released every thread buffers its
publications.  A publication is also handed to interthread subscribers of the same group and type in this
process, as Goby's ``publish`` does.

Restarts (docs/portal.md "Broker restart"): the publishing socket is an XPUB, so it reads the subscriptions the
broker forwards to it and knows which of its publications have a subscriber.  After a reconnection a publication
whose subscription has not come back yet is refused (``publish`` returns False, counted); while connected, a small
probe that this thread publishes to itself through the broker confirms what went before it, and what is
unconfirmed when the connection drops is reported (``on_undelivered``).  This module is the socket layer: what the
XPUB has seen is kept by ``subscription_evidence``, what is unconfirmed by ``delivery_ledger``, and received frames
go to the subscribers through ``frame_dispatch``; the primary's hold requests come from ``hold_handshake`` (none
of these four holds a socket); a TCP portal asks the manager for moved ports through ``endpoint_requery``.  All of
it runs on the owning thread.
"""

from __future__ import annotations

import logging
import os
import re
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable
from typing import Any

import zmq

from gateway.goby.portal.context import ProcessContext
from gateway.goby.portal.delivery_ledger import MAX_UNCONFIRMED, DeliveryLedger
from gateway.goby.portal.endpoint_requery import EndpointRequery
from gateway.goby.portal.errors import ClosedError, WrongThreadError
from gateway.goby.portal.frame_dispatch import FrameDispatcher, RegexCallback, RegexSubscription, Subscription
from gateway.goby.portal.group import GroupLike, as_group, check_named
from gateway.goby.portal.hold_handshake import HoldHandshake
from gateway.goby.portal.identifier import EVERYTHING, encode_frame, make_identifier, thread_id, type_prefix
from gateway.goby.portal.interface_registry import InterfaceEntry
from gateway.goby.portal.interthread import type_key
from gateway.goby.portal.manager_client import request_endpoints
from gateway.goby.portal.marshalling import (
    Scheme,
    interprocess_scheme,
    scheme_to_string,
    serialize,
    type_name,
)
from gateway.goby.portal.monitor_events import recv_monitor_event
from gateway.goby.portal.subscription_evidence import LIVE, MISSING, RESUBSCRIBE_WAIT_S, SubscriptionEvidence
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.goby.protobuf.interprocess_zeromq_pb2 import ManagerResponse
from util.reactor import Mailbox

log = logging.getLogger(__name__)

LAYER = "interprocess"
#: How long ``publish`` waits for room when the PUB queue toward the broker is full before dropping (logged).
SEND_BLOCK_S = 1.0
PROBE_GROUP = "goby::zeromq::_internal_delivery_probe"  # not in Goby3: each portal publishes it to itself
RECV_BATCH = 512


class InterProcessPortal:
    """Publish/subscribe through the broker from the owning thread; not thread-safe (use ``call_soon``)."""

    def __init__(self, context: ProcessContext, mailbox: Mailbox, thread_name: str) -> None:
        self._ctx = context
        self._cfg: InterProcessPortalConfig = context.interprocess_cfg
        self._mailbox = mailbox
        self._thread_name = thread_name
        self._pid = os.getpid()
        self._thread_hex = thread_id()
        self._owner = threading.get_ident()
        self._frames = FrameDispatcher(thread_name, self._pid, lambda: context.dccl, log)
        self._subs = self._frames.subs
        self._regex = self._frames.regex
        self._held: deque[bytes] = deque()
        self._identifiers: dict[tuple[str, int, str], str] = {}
        self._groups: dict[GroupLike, str] = {}
        self._types: dict[tuple[type, int | None], tuple[int, str, str]] = {}
        self._closed = False
        self.dropped = 0
        self.refused = 0  # publications refused: no connection, or their subscription not back yet (returned False)
        self.in_doubt = 0  # publications reported undelivered: not confirmed by a probe when the connection dropped
        self.on_undelivered: Callable[[list[tuple[str, bytes]]], None] | None = None
        self._topics = SubscriptionEvidence()  # what our XPUB knows: publications are classified against it
        self._ledger = DeliveryLedger()  # publications sent to a live topic and not yet confirmed by a probe
        zctx = context.zmq_context
        self._pub_endpoint, self._sub_endpoint, _ = request_endpoints(zctx, self._cfg, context.client_name)
        self._pub = zctx.socket(zmq.XPUB)  # a PUB that also hands us the subscriptions it receives
        self._sub = zctx.socket(zmq.SUB)
        for sock in (self._pub, self._sub):
            sock.setsockopt(zmq.SNDHWM, self._cfg.send_queue_size)
            sock.setsockopt(zmq.RCVHWM, self._cfg.receive_queue_size)
            sock.setsockopt(zmq.IPV6, 1)
        self._pub.setsockopt(zmq.XPUB_NODROP, 1)  # a full queue is reported to us instead of dropping silently
        # Every subscription the broker forwards reaches us, even one our XPUB already holds: after a quick broker
        # restart the new connection's subscriptions can arrive before ZeroMQ has retired the dead one, and a
        # non-verbose XPUB would then swallow them as duplicates, leaving the topic missing for RESUBSCRIBE_WAIT_S.
        self._pub.setsockopt(zmq.XPUB_VERBOSE, 1)
        # No queue toward a broker that is not there: a new connection starts with no subscriptions, so what we
        # learn from the new broker is all there is (a kept queue would keep the dead broker's subscriptions).
        self._pub.setsockopt(zmq.IMMEDIATE, 1)
        self._pub.setsockopt(zmq.LINGER, 500)  # flush what was published just before exit
        self._sub.setsockopt(zmq.LINGER, 0)
        self._monitor = self._pub.get_monitor_socket(zmq.EVENT_CONNECTED | zmq.EVENT_DISCONNECTED)
        self._ever_connected = False
        self._disconnected = False
        self.on_pollable: Callable[[zmq.Socket, bool], None] | None = None  # the owner's poller: (socket, add?)
        self._requery = EndpointRequery(zctx, self._cfg, context.client_name, thread_name, self._pollable_changed, log)
        self._probe_ident = make_identifier(PROBE_GROUP, Scheme.CSTR, "CSTR", self._pid, self._thread_hex)
        self._probe_head = self._probe_ident.encode()
        self._probe_prefix = type_prefix(PROBE_GROUP, Scheme.CSTR, "CSTR").encode()
        self._sub.setsockopt(zmq.SUBSCRIBE, self._probe_head)
        self._pub.connect(self._pub_endpoint)
        self._sub.connect(self._sub_endpoint)
        self._primary = context.claim_primary()
        self._hold = HoldHandshake(context.client_name, self._pid, self._thread_hex, context.hold_settle_s)
        self._hold_response_prefix = self._hold.response_prefix
        if self._primary and not context.hold_released:
            self._sub.setsockopt(zmq.SUBSCRIBE, self._hold_response_prefix)
        context.register_mailbox(mailbox)
        log.debug("%s: interprocess portal connected (pub %s, sub %s, primary=%s)",
                  thread_name, self._pub_endpoint, self._sub_endpoint, self._primary)

    # ----------------------------------------------------------------------------------------- publish
    def publish(self, group: GroupLike, msg: Any, *, scheme: int | None = None, record: bool = True) -> bool:
        """Serialize ``msg`` and send it to every subscriber of (group, type) in all processes, this one included.

        ``record=False``: the call is made by a transporter on behalf of another layer (intervehicle), which records
        its own call; the interface registry does not list it as an interprocess publication.
        Returns False (and counts it in ``refused``, logged) when the broker connection is down, so it cannot go
        to other processes; this process's own subscribers still get it. See docs/portal.md "Broker restart".
        """
        self._check_open()
        group_text = self._group_text(group)
        sch, tname, key = self._type_info(type(msg), scheme)
        sent = self._publish_frame(group_text, sch, tname, serialize(msg, sch, self._ctx.dccl if sch == Scheme.DCCL else None), record)
        self._ctx.interthread.deliver(group_text, key, msg, self._mailbox)
        return sent

    def _group_text(self, group: GroupLike) -> str:
        """The validated wire string of ``group`` (cached: publishing is the hot path)."""
        text = self._groups.get(group)
        if text is None:
            grp = as_group(group)
            check_named(grp, "InterProcess")
            text = self._groups[group] = str(grp)
        return text

    def _type_info(self, msg_type: type, scheme: int | None) -> tuple[int, str, str]:
        """(scheme, wire type name, interthread key) for a type; a default of DCCL becomes PROTOBUF as in Goby
        (an explicit ``scheme=Scheme.DCCL`` sends the DCCL bytes)."""
        info = self._types.get((msg_type, scheme))
        if info is None:
            sch = interprocess_scheme(msg_type) if scheme is None else int(scheme)
            info = self._types[(msg_type, scheme)] = (sch, type_name(msg_type, sch), type_key(msg_type))
        return info

    def publish_serialized(self, group: GroupLike, scheme: int, type_name_: str, payload: bytes) -> bool:
        """Send an already-encoded payload (gateways relaying data whose class is not imported); as ``publish``."""
        self._check_open()
        grp = as_group(group)
        check_named(grp, "InterProcess")
        return self._publish_frame(str(grp), int(scheme), type_name_, payload)

    def _publish_frame(self, group: str, scheme: int, tname: str, payload: bytes, record: bool = True) -> bool:
        key = (group, scheme, tname)
        ident = self._identifiers.get(key)
        if ident is None:
            ident = make_identifier(group, scheme, tname, self._pid, self._thread_hex)
            self._identifiers[key] = ident
            if record:
                self._record("publish", group, scheme, tname)
        frame = encode_frame(ident, payload)
        if not self._ctx.hold_released:
            self._held.append(frame)
            return True
        kind = self._topics.classify(ident)
        if self._disconnected or kind == MISSING:
            self._refuse(group)
            return False
        if self._held:
            self._flush_held()
        sent = self._send(frame)
        if sent and kind == LIVE:
            now = time.monotonic()
            ledger = self._ledger
            if ledger.record(group, payload, now):
                self._send_probe(now)
            if ledger.assumed_delivered == 1:
                log.warning("%s: over %d publications unconfirmed (no probe came back): the oldest are assumed "
                            "delivered", self._thread_name, MAX_UNCONFIRMED)
        return sent

    def _refuse(self, group: str) -> None:
        self.refused += 1
        if self.refused == 1 or self.refused % 100 == 0:
            why = ("the broker connection is down" if self._disconnected
                   else "its subscriber has not subscribed again since the broker came back")
            log.error("%s: publication on %s refused: %s (%d refused so far)",
                      self._thread_name, group, why, self.refused)

    def _send(self, frame: bytes) -> bool:
        try:
            self._pub.send(frame, zmq.NOBLOCK)
            return True
        except zmq.Again:
            pass
        # The queue toward the broker is full.  POLLOUT on a PUB socket reports writable even then, so wait by
        # retrying: this back-pressure is the broker not keeping up (slow subscribers never cause it).
        deadline = time.monotonic() + SEND_BLOCK_S
        pause = 0.0001
        while time.monotonic() < deadline:
            time.sleep(pause)
            pause = min(pause * 2, 0.01)
            try:
                self._pub.send(frame, zmq.NOBLOCK)
                return True
            except zmq.Again:
                continue
        self.dropped += 1
        log.error(
            "%s: dropped a publication (%s): the send queue to the broker stayed full for %.1f s "
            "(send_queue_size=%d); %d dropped so far",
            self._thread_name, frame[: frame.find(b"\0")].decode(errors="replace"), SEND_BLOCK_S,
            self._cfg.send_queue_size, self.dropped,
        )
        return False

    def _flush_held(self) -> None:
        count = len(self._held)
        while self._held:
            self._send(self._held.popleft())
        log.debug("%s: hold released, sent %d buffered publication(s)", self._thread_name, count)

    # --------------------------------------------------------------------------------------- subscribe
    def subscribe(
        self, group: GroupLike, msg_type: type, callback: Callable[[Any], None], *, scheme: int | None = None,
        echo: bool = True, record: bool = True,
    ) -> None:
        """Call ``callback(msg)`` on the owning thread for each ``msg_type`` published on ``group`` by any process.

        ``echo=False`` drops this process's own publications (Goby delivers them: the default is ``True``);
        ``record=False`` as for :meth:`publish`.
        """
        self._check_open()
        group_text = self._group_text(group)
        sch, tname, _ = self._type_info(msg_type, scheme)
        prefix = type_prefix(group_text, sch, tname).encode()
        if record:
            self._record("subscribe", group_text, sch, tname)
        if prefix not in self._subs:
            self._subs[prefix] = []
            self._sub.setsockopt(zmq.SUBSCRIBE, prefix)
        self._subs[prefix].append(Subscription(msg_type, sch, callback, echo, group_text))

    def unsubscribe(self, group: GroupLike, msg_type: type, *, scheme: int | None = None) -> None:
        """Remove this thread's subscriptions to (group, msg_type)."""
        self._check_open()
        sch, tname, _ = self._type_info(msg_type, scheme)
        prefix = type_prefix(self._group_text(group), sch, tname).encode()
        if self._subs.pop(prefix, None) is not None:
            self._sub.setsockopt(zmq.UNSUBSCRIBE, prefix)

    def unsubscribe_all(self) -> None:
        """Remove every subscription of this thread, regex ones included."""
        self._check_open()
        for prefix in list(self._subs):
            self._sub.setsockopt(zmq.UNSUBSCRIBE, prefix)
        self._subs.clear()
        if self._regex:
            self._regex.clear()
            self._sub.setsockopt(zmq.UNSUBSCRIBE, EVERYTHING)

    def subscribe_regex(
        self,
        callback: RegexCallback,
        group_regex: str = ".*",
        type_regex: str = ".*",
        schemes: Iterable[int] = (Scheme.ALL_SCHEMES,),
    ) -> None:
        """Call ``callback(payload, scheme, type_name, group)`` on the owning thread for every publication whose
        group and type *fully* match the regexes (``re.fullmatch``, as ``std::regex_match``) and whose scheme is in
        ``schemes``.  ``payload`` is the raw bytes; decode with ``marshalling.parse_dynamic`` if needed."""
        self._check_open()
        scheme_set = frozenset(int(s) for s in schemes)
        self._record("subscribe", f"regex:{group_regex}", Scheme.ALL_SCHEMES, f"regex:{type_regex}")
        if not self._regex:
            self._sub.setsockopt(zmq.SUBSCRIBE, EVERYTHING)
        self._regex.append(RegexSubscription(callback, re.compile(group_regex), re.compile(type_regex), scheme_set))

    def subscribe_type_regex(
        self, group: GroupLike, callback: RegexCallback, type_regex: str = ".*", scheme: int = Scheme.PROTOBUF
    ) -> None:
        """Regex subscription on one group (escaped) for every type matching ``type_regex``; ``callback`` runs on the
        owning thread, as for :meth:`subscribe_regex`."""
        self.subscribe_regex(callback, re.escape(str(as_group(group))), type_regex, (scheme,))

    # ------------------------------------------------------------------------------------------- hold
    def ready(self) -> None:
        """Tell the manager this process has made the subscriptions it needs (releases holds waiting on it)."""
        self._ctx.ready_flag = True

    def hold_state(self) -> bool:
        """True while publications are buffered waiting for the manager's hold release."""
        return not self._ctx.hold_released

    # ------------------------------------------------------------------------------ owner-thread plumbing
    def pollables(self) -> list[zmq.Socket]:
        """Sockets the owning thread's poller must watch (a manager query adds its own through ``on_pollable``)."""
        sockets = [self._sub, self._pub, self._monitor]
        if self._requery.socket is not None:
            sockets.append(self._requery.socket)
        return sockets

    def _pollable_changed(self, sock: zmq.Socket, add: bool) -> None:
        if self.on_pollable is not None:
            self.on_pollable(sock, add)

    def handle(self, sock: zmq.Socket) -> int:
        """Process what is readable on ``sock``; returns the number of events handled."""
        if sock is self._sub:
            return self._receive()
        if sock is self._pub:
            # The monitor first: a dropped connection is announced there before ZeroMQ withdraws the dead
            # broker's subscriptions from our XPUB, so those withdrawals are known to be the crash.
            return self._handle_monitor() + self._read_subscriptions()
        if sock is self._monitor:
            return self._handle_monitor()
        if sock is self._requery.socket:
            events, endpoints = self._requery.finish()
            if endpoints is not None and endpoints != (self._pub_endpoint, self._sub_endpoint):
                self._reconnect_to(*endpoints)
            return events
        return 0

    def _read_subscriptions(self) -> int:
        """The (un)subscriptions the broker forwarded to our XPUB: which topics have a subscriber."""
        count = 0
        while True:
            try:
                msg = self._pub.recv(zmq.NOBLOCK)
            except zmq.Again:
                break
            count += 1
            if self._topics.on_subscription_message(msg):
                log.info("%s: every subscription seen before the broker restart is back", self._thread_name)
        return count

    def service(self, now: float) -> int:
        """Timed work: hold requests while holding (primary only), flushing buffered publications once released,
        delivery probes, giving up on subscriptions that did not come back, TCP manager queries."""
        events = 0
        if self._primary and not self._ctx.hold_released:
            request = self._hold.request_due(now, self._ctx.ready_flag)
            if request is not None:
                try:
                    self._pub.send(request, zmq.NOBLOCK)
                except zmq.Again:
                    log.debug("%s: hold request not sent (queue full); retrying", self._thread_name)
            elif self._hold.released(now):
                self._sub.setsockopt(zmq.UNSUBSCRIBE, self._hold_response_prefix)
                log.info("%s: hold released by the manager", self._thread_name)
                self._ctx.release_hold()
                events += 1
        if self._held and self._ctx.hold_released:
            self._flush_held()
            events += 1
        if self._requery.due_at is not None and now >= self._requery.due_at:
            self._requery.start(now)
        if self._ledger.probe_due(now):
            self._send_probe(now)
        if not self._disconnected:
            gone = self._topics.give_up(now)
            if gone:
                log.warning("%s: %d subscription(s) seen before the broker restart did not come back within %.1f s; "
                            "publishing to them again as to any topic without subscribers: %s", self._thread_name,
                            len(gone), RESUBSCRIBE_WAIT_S, [t.decode(errors="replace") for t in gone])
        return events

    def _send_probe(self, now: float) -> None:
        """Publish a probe to ourselves through the broker: when it comes back, everything sent before it has
        passed the broker (one PUB → XSUB → XPUB path, in order)."""
        if self._disconnected or self._topics.classify(self._probe_ident) != LIVE:
            self._ledger.probe_not_sent(now)  # our own probe subscription is not through yet: try again later
            return
        try:
            self._pub.send(encode_frame(self._probe_ident, self._ledger.next_probe()), zmq.NOBLOCK)
        except zmq.Again:
            self._ledger.probe_not_sent(now)
            return
        self._ledger.probe_sent(now)

    def _reconnect_to(self, pub: str, sub: str) -> None:
        """Move both sockets to the endpoints the manager gave (ZeroMQ would retry the old ports forever)."""
        log.warning("%s: broker moved to publish %s / subscribe %s; reconnecting", self._thread_name, pub, sub)
        for sock, old, new in ((self._pub, self._pub_endpoint, pub), (self._sub, self._sub_endpoint, sub)):
            try:
                sock.disconnect(old)
            except zmq.ZMQError:
                pass
            sock.connect(new)
        self._pub_endpoint, self._sub_endpoint = pub, sub

    def next_deadline(self) -> float | None:
        """The monotonic time ``service`` next needs to run, if any."""
        deadlines = [] if self._requery.due_at is None else [self._requery.due_at]
        if self._primary and not self._ctx.hold_released:
            deadlines.append(self._hold.deadline())
        for deadline in (self._ledger.deadline(), None if self._disconnected else self._topics.deadline()):
            if deadline is not None:
                deadlines.append(deadline)
        return min(deadlines) if deadlines else None

    def _on_manager_response(self, payload: bytes) -> None:
        try:
            response = ManagerResponse.FromString(payload)
        except Exception as exc:  # noqa: BLE001
            log.error("%s: malformed ManagerResponse: %s", self._thread_name, exc)
            return
        self._hold.on_response(response, time.monotonic())

    def _receive(self) -> int:
        count = 0
        sub = self._sub
        while count < RECV_BATCH:
            try:
                frame = sub.recv(zmq.NOBLOCK, copy=True)
            except zmq.Again:
                break
            count += 1
            self._dispatch(frame)
        return count

    def _dispatch(self, frame: bytes) -> None:
        split = self._frames.split(frame)
        if split is None:
            return
        head, ident, prefix, payload = split
        if prefix == self._probe_prefix:  # a delivery probe: ours confirms, others' (regex subscribers) are dropped
            if head == self._probe_head:
                now = time.monotonic()
                if self._ledger.confirm(payload, now):
                    self._send_probe(now)
            return
        if prefix == self._hold_response_prefix and self._primary:
            self._on_manager_response(payload)
        self._frames.deliver(ident, prefix, payload)

    def _handle_monitor(self) -> int:
        count = 0
        while True:
            try:
                event = recv_monitor_event(self._monitor, zmq.NOBLOCK)
            except zmq.Again:
                return count
            count += 1
            if event is None:
                continue
            kind = event.event
            if kind == zmq.EVENT_DISCONNECTED and not self._disconnected:
                self._disconnected = True
                self._topics.connection_lost()
                self._report_in_doubt()
                if self._cfg.transport == InterProcessPortalConfig.TCP:
                    self._requery.start(time.monotonic())
                log.warning("%s: lost connection to the broker (%s); ZeroMQ will reconnect and resubscribe",
                            self._thread_name, self._pub_endpoint)
            elif kind == zmq.EVENT_CONNECTED:
                if self._disconnected:
                    log.warning("%s: reconnected to the broker (%s); %d subscription(s) restored; publications to "
                                "the %d topic(s) that had subscribers wait for them to subscribe again",
                                self._thread_name, self._pub_endpoint, len(self._subs) + len(self._regex),
                                len(self._topics.missing))
                    self._topics.reconnected(time.monotonic())
                self._disconnected = False
                self._ever_connected = True
                self._requery.cancel()

    def _report_in_doubt(self) -> None:
        """The connection dropped: what no probe has confirmed may have died in the broker (or after it)."""
        lost = self._ledger.in_doubt()
        if not lost:
            return
        self.in_doubt += len(lost)
        log.warning("%s: %d publication(s) not yet confirmed through the broker when the connection dropped may "
                    "be lost; reported undelivered", self._thread_name, len(lost))
        if self.on_undelivered is not None:
            try:
                self.on_undelivered(lost)
            except Exception:
                log.exception("%s: on_undelivered callback raised", self._thread_name)

    # ---------------------------------------------------------------------------------------- misc
    def _record(self, direction: str, group: str, scheme: int, tname: str) -> None:
        self._ctx.registry.record(
            InterfaceEntry(LAYER, direction, group, scheme_to_string(scheme), tname, self._thread_name,
                           self._ctx.application)
        )

    def _check_open(self) -> None:
        if self._closed:
            raise ClosedError(f"interprocess portal of {self._thread_name} is closed")
        if threading.get_ident() != self._owner:
            raise WrongThreadError(
                f"interprocess portal of {self._thread_name} used from thread {threading.current_thread().name!r}; "
                "ZeroMQ sockets belong to their thread: hand the work over with call_soon()"
            )

    @property
    def malformed(self) -> int:
        """Frames dropped as malformed (logged: the first ten, then every thousandth)."""
        return self._frames.malformed

    @property
    def connected(self) -> bool:
        """True once the SUB socket is connected to the broker and not known to be disconnected."""
        return self._ever_connected and not self._disconnected

    def close(self) -> None:
        """Close the sockets; publications still buffered by the hold are reported, not silently lost."""
        if self._closed:
            return
        self._closed = True
        if self._held:
            log.warning("%s: closing with %d publication(s) still held (hold never released)",
                        self._thread_name, len(self._held))
        if self._primary and not self._ctx.hold_released:
            self._ctx.release_hold()  # do not leave the other threads buffering forever
        try:
            self._sub.disable_monitor()
        except zmq.ZMQError:
            pass
        self._monitor.close(linger=0)
        self._requery.drop()
        self._sub.close(linger=0)
        self._pub.close()
