"""goby-liaison's errors, under the launch package's root."""

from __future__ import annotations

from launch.errors import LaunchError


class LiaisonError(LaunchError):
    """Root of every error goby-liaison raises on purpose."""


class LiaisonConfigError(LiaisonError):
    """The configuration names something that cannot be served (an unknown type, a bad regex, a bad layer)."""


class CommandRefused(LiaisonError, ValueError):
    """A command from a browser that is not sent; ``field`` names the offending field ('' for the whole form)."""

    def __init__(self, message: str, field: str = "") -> None:
        super().__init__(message)
        self.field = field
