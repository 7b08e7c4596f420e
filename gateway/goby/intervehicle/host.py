"""Start the intervehicle portal inside ``goby-broker`` from its ``GobyDaemonConfig`` (the gobyd role)."""

from __future__ import annotations

from typing import Any

from gateway.goby.intervehicle.errors import IntervehicleConfigError
from gateway.goby.intervehicle.portal import IntervehiclePortal
from gateway.goby.portal.context import ProcessContext
from gateway.goby.portal.runner import apply_simulation_time
from gateway.goby.portal.timeutil import SystemClock
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig


class HostedIntervehicle:
    """The portal and the process context of its ``intervehicle`` thread; ``close()`` stops both (idempotent)."""

    def __init__(self, portal: IntervehiclePortal, context: ProcessContext) -> None:
        self.portal = portal
        self.context = context

    def close(self) -> None:
        self.portal.stop()
        self.context.close()


def start_intervehicle(cfg: Any, manager_port: int) -> HostedIntervehicle:
    """Start the links of ``cfg.intervehicle`` on the broker of ``cfg.interprocess`` (warped by ``cfg.app``)."""
    ipc = InterProcessPortalConfig()
    ipc.CopyFrom(cfg.interprocess)
    if ipc.transport == InterProcessPortalConfig.TCP and manager_port:
        ipc.tcp_port = manager_port
    clock = SystemClock()
    try:
        apply_simulation_time(cfg, clock)
    except ValueError as exc:  # e.g. warp_factor: -3 (the links run on the warped clock)
        raise IntervehicleConfigError(f"app.simulation.time: {exc}") from None
    context = ProcessContext(ipc, application=(cfg.app.name or "goby-broker") + "/intervehicle", clock=clock)
    portal = IntervehiclePortal(cfg.intervehicle, context)
    try:
        portal.start()
    except BaseException:
        context.close()
        raise
    return HostedIntervehicle(portal, context)
