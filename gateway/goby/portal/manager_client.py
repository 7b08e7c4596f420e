"""The client side of the broker's manager protocol: ask for the pub/sub endpoints over REQ/REP."""

from __future__ import annotations

import logging
import os

import zmq

from gateway.goby.portal.endpoints import manager_endpoint, socket_endpoint
from gateway.goby.portal.errors import BrokerUnavailableError
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.goby.protobuf.interprocess_zeromq_pb2 import (
    PROVIDE_PUB_SUB_SOCKETS,
    ManagerRequest,
    ManagerResponse,
)

log = logging.getLogger(__name__)


def _new_request_socket(zctx: zmq.Context, cfg: InterProcessPortalConfig, client_name: str) -> zmq.Socket:
    """A REQ socket connected to the manager with a ``PROVIDE_PUB_SUB_SOCKETS`` request already queued."""
    endpoint = manager_endpoint(cfg)
    request = ManagerRequest(request=PROVIDE_PUB_SUB_SOCKETS, client_name=client_name, client_pid=os.getpid())
    req = zctx.socket(zmq.REQ)
    req.setsockopt(zmq.LINGER, 0)
    req.setsockopt(zmq.IPV6, 1)
    try:
        req.connect(endpoint)
    except zmq.ZMQError as exc:
        req.close()
        raise BrokerUnavailableError(f"cannot connect to the broker's manager at {endpoint}: {exc}") from exc
    req.send(request.SerializeToString())  # queued until the manager is there (REQ waits for a peer)
    return req


def _parse_response(raw: bytes, cfg: InterProcessPortalConfig) -> tuple[str, str, ManagerResponse]:
    endpoint = manager_endpoint(cfg)
    response = ManagerResponse()
    try:
        response.ParseFromString(raw)
    except Exception as exc:  # noqa: BLE001 - any decode failure means a broken manager
        raise BrokerUnavailableError(f"malformed ManagerResponse from {endpoint}: {exc}") from exc
    if not (response.HasField("publish_socket") and response.HasField("subscribe_socket")):
        raise BrokerUnavailableError(f"ManagerResponse from {endpoint} lacks sockets: {response}")
    pub = socket_endpoint(response.publish_socket, cfg)
    sub = socket_endpoint(response.subscribe_socket, cfg)
    log.debug("manager %s: publish to %s, subscribe from %s", endpoint, pub, sub)
    return pub, sub, response


def request_endpoints(
    zctx: zmq.Context, cfg: InterProcessPortalConfig, client_name: str, timeout_s: float | None = None
) -> tuple[str, str, ManagerResponse]:
    """Ask the manager for sockets; returns (publish endpoint, subscribe endpoint, the response).

    Raises ``BrokerUnavailableError`` when nothing answers within ``timeout_s`` (default
    ``cfg.manager_timeout_seconds``), naming the endpoint and platform, as gobyd clients do.
    """
    timeout = cfg.manager_timeout_seconds if timeout_s is None else timeout_s
    req = _new_request_socket(zctx, cfg, client_name)
    try:
        if not req.poll(int(timeout * 1000)):
            raise BrokerUnavailableError(
                f"No response from goby-broker at {manager_endpoint(cfg)} within {timeout:g} s "
                f"(platform {cfg.platform!r}); is the broker running?"
            )
        raw = req.recv()
    finally:
        req.close()
    return _parse_response(raw, cfg)


class EndpointQuery:
    """The same request without blocking: the owner polls ``socket`` and calls ``result()`` once it is readable.

    Used after a TCP broker restart (its pub/sub ports are ephemeral): the request waits in the REQ socket until
    the manager is back, so the answer comes as soon as the broker is up, not at the next tick of a timer.
    Belongs to the thread that created it, as every ZeroMQ socket.
    """

    def __init__(self, zctx: zmq.Context, cfg: InterProcessPortalConfig, client_name: str) -> None:
        self._cfg = cfg
        self.socket = _new_request_socket(zctx, cfg, client_name)

    def result(self) -> tuple[str, str, ManagerResponse]:
        """(publish endpoint, subscribe endpoint, response); raises ``BrokerUnavailableError`` if malformed."""
        return _parse_response(self.socket.recv(zmq.NOBLOCK), self._cfg)

    def close(self) -> None:
        self.socket.close(linger=0)
