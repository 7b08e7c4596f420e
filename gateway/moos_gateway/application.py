"""The goby_moos_gateway application (console script ``moos-gateway``, ``gateway.apps.moos_gateway``): a Goby
multi-thread application hosting the translators of its plugins.

Plugins come from ``GOBY_MOOS_GATEWAY_PLUGINS`` (see ``gateway.moos_gateway.plugins``).  They are all resolved before the
configuration is read, so a bad entry stops the process with exit status 1 before anything runs.  The
application then calls each plugin's ``load(gateway)`` in order (which launches its translator threads); an
exception there stops everything already started and exits 1 with one line naming the plugin and the cause
(the traceback at ``-vv``).  SIGINT/SIGTERM: ``unload(gateway)`` for each plugin (same order as loading, as
Goby), every translator stops and closes its MOOS client, exit 0.
"""

from __future__ import annotations

import logging

from gateway.goby.portal import MultiThreadApplication, StartError
from gateway.moos_gateway.plugins import Plugin
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig

log = logging.getLogger(__name__)

APP_NAME = "goby_moos_gateway"


class PluginLoadError(StartError):
    """A plugin's ``load(gateway)`` raised; the message names the plugin and the exception."""


class GobyMOOSGateway(MultiThreadApplication):
    """The gateway's main thread: owns the interprocess portal and runs no loop (0 Hz), as Goby's.

    ``plugins`` are loaded in order in the constructor, on the thread constructing the gateway (the process's main
    thread under ``main``); translators are the threads they launch.  ``unload`` runs on the thread that closes it.
    """

    def __init__(self, cfg: GobyMOOSGatewayConfig, plugins: list[Plugin]) -> None:
        super().__init__(cfg)
        if cfg.HasField("poll_frequency"):
            log.info("poll_frequency %g is ignored, as in Goby: translators loop at 10 Hz x warp and handle MOOS "
                     "mail as soon as it arrives", cfg.poll_frequency)
        self._loaded: list[Plugin] = []
        for plugin in plugins:
            try:
                plugin.load(self)
            except Exception as exc:
                log.debug("load of %s failed", plugin.entry, exc_info=True)
                self._loaded.append(plugin)  # unload what it may have launched
                self.close()
                raise PluginLoadError(
                    f"plugin {plugin.entry}: load(gateway) raised {type(exc).__name__}: {exc}"
                ) from exc
            self._loaded.append(plugin)
            log.info("loaded plugin %s", plugin.entry)

    def plugins(self) -> list[Plugin]:
        """The plugins loaded so far, in load order."""
        return list(self._loaded)

    def close(self) -> None:
        """``unload(gateway)`` for each plugin (load order), then join every remaining thread; idempotent."""
        loaded, self._loaded = self._loaded, []
        for plugin in loaded:
            if plugin.unload is None:
                continue
            try:
                plugin.unload(self)
            except Exception:
                log.exception("unload of plugin %s raised; carrying on with shutdown", plugin.entry)
        super().close()
