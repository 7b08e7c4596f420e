"""The broker's input bounds: ZeroMQ socket options plus a cap on connected peers per listening socket.

ZeroMQ bounds one frame (``MAXMSGSIZE``) and the time to finish the greeting (``HANDSHAKE_IVL``) but has no
"max connections" option, so unfinished frames on many connections add up without limit.  The cap is enforced
with ZeroMQ's own admission hook, ZAP: each socket gets a ``ZAP_DOMAIN``, every handshake asks the broker's ZAP
handler, and a peer is refused (ZMTP ERROR; libzmq retries every 100 ms) while the socket holds ``max_connections``
handshaken peers.  Peers that never finish the greeting are not counted (they cannot hold frames, and
``HANDSHAKE_IVL`` drops them), so a flood of half-open connections does not lock real clients out.

Counting without knowing which connection a ZAP request belongs to (libzmq 4.3 reports no descriptor with
``HANDSHAKE_SUCCEEDED``): a connection still open ``handshake_s`` + a margin after ``ACCEPTED`` has finished its
handshake (else ZeroMQ would have dropped it); a younger one counts only up to the number of peers approved in
that window.  The estimate never undercounts, so the cap holds.

Not thread safe: :class:`Admission` lives on the broker's manager thread, whose reactor reads the ZAP and monitor
sockets.
"""

from __future__ import annotations

import logging
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import zmq

from gateway.goby.portal.monitor_events import parse_monitor_frames

log = logging.getLogger(__name__)

ZAP_ENDPOINT = "inproc://zeromq.zap.01"  # fixed by the ZAP specification (RFC 27), one per context
_MONITORED = zmq.EVENT_ACCEPTED | zmq.EVENT_DISCONNECTED
_MARGIN_S = 2.0  # ZeroMQ's handshake timer may fire late on a loaded machine


@dataclass(frozen=True)
class BrokerLimits:
    """Every input bound of the broker; the worst case of unfinished input is
    ``max_connections * (max_message_bytes + 2 * max_control_bytes)`` (docs/reliability.md "Memory bounds")."""

    max_message_bytes: int = 4 * 1024 * 1024  # one frame on the publishers' socket (XSUB)
    max_control_bytes: int = 64 * 1024  # one frame on the subscribers' socket (subscriptions) and the manager
    max_connections: int = 64  # handshaken peers per listening socket
    handshake_s: float = 3.0  # ZMQ_HANDSHAKE_IVL (ZeroMQ's default is 30 s)
    heartbeat_s: float = 1.0  # ZMQ_HEARTBEAT_IVL: a PING every second ...
    heartbeat_timeout_s: float = 10.0  # ... and a peer with no whole message for this long is dropped

    def __post_init__(self) -> None:
        for name in ("max_message_bytes", "max_control_bytes", "max_connections"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"BrokerLimits.{name} must be >= 1, got {getattr(self, name)}")
        for name in ("handshake_s", "heartbeat_s", "heartbeat_timeout_s"):
            if not 0.001 <= float(getattr(self, name)) < 1e6:
                raise ValueError(f"BrokerLimits.{name} must be a finite number of seconds >= 0.001")


def apply_limits(sock: zmq.Socket, limits: BrokerLimits, max_frame: int, domain: str) -> None:
    """Set the per-connection bounds on a listening socket, and its ZAP domain (so its handshakes ask us)."""
    sock.setsockopt(zmq.MAXMSGSIZE, max_frame)
    sock.setsockopt(zmq.HANDSHAKE_IVL, int(limits.handshake_s * 1000))
    sock.setsockopt(zmq.HEARTBEAT_IVL, int(limits.heartbeat_s * 1000))
    sock.setsockopt(zmq.HEARTBEAT_TIMEOUT, int(limits.heartbeat_timeout_s * 1000))
    sock.setsockopt(zmq.ZAP_DOMAIN, domain.encode())


class Admission:
    """The count of handshaken peers of one listening socket and the ZAP decision for it."""

    def __init__(self, name: str, limits: BrokerLimits, events: zmq.Socket | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.name = name
        self.limit = limits.max_connections
        self.window_s = limits.handshake_s + _MARGIN_S
        self.events = events  # the monitor PAIR feeding on_event
        self._now = clock
        self._accepted: dict[int, float] = {}  # descriptor -> when accepted
        self._approved: deque[float] = deque()  # when each recent approval was given
        self.refused = 0

    def on_event(self, frames: list[bytes]) -> None:
        """One monitor event (ACCEPTED or DISCONNECTED, with the connection's descriptor)."""
        event = parse_monitor_frames(frames)
        if event is None:
            return
        if event.event == zmq.EVENT_ACCEPTED:
            self._accepted[event.value] = self._now()
        elif event.event == zmq.EVENT_DISCONNECTED:
            self._accepted.pop(event.value, None)

    def drain(self) -> None:
        """Read every pending monitor event, so a ZAP decision sees every accepted connection."""
        while self.events is not None and self.events.poll(0):
            self.on_event(self.events.recv_multipart())

    def connected(self) -> int:
        """An upper bound of the handshaken peers now connected."""
        now = self._now()
        while self._approved and now - self._approved[0] > self.window_s:
            self._approved.popleft()
        young = sum(1 for t in self._accepted.values() if now - t <= self.window_s)
        return len(self._accepted) - young + min(young, len(self._approved))

    def admit(self, address: str) -> bool:
        """ZAP's question for a peer at ``address`` finishing its handshake: is there room?"""
        self.drain()
        if self.connected() < self.limit:
            self._approved.append(self._now())
            return True
        self.refused += 1
        if self.refused == 1 or self.refused % 100 == 0:
            log.warning("broker %s: refused a connection from %s: %d peers connected (max_connections); "
                        "%d refused so far", self.name, address or "a local peer", self.limit, self.refused)
        return False


class AdmissionControl:
    """The ZAP handlers (one per ZeroMQ context) and one :class:`Admission` per listening socket.

    ``guard`` runs on the thread that creates the sockets, before they bind; ``sockets``/``handle``/``reader`` on
    the one thread that polls them (the broker's manager thread), which also closes them with ``close``.
    """

    def __init__(self, limits: BrokerLimits) -> None:
        self.limits = limits
        self.admissions: dict[bytes, Admission] = {}
        self._zaps: dict[int, zmq.Socket] = {}  # id(context) -> its ZAP handler

    def guard(self, zctx: zmq.Context, sock: zmq.Socket, name: str, max_frame: int) -> None:
        """Bound ``sock`` (a listening socket of ``zctx``, not yet bound) and count its peers under ``name``."""
        if id(zctx) not in self._zaps:
            zap = zctx.socket(zmq.REP)
            zap.setsockopt(zmq.LINGER, 0)
            zap.bind(ZAP_ENDPOINT)
            self._zaps[id(zctx)] = zap
        domain = f"goby-broker.{name}"
        apply_limits(sock, self.limits, max_frame, domain)
        addr = f"inproc://broker-monitor-{name}-{id(sock)}"
        sock.monitor(addr, _MONITORED)
        events = zctx.socket(zmq.PAIR)
        events.setsockopt(zmq.RCVHWM, 0)  # unbounded: a lost DISCONNECTED would leave a peer counted for ever
        events.setsockopt(zmq.LINGER, 0)
        events.connect(addr)
        self.admissions[domain.encode()] = Admission(name, self.limits, events)

    def sockets(self) -> list[zmq.Socket]:
        """Every socket to poll for input: the ZAP handlers and the monitors."""
        events = [a.events for a in self.admissions.values() if a.events is not None]
        return [*self._zaps.values(), *events]

    def reader(self, sock: zmq.Socket) -> Callable[[], None]:
        """The reactor handler of ``sock`` (one of :meth:`sockets`)."""
        return lambda: self.handle(sock)

    def handle(self, sock: zmq.Socket) -> None:
        """Read everything ``sock`` (one of :meth:`sockets`) has: answer ZAP requests or count monitor events."""
        if sock in self._zaps.values():
            while True:
                try:
                    request = sock.recv_multipart(zmq.NOBLOCK)
                except zmq.Again:
                    return
                _version, request_id, domain, address = (request + [b""] * 4)[:4]
                admission = self.admissions.get(domain)
                ok = admission is None or admission.admit(address.decode(errors="replace"))
                status = [b"200", b"OK"] if ok else [b"400", b"too many connections"]
                sock.send_multipart([b"1.0", request_id, *status, b"", b""])
        for admission in self.admissions.values():
            if admission.events is sock:
                admission.drain()

    def close(self) -> None:
        """Close the ZAP handlers and monitors (on the polling thread)."""
        for sock in self.sockets():
            sock.close(linger=0)
