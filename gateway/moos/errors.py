"""One error root for the MOOS package, with a subclass per kind of failure."""

from __future__ import annotations


class MoosError(Exception):
    """Root of every error raised by ``gateway.moos``."""


class ProtocolError(MoosError):
    """Bytes on the wire do not form a valid MOOS v10 packet or message."""

    packets: list = []  # set by PacketReader.feed: whole packets decoded before the error


class HandshakeError(MoosError):
    """The connection handshake failed (wrong protocol string, no name, closed early)."""


class PoisonedError(HandshakeError):
    """The DB refused this client with a POISON message (e.g. its name is already taken)."""


class ConnectionClosedError(MoosError):
    """The peer closed the connection, or the connection was closed locally."""


class MissionFileError(MoosError):
    """A ``.moos`` mission file cannot be read or is malformed."""
