"""Where the broker's sockets live for a given ``InterProcessPortalConfig`` (shared by broker and clients)."""

from __future__ import annotations

import ipaddress

from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.goby.protobuf.interprocess_zeromq_pb2 import Socket

MANAGER_REQUEST_GROUP = "goby::zeromq::_internal_manager_request"
MANAGER_RESPONSE_GROUP = "goby::zeromq::_internal_manager_response"


def ipc_base(cfg: InterProcessPortalConfig) -> str:
    """The IPC base path: ``socket_name`` if set, else ``/tmp/goby_<platform>``."""
    return cfg.socket_name if cfg.HasField("socket_name") else f"/tmp/goby_{cfg.platform}"


def ipc_manager_path(base: str) -> str:
    """The manager's socket file for IPC base path ``base``: it exists while a broker serves that base."""
    return f"{base}.manager"


def ip_address(cfg: InterProcessPortalConfig) -> str:
    """The configured address: ``ip_address`` when set, else ``ipv4_address``."""
    return cfg.ip_address if cfg.HasField("ip_address") else cfg.ipv4_address


def tcp_endpoint(address: str, port: int) -> str:
    """``tcp://addr:port``, bracketing IPv6 addresses; ``*`` binds every interface."""
    if address != "*":
        try:
            if ipaddress.ip_address(address).version == 6:
                address = f"[{address}]"
        except ValueError:
            pass  # a host name
    return f"tcp://{address}:{port}"


def manager_endpoint(cfg: InterProcessPortalConfig) -> str:
    """The manager's REQ/REP endpoint; the broker binds the same configured address clients connect to."""
    if cfg.transport == InterProcessPortalConfig.IPC:
        return f"ipc://{ipc_manager_path(ipc_base(cfg))}"
    return tcp_endpoint(ip_address(cfg), cfg.tcp_port)


def socket_endpoint(sock: Socket, cfg: InterProcessPortalConfig) -> str:
    """The endpoint a client connects for a ``Socket`` from a ManagerResponse (TCP uses the client's address)."""
    if sock.transport == Socket.IPC:
        return f"ipc://{sock.socket_name}"
    if sock.transport == Socket.TCP:
        return tcp_endpoint(ip_address(cfg), sock.ethernet_port)
    if sock.transport == Socket.INPROC:
        return f"inproc://{sock.socket_name}"
    raise ValueError(f"unsupported socket transport {Socket.Transport.Name(sock.transport)}")
