"""``run_application``: config, logging, warp, signals, the application's lifetime, and the exit code."""

from __future__ import annotations

import logging
import os
import signal
import sys
import threading
from collections.abc import Callable
from typing import Any

from google.protobuf import message as pb_message

from gateway.goby.portal.config import app_config_of, app_name_of, interprocess_config_of, load_for_run
from gateway.goby.portal.context import ProcessContext, use_context
from gateway.goby.portal.errors import StartError
from gateway.goby.portal.thread import SimpleThread
from gateway.goby.portal.timeutil import SystemClock
from util.extensions import ExtensionError
from util.logsetup import configure_logging
from util.process import handle_signals

log = logging.getLogger(__name__)


def apply_simulation_time(cfg: Any, clock: SystemClock) -> None:
    """Apply ``app.simulation.time`` (use_sim_time, warp_factor, reference_microtime) to ``clock``."""
    app = app_config_of(cfg)
    if app is None:
        return
    sim = app.simulation.time
    if sim.use_sim_time:
        reference = sim.reference_microtime if sim.HasField("reference_microtime") else None
        clock.configure(True, sim.warp_factor, reference)
        log.info("simulation time on: warp %d, reference %d µs", clock.warp_factor, clock.reference_micro)


def run_application(
    app_class: Callable[[Any], SimpleThread],
    config_type: type[pb_message.Message],
    argv: list[str] | None = None,
    *,
    prog: str | None = None,
) -> int:
    """Parse the configuration and run ``app_class(cfg)`` until it quits or SIGINT/SIGTERM; returns the exit code.

    Exit codes: the application's ``quit(code)``; 0 for ``--example_config`` and ``debug_cfg``; 1 when the broker
    does not answer or the application fails; 2 for a bad configuration.  A ``StartError`` or ``ExtensionError``
    from the constructor is printed as one line (its traceback at ``-vv``); any other exception with its traceback.
    """
    prog = prog or os.path.basename(sys.argv[0] or "app")
    loaded = load_for_run(config_type, argv, prog)
    if isinstance(loaded, int):
        return loaded
    cfg = loaded.cfg
    app_name = app_name_of(cfg, prog)  # load_config set app.name if the config type has an app block
    configure_logging(loaded.verbosity, app_name)
    clock = SystemClock()  # this run's clock, owned by its context: nothing process-wide is changed
    apply_simulation_time(cfg, clock)
    context = ProcessContext(interprocess_config_of(cfg), application=app_name, clock=clock)
    app: SimpleThread | None = None
    stop_requested = threading.Event()  # a signal during construction must not be lost

    def on_signal(signum: int) -> None:
        log.info("received %s; shutting down", signal.Signals(signum).name)
        stop_requested.set()
        if app is not None:
            app.quit()

    try:
        with handle_signals(on_signal), use_context(context):
            try:
                app = app_class(cfg)
                if stop_requested.is_set():
                    app.quit()
            except (StartError, ExtensionError) as exc:  # the message names the part and the cause: one line
                log.critical("%s", exc)
                log.debug("%s could not start", app_name, exc_info=True)
                return 1
            except Exception:
                log.exception("%s failed to start", app_name)
                return 1
            try:
                app.run()
            except Exception:
                log.exception("%s failed", app_name)
                return 1
            return int(getattr(app, "return_code", 0))
    finally:
        if app is not None:
            app.close()
        context.close()
        context.registry.write_if_requested()
