"""Test helpers for translators: host translator classes in-process as the gateway does, or run ``moos-gateway``
as a process with plugins.  Pair them with ``gateway.moos.testing`` (a MOOSDB) and ``gateway.goby.portal.testing``
(a broker and a portal client)::

    with running_moosdb() as db, broker_process(tmp_path) as broker:
        cfg = gateway_config(db.port, broker.interprocess_config())
        with hosted_translators(cfg, MyTranslator) as gateway:
            ...   # talk to it with connected_comms(db.port, ...) and PortalClient(broker.interprocess_config())
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
from collections.abc import Iterable, Iterator
from pathlib import Path

from gateway.goby.portal import ProcessContext, SimpleThread, use_context
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.moos_gateway.application import GobyMOOSGateway
from gateway.moos_gateway.plugins import ENV_VAR, Plugin
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from translators.base import translator_plugin
from util.process import ChildProcess


def gateway_config(moos_port: int, interprocess: InterProcessPortalConfig | None = None,
                   moos_server: str = "127.0.0.1", app_name: str = "goby_moos_gateway") -> GobyMOOSGatewayConfig:
    """A ``GobyMOOSGatewayConfig`` pointing at a MOOSDB on ``moos_server:moos_port`` and a broker."""
    cfg = GobyMOOSGatewayConfig()
    cfg.app.name = app_name
    cfg.moos.server = moos_server
    cfg.moos.port = moos_port
    if interprocess is not None:
        cfg.interprocess.CopyFrom(interprocess)
    return cfg


@contextlib.contextmanager
def hosted_translators(cfg: GobyMOOSGatewayConfig, *translator_classes: type[SimpleThread],
                       hold_settle_s: float = 0.2) -> Iterator[GobyMOOSGateway]:
    """Run a ``GobyMOOSGateway`` in this process whose one plugin launches ``translator_classes``.

    The gateway's main thread runs on a background thread; on exit it quits and every translator is joined.
    ``gateway.threads()`` gives the translator instances (inspect them only through thread-safe means).
    """
    load, _ = translator_plugin(*translator_classes)
    plugin = Plugin("hosted_translators", None, load, None)
    context = ProcessContext(cfg.interprocess, application=cfg.app.name or "goby_moos_gateway",
                             hold_settle_s=hold_settle_s)
    app: GobyMOOSGateway | None = None
    runner: threading.Thread | None = None
    try:
        with use_context(context):
            app = GobyMOOSGateway(cfg, [plugin])
        runner = threading.Thread(target=app.run, name="hosted-gateway-main")
        runner.start()
        yield app
    finally:
        if app is not None:
            app.quit()
            if runner is not None:
                runner.join(30)
                if runner.is_alive():
                    # Closing transports under a thread still polling them would hide the real fault.
                    raise RuntimeError("the hosted gateway's main thread did not stop within 30 s")
            app.close()
        context.close()


class GatewayProcess:
    """``moos-gateway`` as a child process with ``GOBY_MOOS_GATEWAY_PLUGINS`` set; stdout in ``gateway.out``,
    its log (stderr) in ``gateway.err``."""

    def __init__(self, workdir: str | os.PathLike[str], plugins: Iterable[str], config_text: str,
                 env: dict[str, str] | None = None, extra_args: Iterable[str] = ()) -> None:
        self.workdir = Path(workdir)
        self.config_path = self.workdir / "gateway.pb.cfg"
        self.config_path.write_text(config_text)
        env = dict(os.environ if env is None else env)
        env[ENV_VAR] = ":".join(plugins)
        self.proc = ChildProcess([sys.executable, "-m", "gateway.apps.moos_gateway", str(self.config_path),
                                  *extra_args], self.workdir / "gateway.out", name="moos-gateway",
                                 env=env, cwd=self.workdir, stderr_path=self.workdir / "gateway.err")

    def start(self) -> GatewayProcess:
        self.proc.start()
        return self

    def wait(self, timeout: float = 60.0) -> int | None:
        return self.proc.wait(timeout)

    def stop(self, sig: int = signal.SIGTERM, timeout: float = 30.0) -> int | None:
        """Send ``sig`` and wait (SIGKILL after ``timeout``); returns the exit code; idempotent."""
        return self.proc.stop(grace=timeout, sig=sig)

    def stderr(self) -> str:
        return self.proc.stderr_text()

    def __enter__(self) -> GatewayProcess:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
