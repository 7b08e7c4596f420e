"""The portal's one error root and its failure kinds, so callers can catch exactly what they mean."""

from __future__ import annotations

from gateway.errors import GatewayError


class PortalError(GatewayError):
    """Root of every error the portal raises."""


class InvalidGroupError(PortalError, ValueError):
    """A group that cannot be used on this layer (e.g. an empty name on interprocess)."""


class MarshallingError(PortalError):
    """A payload that cannot be serialized or parsed, or a scheme/type we do not know."""


class IdentifierError(PortalError):
    """A received frame whose wire identifier is malformed."""


class AppConfigError(PortalError):
    """An application's configuration (file, command-line override, required field) that cannot be used."""


class StartError(PortalError):
    """An application cannot start, for a reason its message states in full (naming the part and the cause).

    ``run_application`` prints it as one line (the traceback only at ``-vv``); any other exception from an
    application's constructor is a bug and is printed with its traceback.
    """


class BrokerUnavailableError(StartError):
    """The broker's manager did not answer within ``manager_timeout_seconds``."""


class ClosedError(PortalError):
    """An operation on a portal, thread or broker that has already been shut down."""


class ThreadError(PortalError):
    """A thread launched by an application failed to start."""


class WrongThreadError(PortalError):
    """A transporter method called from a thread other than its owner (hand the work over with ``call_soon``)."""
