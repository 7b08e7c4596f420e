"""``goby-broker``: run the broker for one platform (the gobyd role) until SIGINT/SIGTERM.

Config: ``GobyDaemonConfig`` in protobuf text format (``app {}``, ``router_threads``, ``interprocess {}``,
``hold { required_client: ... }``), command-line overrides such as ``--interprocess 'platform: "usv"'``, and
``GOBY_INTERPROCESS``.  Prints one line ``goby-broker ready: {...}`` (JSON endpoints) to stdout when serving.

Like gobyd (a Goby application itself), the broker answers goby-coroner's health requests and quits on a
goby-terminate request naming it (``app.name``, default ``goby-broker``, or its pid): its main thread is a
:class:`BrokerApplication`, a client of its own broker (docs/health.md).
"""

from __future__ import annotations

import json
import logging
import os
import resource
import sys

from gateway.goby.portal import SingleThreadApplication
from gateway.goby.portal.broker import READY_PREFIX, Broker, BrokerError
from gateway.goby.portal.config import load_for_run
from gateway.goby.portal.context import ProcessContext, use_context
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.goby.portal.runner import apply_simulation_time
from gateway.goby.portal.timeutil import SystemClock
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from util.logsetup import configure_logging
from util.process import handle_signals

log = logging.getLogger(__name__)

MAX_OPEN_FILES = 1 << 20  # the soft limit asked for when the hard limit is unlimited


def raise_open_files_limit() -> int:
    """Raise the soft limit of open descriptors to the hard limit and return it.

    Every connection is a descriptor; at the usual soft limit of 1024, a thousand half-open connections would fill
    the table and no new client could connect until ZeroMQ's handshake timer closed them.
    """
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    target = MAX_OPEN_FILES if hard == resource.RLIM_INFINITY else hard
    if soft != resource.RLIM_INFINITY and soft < target:
        try:
            resource.setrlimit(resource.RLIMIT_NOFILE, (target, hard))
            soft = target
        except (ValueError, OSError) as exc:
            log.warning("cannot raise the open-files limit from %d to %d: %s", soft, target, exc)
    return soft


class BrokerApplication(SingleThreadApplication):
    """gobyd's own portal client: on its main thread it answers health requests (``ProcessHealth`` named after
    the broker) and quits on a ``TerminateRequest`` naming it. The application base class does both."""

    def __init__(self, cfg: GobyDaemonConfig) -> None:
        super().__init__(cfg)


def control_context(cfg: GobyDaemonConfig, broker: Broker) -> ProcessContext:
    """The process context of the broker's own client: its interprocess (the manager's real TCP port when the
    config asked for any) and the warped clock of ``app.simulation``."""
    ipc = InterProcessPortalConfig()
    ipc.CopyFrom(cfg.interprocess)
    if ipc.transport == InterProcessPortalConfig.TCP and broker.manager_port:
        ipc.tcp_port = broker.manager_port
    clock = SystemClock()
    apply_simulation_time(cfg, clock)
    return ProcessContext(ipc, application=cfg.app.name or "goby-broker", clock=clock)


def serve(cfg: GobyDaemonConfig, broker: Broker) -> None:
    """Run the broker's own client on this (main) thread until SIGINT/SIGTERM or a terminate request."""
    context = control_context(cfg, broker)
    app: BrokerApplication | None = None
    stop_requested = False

    def on_signal(_signum: int) -> None:
        nonlocal stop_requested
        stop_requested = True
        if app is not None:
            app.quit()

    try:
        with handle_signals(on_signal), use_context(context):
            app = BrokerApplication(cfg)
            if stop_requested:
                app.quit()
            app.run()
    finally:
        if app is not None:
            app.close()
        context.close()


def main(argv: list[str] | None = None) -> int:
    loaded = load_for_run(GobyDaemonConfig, argv, "goby-broker")
    if isinstance(loaded, int):
        return loaded
    cfg = loaded.cfg
    configure_logging(loaded.verbosity, cfg.app.name)
    if not cfg.interprocess.HasField("platform"):
        log.warning("Using default platform name of %s", cfg.interprocess.platform)
    log.debug("open-files limit: %d", raise_open_files_limit())
    broker = Broker(cfg)
    with handle_signals() as stop:
        try:
            try:
                broker.start()
            except BrokerError as exc:
                log.critical("%s", exc)
                return 1
            info = {"platform": cfg.interprocess.platform, **broker.endpoints(), "pid": os.getpid()}
            print(READY_PREFIX + json.dumps(info), flush=True)
            log.info("=== goby-broker is ready ===")
            if not stop.is_set():
                serve(cfg, broker)  # returns on a signal or a terminate request naming this broker
            return 0
        finally:
            broker.stop()

if __name__ == "__main__":
    sys.exit(main())
