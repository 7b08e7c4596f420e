"""Goby3's UDP multicast modem driver (``goby::acomms::UDPMulticastDriver``), datagram-compatible with it.

Every node binds ``multicast_address:multicast_port`` with SO_REUSEADDR, joins ``multicast_address`` on the
interface ``listen_address`` names and sends there; the datagram is the binary ``ModemTransmission`` (see
:class:`DatagramDriver`). Binding the group address (Goby binds ``listen_address``, default 0.0.0.0) makes the kernel
deliver only datagrams sent to the group, never unicast to the port; joining on one interface with
``IP_MULTICAST_ALL`` off delivers only what arrived on that interface. A loopback ``listen_address`` joins and
sends on 127.0.0.1 (``IP_MULTICAST_IF``), which needs no multicast route and never leaves the machine; 0.0.0.0
joins on the default interface, as Goby does; any other address joins on the interface that has it. Datagrams
from a source outside ``peer_address`` (our ``udp_peers`` extension; loopback listen: outside 127.0.0.0/8) are
dropped, counted and logged at a rate-limited cadence. Our ``channel_model`` extension of the driver block adds a
simulated channel's loss, delay and outages on receive (:class:`DatagramDriver`, ``gateway.goby.acomms.channel``)
where Linux netem cannot be used (docs/intervehicle.md "Lossy channels").
"""

from __future__ import annotations

import errno
import ipaddress
import logging
import random
import socket
import struct

from gateway.goby.acomms.driver import DatagramDriver
from gateway.goby.acomms.errors import ModemDriverError
from gateway.goby.acomms.protobuf import udp_multicast_driver_pb2 as udp_pb
from gateway.goby.acomms.protobuf import udp_peers_pb2 as udp_peers_pb
from gateway.goby.acomms.protobuf.driver_base_pb2 import DriverConfig
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission

log = logging.getLogger(__name__)
MAX_DATAGRAM = 65535
#: Datagrams read per ``do_work``: a flood waits in the socket buffer (the kernel drops past it), the MAC keeps time.
MAX_DATAGRAMS_PER_CALL = 1000
#: Linux's IP_MULTICAST_ALL (not in Python's socket module): 0 = only groups this socket joined, on their interface.
IP_MULTICAST_ALL = getattr(socket, "IP_MULTICAST_ALL", 49)
#: Linux's SO_RXQ_OVFL: each datagram carries the count of datagrams the kernel dropped on this socket (buffer full).
SO_RXQ_OVFL = getattr(socket, "SO_RXQ_OVFL", 40)
LOOPBACK_NET = ipaddress.ip_network("127.0.0.0/8")
Network = ipaddress.IPv4Network | ipaddress.IPv6Network


def random_multicast() -> tuple[str, int]:
    """A multicast group and port unlikely to be used by anything else on the machine (side-by-side runs)."""
    rng = random.SystemRandom()
    return f"239.142.{rng.randrange(10, 250)}.{rng.randrange(1, 250)}", rng.randrange(40000, 60000)


def join_multicast(group: str, port: int, interface: str = "0.0.0.0") -> socket.socket:
    """A UDP socket bound to ``group:port`` that has joined ``group`` on ``interface`` only; closed again if any
    step fails (the OSError propagates). Bound to the group, it never receives unicast sent to the port."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((group, port))
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                        struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton(interface)))
        try:  # Linux: not what other sockets joined on other interfaces
            sock.setsockopt(socket.IPPROTO_IP, IP_MULTICAST_ALL, 0)
        except OSError:
            pass
    except OSError:
        sock.close()
        raise
    return sock


def multicast_interface(listen_address: str) -> str:
    """The interface a node joins and sends on: 127.0.0.1 for a loopback ``listen_address``, the default one for
    0.0.0.0 (or a multicast address), else the interface that has ``listen_address``."""
    address = ipaddress.ip_address(listen_address)
    if address.is_loopback:
        return "127.0.0.1"
    if address.is_unspecified or address.is_multicast:
        return "0.0.0.0"
    return str(address)


def peer_networks(cfg: DriverConfig, mc: udp_pb.Config) -> list[Network] | None:
    """The source networks datagrams are accepted from (None: any), from our ``udp_peers`` extension of the driver
    block; raises ``ModemDriverError`` naming a bad one."""
    networks: list[Network] = []
    for i, text in enumerate(cfg.Extensions[udp_peers_pb.udp_peers].peer_address):
        try:
            networks.append(ipaddress.ip_network(text, strict=False))
        except ValueError as exc:
            raise ModemDriverError(f"udp_peers.peer_address[{i}] {text!r}: {exc}") from None
    if networks:
        return networks
    return [LOOPBACK_NET] if multicast_interface(mc.listen_address) == "127.0.0.1" else None


def multicast_config(cfg: DriverConfig) -> udp_pb.Config:
    """The driver's ``[goby.acomms.udp_multicast.protobuf.config]`` block (defaults if absent)."""
    return cfg.Extensions[udp_pb.config]


_OVFL_SPACE = socket.CMSG_SPACE(4)


class UDPMulticastDriver(DatagramDriver):
    """``DRIVER_UDP_MULTICAST``."""

    def __init__(self) -> None:
        super().__init__()
        self._sock: socket.socket | None = None
        self._mc = udp_pb.Config()
        self._dest: tuple[str, int] = ("", 0)
        self._peers: list[Network] | None = None
        self._kernel_dropped = 0  # the last SO_RXQ_OVFL count seen

    def startup(self, cfg: DriverConfig) -> None:
        super().startup(cfg)
        self._mc = multicast_config(cfg)
        group, port = self._mc.multicast_address, self._mc.multicast_port
        try:
            if not ipaddress.ip_address(group).is_multicast:
                raise ModemDriverError(f"udp_multicast.multicast_address {group!r} is not a multicast address")
        except ValueError as exc:
            raise ModemDriverError(f"udp_multicast.multicast_address {group!r}: {exc}") from None
        try:
            interface = multicast_interface(self._mc.listen_address)
        except ValueError as exc:
            raise ModemDriverError(f"udp_multicast.listen_address {self._mc.listen_address!r}: {exc}") from None
        self._peers = peer_networks(cfg, self._mc)
        try:
            # The group, not listen_address: on Linux a socket bound to a unicast address receives no multicast.
            sock = join_multicast(group, port, interface)
        except OSError as exc:
            raise ModemDriverError(f"udp_multicast: cannot listen on {group}:{port} "
                                   f"(listen_address {self._mc.listen_address}): {exc}") from None
        try:
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
            try:  # so that datagrams the kernel drops (a flood fills the buffer) are counted, not lost silently
                sock.setsockopt(socket.SOL_SOCKET, SO_RXQ_OVFL, 1)
            except OSError:
                pass
            if interface != "0.0.0.0":
                sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(interface))
            sock.setblocking(False)
        except OSError as exc:
            sock.close()
            raise ModemDriverError(f"udp_multicast: cannot listen on {group}:{port} "
                                   f"(listen_address {self._mc.listen_address}): {exc}") from None
        self._sock = sock
        self._dest = (group, port)
        log.info("%s: udp_multicast on %s:%d (interface %s, from %s)", self.name, group, port, interface,
                 "any address" if self._peers is None else ", ".join(map(str, self._peers)))

    def shutdown(self) -> None:
        self.refusals.flush(final=True)
        if self._sock is not None:
            self._sock.close()
            self._sock = None

    def fileno(self) -> int:
        if self._sock is None:
            raise ValueError(f"{self.name or 'udp_multicast'}: not started")
        return self._sock.fileno()

    def _max_frame_size(self, msg: ModemTransmission) -> int:
        for pair in self._mc.rate_to_bytes:
            if pair.rate == msg.rate:
                return pair.bytes
        return self._mc.max_frame_size

    def _send(self, datagram: bytes) -> None:
        if self._sock is None:
            return
        try:
            self._sock.sendto(datagram, self._dest)
        except OSError as exc:
            log.error("%s: udp_multicast cannot send to %s:%d: %s", self.name, *self._dest, exc)

    def _from_peer(self, address: str) -> bool:
        if self._peers is None:
            return True
        source = ipaddress.ip_address(address)
        return any(source in network for network in self._peers)

    def _count_kernel_drops(self, ancillary: list[tuple[int, int, bytes]]) -> None:
        for level, kind, data in ancillary:
            if level == socket.SOL_SOCKET and kind == SO_RXQ_OVFL and len(data) >= 4:
                total = struct.unpack("=I", data[:4])[0]
                if total > self._kernel_dropped:
                    dropped, self._kernel_dropped = total - self._kernel_dropped, total
                    self.refused["receive buffer full"] += dropped
                    self.refusals.error("receive buffer full", "%s: the kernel dropped %d datagram(s) before we read "
                                        "them (receive buffer full: a flood?) [%d so far]", self.name, dropped, total)

    def _receive_all(self) -> list[bytes]:
        out: list[bytes] = []
        for _ in range(MAX_DATAGRAMS_PER_CALL):
            if self._sock is None:
                break
            try:
                datagram, ancillary, _flags, (address, port) = self._sock.recvmsg(MAX_DATAGRAM, _OVFL_SPACE)
                self._count_kernel_drops(ancillary)
                if self._from_peer(address):
                    out.append(datagram)
                else:
                    self.refuse("not a peer address", "from %s:%d, not a peer_address of this link",
                                address, port, size=len(datagram))
            except BlockingIOError:
                break
            except OSError as exc:
                if exc.errno not in (errno.EAGAIN, errno.EWOULDBLOCK):
                    log.error("%s: udp_multicast receive failed: %s", self.name, exc)
                break
        return out
