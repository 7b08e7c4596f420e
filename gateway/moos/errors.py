"""One error root for the MOOS package, with a subclass per kind of failure."""

from __future__ import annotations

from typing import Any

from gateway.errors import GatewayError


class MoosError(GatewayError):
    """Root of every error raised by ``gateway.moos``."""


class ProtocolError(MoosError):
    """Bytes on the wire do not form a valid MOOS v10 packet or message.

    ``packets``: the whole packets ``PacketReader.feed`` decoded before the bad bytes (each error its own list).
    """

    def __init__(self, message: str, packets: list[Any] | None = None) -> None:
        super().__init__(message)
        self.packets: list[Any] = list(packets) if packets is not None else []


class HandshakeError(MoosError):
    """The connection handshake failed (wrong protocol string, no name, closed early)."""


class PoisonedError(HandshakeError):
    """The DB refused this client with a POISON message (e.g. its name is already taken)."""


class ConnectionClosedError(MoosError):
    """The peer closed the connection, or the connection was closed locally."""


class MissionFileError(MoosError):
    """A ``.moos`` mission file cannot be read or is malformed."""
