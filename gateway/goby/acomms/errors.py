"""The acomms layer's error kinds (under ``GatewayError``): modem drivers, the MAC and the buffers."""

from __future__ import annotations

from gateway.errors import GatewayError


class AcommsError(GatewayError):
    """Root of every error the acomms layer (drivers, MAC, buffers) raises."""


class ModemConfigError(AcommsError, ValueError):
    """A link's driver or MAC configuration that cannot be used (names the field and the cause)."""


class ModemDriverError(AcommsError):
    """A modem driver cannot start or send (e.g. the multicast group cannot be joined)."""
