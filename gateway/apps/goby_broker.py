"""``goby-broker``: run the broker for one platform (the gobyd role) until SIGINT/SIGTERM.

Config: ``GobyDaemonConfig`` in protobuf text format (``app {}``, ``router_threads``, ``interprocess {}``,
``hold { required_client: ... }``), command-line overrides such as ``--interprocess 'platform: "usv"'``, and
``GOBY_INTERPROCESS``.  Prints one line ``goby-broker ready: {...}`` (JSON endpoints) to stdout when serving.
"""

from __future__ import annotations

import json
import logging
import os
import resource
import sys

from gateway.goby.portal.broker import READY_PREFIX, Broker, BrokerError
from gateway.goby.portal.config import load_for_run
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
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
            stop.wait()  # no timeout: the signal handler sets it (an idle broker's main thread never wakes)
            return 0
        finally:
            broker.stop()

if __name__ == "__main__":
    sys.exit(main())
