"""The broker (gobyd's router and manager): an XPUB/XSUB proxy plus the manager that hands out endpoints and
runs the start-up hold.

Two threads: the proxy (``zmq.proxy_steerable``, in C, stopped through an inproc control socket) and the manager,
a ``util.reactor.Reactor`` whose readers are the REP for endpoint requests, the SUB on the proxy for hold-state
requests (answered on a PUB) and the sockets of ``broker_admission`` (ZAP answers, connection counts).  The manager
has no timed work (ZeroMQ sends the heartbeats; admission windows are computed when a handshake asks), so an idle
broker's threads all sleep.  Neither thread runs user code; ``intervehicle {}`` links run on a third
(``gateway.goby.intervehicle.portal``).
"""

from __future__ import annotations

import dataclasses
import logging
import os
import socket
import threading
from typing import Any

import zmq

from gateway.errors import GatewayError
from gateway.goby.portal.broker_admission import AdmissionControl, BrokerLimits
from gateway.goby.portal.endpoints import (
    MANAGER_REQUEST_GROUP,
    MANAGER_RESPONSE_GROUP,
    ip_address,
    ipc_base,
    ipc_manager_path,
    manager_endpoint,
    tcp_endpoint,
)
from gateway.goby.portal.errors import ClosedError, IdentifierError, PortalError
from gateway.goby.portal.identifier import decode_frame, encode_frame, make_identifier, thread_id, type_prefix
from gateway.goby.portal.marshalling import Scheme
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.goby.protobuf.interprocess_zeromq_pb2 import (
    PROVIDE_HOLD_STATE,
    PROVIDE_PUB_SUB_SOCKETS,
    ManagerRequest,
    ManagerResponse,
    Socket,
)
from util.descriptors import initialization_errors
from util.reactor import Reactor

log = logging.getLogger(__name__)

READY_PREFIX = "goby-broker ready: "  # goby-broker's stdout line when serving, then JSON endpoints


MAX_MESSAGE_BYTES = BrokerLimits.max_message_bytes  # one publication frame (ZeroMQ's MAXMSGSIZE on the XSUB)


class BrokerError(PortalError):
    """The broker cannot start (e.g. another broker already serves the platform)."""


def _ipc_in_use(path: str) -> bool:
    """True when something accepts connections on the Unix socket ``path`` (a live broker)."""
    if not os.path.exists(path):
        return False
    probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    probe.settimeout(0.5)
    try:
        probe.connect(path)
        return True
    except OSError:
        return False
    finally:
        probe.close()


class Broker:
    """Router + manager for one platform.  ``start()`` binds and returns when ready; ``stop()`` is idempotent."""

    def __init__(self, cfg: GobyDaemonConfig | None = None, max_message_bytes: int | None = None,
                 limits: BrokerLimits | None = None) -> None:
        """``limits`` bound every input (frames, connections, handshake and heartbeat times); ``max_message_bytes``
        overrides its publication frame limit.  GobyDaemonConfig keeps Goby's field set, so these are arguments."""
        self.cfg = cfg if cfg is not None else GobyDaemonConfig()
        limits = limits or BrokerLimits()
        if max_message_bytes is not None:
            limits = dataclasses.replace(limits, max_message_bytes=int(max_message_bytes))
        self.limits = limits
        # ZeroMQ would allocate whatever a frame header announces; past this the sender is disconnected instead.
        self.max_message_bytes = limits.max_message_bytes
        self._admission: AdmissionControl | None = None  # handed to the manager thread, which closes it
        self.ipc: InterProcessPortalConfig = self.cfg.interprocess
        self.required_clients = frozenset(self.cfg.hold.required_client)
        self.reported_clients: set[str] = set()
        self.pub_port = 0  # TCP: the XPUB (clients' subscribe socket) port
        self.sub_port = 0  # TCP: the XSUB (clients' publish socket) port
        self.manager_port = 0
        self._zctx: zmq.Context | None = None
        self._mctx: zmq.Context | None = None
        self._threads: list[threading.Thread] = []
        self._proxy_control: zmq.Socket | None = None
        self._manager: Reactor | None = None  # the manager thread's loop (stop() stops it)
        self._started = False
        self._stopped = False
        self._ipc_files: list[str] = []  # created by this broker, removed on stop
        self._ready = threading.Event()
        self._errors: list[BaseException] = []
        self._intervehicle: Any = None  # the intervehicle portal, when the config has an intervehicle block

    @property
    def is_tcp(self) -> bool:
        return self.ipc.transport == InterProcessPortalConfig.TCP

    def endpoints(self) -> dict[str, str]:
        """Bound endpoints: ``xpub``, ``xsub``, ``manager``."""
        if self.is_tcp:
            host = ip_address(self.ipc)
            return {"xpub": tcp_endpoint(host, self.pub_port), "xsub": tcp_endpoint(host, self.sub_port),
                    "manager": tcp_endpoint(host, self.manager_port)}
        base = ipc_base(self.ipc)
        return {"xpub": f"ipc://{base}.xpub", "xsub": f"ipc://{base}.xsub", "manager": f"ipc://{base}.manager"}

    # ------------------------------------------------------------------------------------------ lifecycle
    def start(self) -> Broker:
        """Bind every socket and start the threads; raises ``BrokerError`` if the platform is taken."""
        if self._stopped:
            raise ClosedError("broker was stopped; create a new one")
        if self._started:
            return self
        if not self.is_tcp and _ipc_in_use(ipc_manager_path(ipc_base(self.ipc))):
            raise BrokerError(f"another broker already serves {ipc_manager_path(ipc_base(self.ipc))} "
                              f"(platform {self.ipc.platform!r})")
        self._started = True
        self._zctx = zmq.Context(io_threads=max(1, self.cfg.router_threads))
        self._mctx = zmq.Context(io_threads=1)
        self._admission = admission = AdmissionControl(self.limits)
        xpub = self._zctx.socket(zmq.XPUB)
        xsub = self._zctx.socket(zmq.XSUB)
        for sock in (xpub, xsub):
            sock.setsockopt(zmq.SNDHWM, self.ipc.send_queue_size)
            sock.setsockopt(zmq.RCVHWM, self.ipc.receive_queue_size)
            sock.setsockopt(zmq.IPV6, 1)
            sock.setsockopt(zmq.LINGER, 0)
        # subscribers send only subscriptions (small frames); publishers send the publications
        admission.guard(self._zctx, xpub, "xpub", self.limits.max_control_bytes)
        admission.guard(self._zctx, xsub, "xsub", self.limits.max_message_bytes)
        try:
            if self.is_tcp:  # the configured address only (Goby's ipv4_address, default 127.0.0.1)
                self.pub_port = xpub.bind_to_random_port(self._tcp_host())
                self.sub_port = xsub.bind_to_random_port(self._tcp_host())
            else:
                base = ipc_base(self.ipc)
                xpub.bind(f"ipc://{base}.xpub")
                self._ipc_files.append(f"{base}.xpub")
                xsub.bind(f"ipc://{base}.xsub")
                self._ipc_files.append(f"{base}.xsub")
        except zmq.ZMQError as exc:
            xpub.close()
            xsub.close()
            self.stop()
            raise BrokerError(f"cannot bind the broker's pub/sub sockets: {exc}") from exc
        self._proxy_control = self._start_proxy(self._zctx, xpub, xsub)

        rep = self._mctx.socket(zmq.REP)
        rep.setsockopt(zmq.LINGER, 0)
        rep.setsockopt(zmq.IPV6, 1)
        admission.guard(self._mctx, rep, "manager", self.limits.max_control_bytes)
        try:
            endpoint = manager_endpoint(self.ipc)
            if self.is_tcp and self.ipc.tcp_port == 0:
                self.manager_port = rep.bind_to_random_port(self._tcp_host())
            else:
                rep.bind(endpoint)
                self.manager_port = self.ipc.tcp_port if self.is_tcp else 0
                if not self.is_tcp:
                    self._ipc_files.append(ipc_manager_path(ipc_base(self.ipc)))
        except zmq.ZMQError as exc:
            rep.close()
            self.stop()
            raise BrokerError(f"cannot bind the manager socket {manager_endpoint(self.ipc)}: {exc}") from exc
        self._admission = None  # the manager thread owns and closes it from here on
        self._manager = Reactor("broker-manager")
        self._start_thread(self._run_manager, (self._mctx, rep, admission, self._manager), "broker-manager")
        if not self._ready.wait(10):
            self.stop()
            raise BrokerError("the broker's manager thread did not become ready within 10 s")
        log.info("broker ready for platform %r: %s", self.ipc.platform, self.endpoints())
        if self.cfg.HasField("intervehicle"):
            self._start_intervehicle()
        return self

    def _start_proxy(self, zctx: zmq.Context, xpub: zmq.Socket, xsub: zmq.Socket) -> zmq.Socket:
        """Start the proxy on a thread of its own; returns its control socket (an inproc PAIR: ``TERMINATE``)."""
        addr = f"inproc://broker-control-{id(self)}"
        peer = zctx.socket(zmq.PAIR)
        peer.bind(addr)
        control = zctx.socket(zmq.PAIR)
        control.connect(addr)
        self._start_thread(self._run_proxy, (xpub, xsub, peer), "broker-proxy")
        return control

    def _start_thread(self, target: Any, args: tuple[Any, ...], name: str) -> None:
        thread = threading.Thread(target=target, args=args, name=name)
        thread.start()
        self._threads.append(thread)

    def _start_intervehicle(self) -> None:
        """Run the intervehicle links in this process, as gobyd does (raises ``BrokerError`` naming the link)."""
        from gateway.goby.intervehicle.host import start_intervehicle

        try:
            self._intervehicle = start_intervehicle(self.cfg, self.manager_port)
        except GatewayError as exc:
            self.stop()
            raise BrokerError(f"cannot start the intervehicle portal: {exc}") from exc

    def _tcp_host(self) -> str:
        """``tcp://<configured address>`` for ``bind_to_random_port``."""
        return tcp_endpoint(ip_address(self.ipc), 0).rsplit(":", 1)[0]

    def stop(self) -> None:
        """Stop both threads and close every socket; idempotent."""
        if self._stopped:
            return
        self._stopped = True
        if self._intervehicle is not None:
            self._intervehicle.close()
        if self._proxy_control is not None:
            self._proxy_control.send(b"TERMINATE")
        if self._manager is not None:
            self._manager.stop()
        for thread in self._threads:
            thread.join(10)
        if self._proxy_control is not None:
            self._proxy_control.close(linger=0)
        if self._admission is not None:  # start() failed before the manager thread took it over
            self._admission.close()
        for zctx in (self._zctx, self._mctx):
            if zctx is not None:
                zctx.term()
        for path in self._ipc_files:
            try:
                os.unlink(path)
            except OSError:
                pass
        log.info("broker stopped")

    def __enter__(self) -> Broker:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # -------------------------------------------------------------------------------------------- threads
    def _run_proxy(self, xpub: zmq.Socket, xsub: zmq.Socket, control: zmq.Socket) -> None:
        try:
            zmq.proxy_steerable(xpub, xsub, None, control)
        except zmq.ContextTerminated:
            pass
        except zmq.ZMQError as exc:
            log.error("broker proxy stopped: %s", exc)
        finally:
            for sock in (xpub, xsub, control):
                sock.close(linger=0)

    def _run_manager(self, mctx: zmq.Context, rep: zmq.Socket, admission: AdmissionControl,
                     reactor: Reactor) -> None:
        """The manager thread: every socket a reader of ``reactor``, until ``stop()`` stops it."""
        endpoints = self.endpoints()
        sub = mctx.socket(zmq.SUB)
        pub = mctx.socket(zmq.PUB)
        for sock in (sub, pub):
            sock.setsockopt(zmq.LINGER, 0)
            sock.setsockopt(zmq.IPV6, 1)  # the proxy may be bound on an IPv6 address
        sub.connect(endpoints["xpub"])
        pub.connect(endpoints["xsub"])
        sub.setsockopt(zmq.SUBSCRIBE, type_prefix(
            MANAGER_REQUEST_GROUP, Scheme.PROTOBUF, ManagerRequest.DESCRIPTOR.full_name).encode())
        response_ident = make_identifier(
            MANAGER_RESPONSE_GROUP, Scheme.PROTOBUF, ManagerResponse.DESCRIPTOR.full_name, os.getpid(), thread_id())

        def answer_requests() -> None:
            while True:  # REP: each request is answered before the next is read
                try:
                    raw = rep.recv(zmq.NOBLOCK)
                except zmq.Again:
                    return
                rep.send(self._answer_rep(raw))

        def answer_holds() -> None:
            while True:
                try:
                    frame = sub.recv(zmq.NOBLOCK)
                except zmq.Again:
                    return
                reply = self._answer_hold(frame)
                if reply is not None:
                    pub.send(encode_frame(response_ident, reply.SerializeToString()))

        reactor.add_reader(rep, answer_requests)
        reactor.add_reader(sub, answer_holds)
        for sock in admission.sockets():
            reactor.add_reader(sock, admission.reader(sock))
        self._ready.set()
        try:
            reactor.run(until=lambda: self._stopped)  # (a stop() just before run() began is not missed)
        except zmq.ContextTerminated:
            pass
        finally:
            reactor.close()
            for sock in (rep, sub, pub):
                sock.close(linger=0)
            admission.close()

    # ------------------------------------------------------------------------------------------ answers
    def _answer_rep(self, raw: bytes) -> bytes:
        """Answer one REQ; a malformed request is logged and gets an empty reply (REP must always answer)."""
        request = ManagerRequest()
        try:
            request.ParseFromString(raw)
            if not request.IsInitialized():
                raise ValueError("missing " + ", ".join(initialization_errors(request)))
        except Exception as exc:  # noqa: BLE001 - any decode failure
            log.error("manager: malformed ManagerRequest (%d bytes): %s", len(raw), exc)
            return b""
        response = self.respond(request)
        return response.SerializeToString() if response is not None else b""

    def _answer_hold(self, frame: bytes) -> ManagerResponse | None:
        try:
            _, payload = decode_frame(frame)
            request = ManagerRequest.FromString(payload)
            if not request.IsInitialized():
                raise ValueError("missing " + ", ".join(initialization_errors(request)))
        except (IdentifierError, Exception) as exc:  # noqa: BLE001
            log.error("manager: malformed hold request: %s", exc)
            return None
        return self.respond(request)

    def respond(self, request: ManagerRequest) -> ManagerResponse | None:
        """The manager's answer to one request (pure; exposed for tests)."""
        response = ManagerResponse(
            request=request.request, client_name=request.client_name, client_pid=request.client_pid
        )
        if request.request == PROVIDE_PUB_SUB_SOCKETS:
            log.debug("manager: sockets for %s (pid %d)", request.client_name, request.client_pid)
            response.publish_socket.CopyFrom(self._socket(Socket.PUBLISH))
            response.subscribe_socket.CopyFrom(self._socket(Socket.SUBSCRIBE))
            return response
        if request.request == PROVIDE_HOLD_STATE:
            if request.ready and request.client_name in self.required_clients:
                if request.client_name not in self.reported_clients:
                    log.info("manager: required client %s is ready", request.client_name)
                self.reported_clients.add(request.client_name)
            response.hold = self.reported_clients != set(self.required_clients)
            return response
        log.error("manager: unknown request %d from %s", request.request, request.client_name)
        return None

    def _socket(self, socket_type: Socket.SocketType.ValueType) -> Socket:
        sock = Socket(
            socket_type=socket_type, connect_or_bind=Socket.CONNECT,
            send_queue_size=self.ipc.send_queue_size, receive_queue_size=self.ipc.receive_queue_size,
        )
        if self.is_tcp:
            sock.transport = Socket.TCP
            sock.ethernet_port = self.sub_port if socket_type == Socket.PUBLISH else self.pub_port
        else:
            sock.transport = Socket.IPC
            suffix = ".xsub" if socket_type == Socket.PUBLISH else ".xpub"
            sock.socket_name = ipc_base(self.ipc) + suffix
        return sock
