"""The intervehicle layer's error kinds (under ``GatewayError``)."""

from __future__ import annotations

from gateway.errors import GatewayError


class IntervehicleError(GatewayError):
    """Root of every error the intervehicle layer raises."""


class InvalidPublicationError(IntervehicleError, ValueError):
    """A publication Goby refuses (e.g. a non-broadcast group without a set_group function)."""


class InvalidSubscriptionError(IntervehicleError, ValueError):
    """A subscription Goby refuses (no group function for a non-broadcast group, broadcast with ack_required)."""


class IntervehicleConfigError(IntervehicleError, ValueError):
    """A broker's intervehicle settings that cannot be used (names the field and the cause)."""
