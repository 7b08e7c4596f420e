"""Test helpers for the intervehicle layer: link config blocks, goby-broker processes hosting links, a multicast
availability check, and a portal client with an intervehicle forwarder driven by the test's own thread."""

from __future__ import annotations

import contextlib
import socket
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path

__all__ = ["IntervehicleClient", "LoopbackLink", "broker_config", "link_block", "link_brokers",
           "loopback_multicast_works", "random_multicast"]

from gateway.goby.acomms.udp_multicast import join_multicast, random_multicast
from gateway.goby.intervehicle.forwarder import InterVehicleForwarder
from gateway.goby.portal.testing import BrokerProcess, PortalClient
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig


def loopback_multicast_works(timeout_s: float = 1.0) -> bool:
    """True when a datagram sent to a multicast group on 127.0.0.1 comes back (the UDP multicast driver needs it)."""
    group, port = random_multicast()
    try:
        rx = join_multicast(group, port, interface="127.0.0.1")
    except OSError:
        return False
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    try:
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


class LoopbackLink:
    """A simulated link: UDP multicast on loopback on a group and port of its own, TDMA with ``(src, s, bytes)``."""

    def __init__(self, slots: Sequence[tuple[int, float, int]]) -> None:
        self.group, self.port = random_multicast()
        self.slots = list(slots)

    def block(self, modem_id: int, subnet_mask: int = 0xFF00) -> str:
        """The ``link {}`` block of the modem ``modem_id`` on this link."""
        return link_block(modem_id, self.group, self.port, self.slots, subnet_mask)


def broker_config(links: Sequence[str], warp: int = 1) -> str:
    """A goby-broker config file's text with these links, warped."""
    sim = f"app {{ simulation {{ time {{ use_sim_time: true warp_factor: {warp} }} }} }}\n" if warp > 1 else ""
    return sim + "intervehicle {\n  " + "\n  ".join(links) + "\n}\n"


@contextlib.contextmanager
def link_brokers(workdir: Path, links: Mapping[str, Sequence[str]], prefix: str, warp: int = 1, header: str = "",
                 startup_timeout: float = 30.0) -> Iterator[dict[str, BrokerProcess]]:
    """One goby-broker process per name (platform ``<prefix>_<name>``), each hosting its ``link {}`` blocks, with
    ``header`` (an ``app {}`` block) and ``broker_config(links, warp)`` as its config file
    (``workdir/gobyd_<name>.pb.cfg``, log ``workdir/gobyd_<name>.log`` at ``-v``: it names every subscription
    that crossed a link); all are stopped on leaving."""
    brokers: dict[str, BrokerProcess] = {}
    try:
        for name, blocks in links.items():
            cfg = workdir / f"gobyd_{name}.pb.cfg"
            cfg.write_text(header + broker_config(blocks, warp=warp))
            brokers[name] = BrokerProcess(workdir, platform=f"{prefix}_{name}", extra_args=[str(cfg), "-v"],
                                          log_path=workdir / f"gobyd_{name}.log", startup_timeout=startup_timeout)
            brokers[name].start()
        yield brokers
    finally:
        for broker in brokers.values():
            broker.stop()


class IntervehicleClient(PortalClient):
    """A :class:`PortalClient` with ``intervehicle()``; callbacks run in ``poll`` on the test's thread."""

    def __init__(self, interprocess: InterProcessPortalConfig, name: str = "test_client") -> None:
        super().__init__(interprocess, name)
        self._forwarder = InterVehicleForwarder(self.portal, self.context, name)

    def intervehicle(self) -> InterVehicleForwarder:
        return self._forwarder
