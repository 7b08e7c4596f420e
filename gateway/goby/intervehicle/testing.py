"""Test helpers for the intervehicle layer: link config blocks, a multicast availability check, and a portal client
with an intervehicle forwarder driven by the test's own thread."""

from __future__ import annotations

import socket
import struct
from collections.abc import Sequence

__all__ = ["IntervehicleClient", "broker_config", "link_block", "loopback_multicast_works", "random_multicast"]

from gateway.goby.acomms.udp_multicast import random_multicast
from gateway.goby.intervehicle.forwarder import InterVehicleForwarder
from gateway.goby.portal.testing import PortalClient
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig


def loopback_multicast_works(timeout_s: float = 1.0) -> bool:
    """True when a datagram sent to a multicast group on 127.0.0.1 comes back (the UDP multicast driver needs it)."""
    group, port = random_multicast()
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    try:
        rx.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        rx.bind(("0.0.0.0", port))
        rx.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                      struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton("127.0.0.1")))
        tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
        tx.sendto(b"probe", (group, port))
        rx.settimeout(timeout_s)
        return rx.recv(16) == b"probe"
    except OSError:
        return False
    finally:
        rx.close()
        tx.close()


def link_block(modem_id: int, group: str, port: int, slots: Sequence[tuple[int, float, int]],
               subnet_mask: int = 0xFF00) -> str:
    """One ``link {}`` of gobyd's intervehicle block: UDP multicast on loopback, TDMA with ``(src, s, bytes)``."""
    slot_text = " ".join(f"slot {{ src: {src} slot_seconds: {sec} max_frame_bytes: {nbytes} }}"
                         for src, sec, nbytes in slots)
    return (f"link {{ modem_id: {modem_id} subnet_mask: {subnet_mask} "
            f"driver {{ driver_type: DRIVER_UDP_MULTICAST [goby.acomms.udp_multicast.protobuf.config] {{ "
            f"listen_address: \"127.0.0.1\" multicast_address: \"{group}\" multicast_port: {port} }} }} "
            f"mac {{ type: MAC_FIXED_DECENTRALIZED {slot_text} }} }}")


def broker_config(links: Sequence[str], warp: int = 1) -> str:
    """A goby-broker config file's text with these links, warped."""
    sim = f"app {{ simulation {{ time {{ use_sim_time: true warp_factor: {warp} }} }} }}\n" if warp > 1 else ""
    return sim + "intervehicle {\n  " + "\n  ".join(links) + "\n}\n"


class IntervehicleClient(PortalClient):
    """A :class:`PortalClient` with ``intervehicle()``; callbacks run in ``poll`` on the test's thread."""

    def __init__(self, interprocess: InterProcessPortalConfig, name: str = "test_client") -> None:
        super().__init__(interprocess, name)
        self._forwarder = InterVehicleForwarder(self.portal, self.context, name)

    def intervehicle(self) -> InterVehicleForwarder:
        return self._forwarder
