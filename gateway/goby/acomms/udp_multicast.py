"""Goby3's UDP multicast modem driver (``goby::acomms::UDPMulticastDriver``), datagram-compatible with it.

Every node binds ``listen_address:multicast_port`` with SO_REUSEADDR, joins ``multicast_address`` and sends there;
the datagram is the binary ``ModemTransmission`` (see :class:`DatagramDriver`). On a machine without a multicast
route, loopback works when the group is joined and sent on 127.0.0.1 (``IP_MULTICAST_IF``), which is what we do
when ``listen_address`` is a loopback address; otherwise the default interface is used, as Goby does.
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
from gateway.goby.acomms.protobuf.driver_base_pb2 import DriverConfig
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission

log = logging.getLogger(__name__)
MAX_DATAGRAM = 65535


def random_multicast() -> tuple[str, int]:
    """A multicast group and port unlikely to be used by anything else on the machine (side-by-side runs)."""
    rng = random.SystemRandom()
    return f"239.142.{rng.randrange(10, 250)}.{rng.randrange(1, 250)}", rng.randrange(40000, 60000)


def join_multicast(group: str, port: int, interface: str = "0.0.0.0", bind_address: str = "0.0.0.0") -> socket.socket:
    """A UDP socket bound to ``bind_address:port`` that has joined ``group`` on ``interface``; closed again if
    any step fails (the OSError propagates)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((bind_address, port))
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                        struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton(interface)))
    except OSError:
        sock.close()
        raise
    return sock


def multicast_interface(listen_address: str) -> str:
    """The interface a node joins and sends on: loopback for a loopback ``listen_address``, else the default one."""
    return "127.0.0.1" if ipaddress.ip_address(listen_address).is_loopback else "0.0.0.0"


def multicast_config(cfg: DriverConfig) -> udp_pb.Config:
    """The driver's ``[goby.acomms.udp_multicast.protobuf.config]`` block (defaults if absent)."""
    return cfg.Extensions[udp_pb.config]


class UDPMulticastDriver(DatagramDriver):
    """``DRIVER_UDP_MULTICAST``."""

    def __init__(self) -> None:
        super().__init__()
        self._sock: socket.socket | None = None
        self._mc = udp_pb.Config()
        self._dest: tuple[str, int] = ("", 0)

    def startup(self, cfg: DriverConfig) -> None:
        super().startup(cfg)
        self._mc = multicast_config(cfg)
        group, port = self._mc.multicast_address, self._mc.multicast_port
        try:
            if not ipaddress.ip_address(group).is_multicast:
                raise ModemDriverError(f"udp_multicast.multicast_address {group!r} is not a multicast address")
        except ValueError as exc:
            raise ModemDriverError(f"udp_multicast.multicast_address {group!r}: {exc}") from None
        interface = multicast_interface(self._mc.listen_address)
        loopback = interface != "0.0.0.0"
        try:
            # Bind the wildcard address: on Linux a socket bound to 127.0.0.1 does not receive multicast.
            sock = join_multicast(group, port, interface, "0.0.0.0" if loopback else self._mc.listen_address)
        except OSError as exc:
            raise ModemDriverError(f"udp_multicast: cannot listen on {group}:{port} "
                                   f"(listen_address {self._mc.listen_address}): {exc}") from None
        try:
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
            if loopback:
                sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(interface))
            sock.setblocking(False)
        except OSError as exc:
            sock.close()
            raise ModemDriverError(f"udp_multicast: cannot listen on {group}:{port} "
                                   f"(listen_address {self._mc.listen_address}): {exc}") from None
        self._sock = sock
        self._dest = (group, port)
        log.info("udp_multicast modem %d on %s:%d", self.modem_id, group, port)

    def shutdown(self) -> None:
        if self._sock is not None:
            self._sock.close()
            self._sock = None

    def fileno(self) -> int:
        return -1 if self._sock is None else self._sock.fileno()

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
            log.error("udp_multicast modem %d: cannot send to %s:%d: %s", self.modem_id, *self._dest, exc)

    def _receive_all(self) -> list[bytes]:
        out: list[bytes] = []
        while self._sock is not None:
            try:
                out.append(self._sock.recv(MAX_DATAGRAM))
            except BlockingIOError:
                break
            except OSError as exc:
                if exc.errno not in (errno.EAGAIN, errno.EWOULDBLOCK):
                    log.error("udp_multicast modem %d: receive failed: %s", self.modem_id, exc)
                break
        return out
