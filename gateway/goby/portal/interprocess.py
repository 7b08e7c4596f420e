"""One thread's interprocess transporter: its own PUB and SUB sockets on the broker (our forwarder design).

Every thread that uses interprocess owns a PUB (connected to the broker's XSUB) and a SUB (connected to its
XPUB); callbacks run on that thread inside its poll.  The first portal in a process (the application's main
thread) runs Goby's hold handshake with the manager; until the hold is released every thread buffers its
publications.  A publication is also handed to interthread subscribers of the same group and type in this
process, as Goby's ``publish`` does.
"""

from __future__ import annotations

import logging
import os
import re
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import zmq

from gateway.goby.portal.context import ProcessContext
from gateway.goby.portal.endpoints import MANAGER_REQUEST_GROUP, MANAGER_RESPONSE_GROUP
from gateway.goby.portal.errors import ClosedError, IdentifierError, MarshallingError, WrongThreadError
from gateway.goby.portal.group import GroupLike, as_group, check_named
from gateway.goby.portal.identifier import (
    EVERYTHING,
    Identifier,
    decode_frame,
    encode_frame,
    make_identifier,
    thread_id,
    type_prefix,
)
from gateway.goby.portal.interface_registry import InterfaceEntry
from gateway.goby.portal.interthread import type_key
from gateway.goby.portal.mailbox import Mailbox
from gateway.goby.portal.manager_client import request_endpoints
from gateway.goby.portal.marshalling import (
    Scheme,
    interprocess_scheme,
    parse,
    scheme_to_string,
    serialize,
    type_name,
)
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.goby.protobuf.interprocess_zeromq_pb2 import PROVIDE_HOLD_STATE, ManagerRequest, ManagerResponse

log = logging.getLogger(__name__)

LAYER = "interprocess"
HOLD_REQUEST_PERIOD_S = 0.1
#: How long ``publish`` waits for room when the PUB queue toward the broker is full before dropping (logged).
SEND_BLOCK_S = 1.0
IN_DOUBT_S = 0.5  # publications this recent when the broker connection drops may have died with it
RESUBSCRIBE_SETTLE_S = 0.5  # after a reconnection, time for the subscribers' subscriptions to reach our PUB
RECV_BATCH = 512
HEAD_CACHE_SIZE = 4096  # distinct identifiers remembered as already validated

RegexCallback = Callable[[bytes, int, str, str], None]


@dataclass(eq=False)
class _Subscription:
    msg_type: type
    scheme: int
    callback: Callable[[Any], None]
    echo: bool
    group: str


@dataclass(eq=False)
class _RegexSubscription:
    callback: RegexCallback
    group_re: re.Pattern[str]
    type_re: re.Pattern[str]
    schemes: frozenset[int]


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
        self._subs: dict[bytes, list[_Subscription]] = {}
        self._regex: list[_RegexSubscription] = []
        self._held: deque[bytes] = deque()
        self._identifiers: dict[tuple[str, int, str], str] = {}
        self._groups: dict[GroupLike, str] = {}
        self._types: dict[tuple[type, int | None], tuple[int, str, str]] = {}
        self._heads: dict[bytes, tuple[Identifier, bytes]] = {}
        self._closed = False
        self.dropped = 0
        self.malformed = 0
        self.refused = 0  # publications refused because the broker connection was down (publish returned False)
        self.in_doubt = 0  # publications reported undelivered: sent just before the connection dropped
        self.on_undelivered: Callable[[list[tuple[str, bytes]]], None] | None = None
        self._recent: deque[tuple[float, str, bytes]] = deque()  # (sent at, group, payload), the last IN_DOUBT_S
        self._settle_until = 0.0
        zctx = context.zmq_context
        self._pub_endpoint, self._sub_endpoint, _ = request_endpoints(zctx, self._cfg, context.client_name)
        self._pub = zctx.socket(zmq.PUB)
        self._sub = zctx.socket(zmq.SUB)
        for sock in (self._pub, self._sub):
            sock.setsockopt(zmq.SNDHWM, self._cfg.send_queue_size)
            sock.setsockopt(zmq.RCVHWM, self._cfg.receive_queue_size)
            sock.setsockopt(zmq.IPV6, 1)
        self._pub.setsockopt(zmq.XPUB_NODROP, 1)  # a full queue is reported to us instead of dropping silently
        self._pub.setsockopt(zmq.LINGER, 500)  # flush what was published just before exit
        self._sub.setsockopt(zmq.LINGER, 0)
        self._monitor = self._sub.get_monitor_socket(zmq.EVENT_CONNECTED | zmq.EVENT_DISCONNECTED)
        self._ever_connected = False
        self._disconnected = False
        self._requery_at: float | None = None  # TCP: when to ask the manager for (possibly new) ports
        self._pub.connect(self._pub_endpoint)
        self._sub.connect(self._sub_endpoint)
        self._primary = context.claim_primary()
        self._hold_response_prefix = type_prefix(
            MANAGER_RESPONSE_GROUP, Scheme.PROTOBUF, ManagerResponse.DESCRIPTOR.full_name
        ).encode()
        self._next_hold_request = 0.0
        self._release_at: float | None = None
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
        sent = self._publish_frame(group_text, sch, tname, serialize(msg, sch, self._ctx.dccl), record)
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
        now = time.monotonic()
        if self._disconnected or now < self._settle_until:
            self.refused += 1
            if self.refused == 1 or self.refused % 100 == 0:
                log.error("%s: publication on %s refused: the broker connection is down (%d refused so far)",
                          self._thread_name, group, self.refused)
            return False
        if self._held:
            self._flush_held()
        recent = self._recent
        recent.append((now, group, payload))
        while recent[0][0] < now - IN_DOUBT_S:
            recent.popleft()
        return self._send(frame)

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
        self._subs[prefix].append(_Subscription(msg_type, sch, callback, echo, group_text))

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
        self._regex.append(_RegexSubscription(callback, re.compile(group_regex), re.compile(type_regex), scheme_set))

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
        """Sockets the owning thread's poller must watch."""
        return [self._sub, self._monitor]

    def handle(self, sock: zmq.Socket) -> int:
        """Process what is readable on ``sock``; returns the number of events handled."""
        if sock is self._monitor:
            return self._handle_monitor()
        return self._receive()

    def service(self, now: float) -> int:
        """Timed work: hold requests while holding (primary only), flushing buffered publications once released."""
        events = 0
        if self._primary and not self._ctx.hold_released:
            if self._release_at is not None:
                if now >= self._release_at:
                    self._sub.setsockopt(zmq.UNSUBSCRIBE, self._hold_response_prefix)
                    log.info("%s: hold released by the manager", self._thread_name)
                    self._ctx.release_hold()
                    events += 1
            elif now >= self._next_hold_request:
                self._send_hold_request()
                self._next_hold_request = now + HOLD_REQUEST_PERIOD_S
        if self._held and self._ctx.hold_released:
            self._flush_held()
            events += 1
        if self._requery_at is not None and now >= self._requery_at:
            self._requery_endpoints(now)
        return events

    def _requery_endpoints(self, now: float) -> None:
        """TCP after a broker restart: the pub/sub ports are ephemeral, so ask the manager where they are now."""
        try:
            pub, sub, _ = request_endpoints(self._ctx.zmq_context, self._cfg, self._ctx.client_name, timeout_s=0.3)
        except Exception as exc:  # noqa: BLE001 - broker still down: try again later
            log.debug("%s: manager not answering yet (%s)", self._thread_name, exc)
            self._requery_at = now + 1.0
            return
        self._requery_at = None
        if (pub, sub) == (self._pub_endpoint, self._sub_endpoint):
            return
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
        deadline = self._requery_at
        if self._primary and not self._ctx.hold_released:
            hold = self._release_at if self._release_at is not None else self._next_hold_request
            deadline = hold if deadline is None else min(deadline, hold)
        return deadline

    def _send_hold_request(self) -> None:
        request = ManagerRequest(
            request=PROVIDE_HOLD_STATE, client_name=self._ctx.client_name, client_pid=self._pid,
            ready=self._ctx.ready_flag,
        )
        ident = make_identifier(
            MANAGER_REQUEST_GROUP, Scheme.PROTOBUF, ManagerRequest.DESCRIPTOR.full_name, self._pid, self._thread_hex
        )
        try:
            self._pub.send(encode_frame(ident, request.SerializeToString()), zmq.NOBLOCK)
        except zmq.Again:
            log.debug("%s: hold request not sent (queue full); retrying", self._thread_name)

    def _on_manager_response(self, payload: bytes) -> None:
        try:
            response = ManagerResponse.FromString(payload)
        except Exception as exc:  # noqa: BLE001
            log.error("%s: malformed ManagerResponse: %s", self._thread_name, exc)
            return
        if (response.request == PROVIDE_HOLD_STATE and response.client_pid == self._pid
                and response.client_name == self._ctx.client_name and not response.hold
                and self._release_at is None):
            self._release_at = time.monotonic() + self._ctx.hold_settle_s

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
        nul = frame.find(b"\0")
        if nul < 0:
            self._malformed(frame, "frame has no /group/scheme/type/pid/thread/ identifier followed by NUL")
            return
        head = frame[:nul]
        known = self._heads.get(head)
        if known is None:  # first frame from this (group, scheme, type, process, thread): validate it once
            try:
                ident, _ = decode_frame(frame)
            except IdentifierError as exc:
                self._malformed(frame, str(exc))
                return
            cut = head.find(b"/", head.find(b"/", head.find(b"/", 1) + 1) + 1)  # fourth '/'
            known = (ident, head[: cut + 1])
            if len(self._heads) >= HEAD_CACHE_SIZE:
                self._heads.clear()
            self._heads[head] = known
        ident, prefix = known
        payload = frame[nul + 1:]
        subs = self._subs.get(prefix)
        if prefix == self._hold_response_prefix and self._primary:
            self._on_manager_response(payload)
        if subs:
            own = ident.pid == self._pid
            parsed: dict[type, Any] = {}
            for sub in list(subs):
                if own and not sub.echo:
                    continue
                msg = parsed.get(sub.msg_type)
                if msg is None:
                    try:
                        msg = parse(payload, sub.scheme, sub.msg_type, self._ctx.dccl)
                    except MarshallingError as exc:
                        log.error("%s: cannot decode publication on %s (%s): %s", self._thread_name, ident.group,
                                  ident.type_name, exc)
                        return
                    parsed[sub.msg_type] = msg
                try:
                    sub.callback(msg)
                except Exception:
                    log.exception("%s: subscriber callback for %s (%s) raised; continuing", self._thread_name,
                                  ident.group, ident.type_name)
        for rsub in list(self._regex):
            if ((Scheme.ALL_SCHEMES in rsub.schemes or ident.scheme in rsub.schemes)
                    and rsub.type_re.fullmatch(ident.type_name) and rsub.group_re.fullmatch(ident.group)):
                try:
                    rsub.callback(payload, ident.scheme, ident.type_name, ident.group)
                except Exception:
                    log.exception("%s: regex subscriber callback raised; continuing", self._thread_name)

    def _malformed(self, frame: bytes, why: str) -> None:
        self.malformed += 1
        if self.malformed > 10 and self.malformed % 1000:
            return  # a flood: log the first ten, then every thousandth (the count says how many)
        log.error("%s: dropping malformed frame (%d so far): %s: %r", self._thread_name, self.malformed, why,
                  frame[:80])

    def _handle_monitor(self) -> int:
        from zmq.utils.monitor import recv_monitor_message

        count = 0
        while True:
            try:
                event = recv_monitor_message(self._monitor, zmq.NOBLOCK)
            except zmq.Again:
                return count
            count += 1
            kind = event["event"]
            if kind == zmq.EVENT_DISCONNECTED:
                self._disconnected = True
                self._report_in_doubt()
                if self._cfg.transport == InterProcessPortalConfig.TCP:
                    self._requery_at = time.monotonic() + 1.0
                log.warning("%s: lost connection to the broker (%s); ZeroMQ will reconnect and resubscribe",
                            self._thread_name, self._sub_endpoint)
            elif kind == zmq.EVENT_CONNECTED:
                if self._disconnected:
                    log.warning("%s: reconnected to the broker (%s); %d subscription(s) restored",
                                self._thread_name, self._sub_endpoint, len(self._subs) + len(self._regex))
                    self._settle_until = time.monotonic() + RESUBSCRIBE_SETTLE_S
                self._disconnected = False
                self._ever_connected = True
                self._requery_at = None

    def _report_in_doubt(self) -> None:
        """The connection dropped: what was sent in the last IN_DOUBT_S may have died in the broker."""
        cutoff = time.monotonic() - IN_DOUBT_S
        lost = [(group, payload) for sent_at, group, payload in self._recent if sent_at >= cutoff]
        self._recent.clear()
        if not lost:
            return
        self.in_doubt += len(lost)
        log.warning("%s: %d publication(s) sent in the last %.1f s before the broker connection dropped may be "
                    "lost; reported undelivered", self._thread_name, len(lost), IN_DOUBT_S)
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
        self._sub.close(linger=0)
        self._pub.close()
