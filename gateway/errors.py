"""The root of every error the ``gateway`` package raises: the MOOS side (``MoosError``), the Goby side
(``PortalError``) and the gateway process (``PluginLoadError``) all derive from :class:`GatewayError`."""

from __future__ import annotations


class GatewayError(Exception):
    """Root of every error raised on purpose by ``gateway.moos``, ``gateway.goby`` and ``gateway.moos_gateway``."""
