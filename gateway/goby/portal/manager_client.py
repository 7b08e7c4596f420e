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


def request_endpoints(
    zctx: zmq.Context, cfg: InterProcessPortalConfig, client_name: str, timeout_s: float | None = None
) -> tuple[str, str, ManagerResponse]:
    """Ask the manager for sockets; returns (publish endpoint, subscribe endpoint, the response).

    Raises ``BrokerUnavailableError`` when nothing answers within ``timeout_s`` (default
    ``cfg.manager_timeout_seconds``), naming the endpoint and platform, as gobyd clients do.
    """
    endpoint = manager_endpoint(cfg)
    timeout = cfg.manager_timeout_seconds if timeout_s is None else timeout_s
    request = ManagerRequest(request=PROVIDE_PUB_SUB_SOCKETS, client_name=client_name, client_pid=os.getpid())
    req = zctx.socket(zmq.REQ)
    req.setsockopt(zmq.LINGER, 0)
    req.setsockopt(zmq.IPV6, 1)
    try:
        try:
            req.connect(endpoint)
        except zmq.ZMQError as exc:
            raise BrokerUnavailableError(f"cannot connect to the broker's manager at {endpoint}: {exc}") from exc
        req.send(request.SerializeToString())
        if not req.poll(int(timeout * 1000)):
            raise BrokerUnavailableError(
                f"No response from goby-broker at {endpoint} within {timeout:g} s (platform {cfg.platform!r}); "
                "is the broker running?"
            )
        raw = req.recv()
    finally:
        req.close()
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
