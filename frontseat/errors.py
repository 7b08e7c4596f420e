"""Exceptions of the frontseat subsystem: one root, one subclass per kind of failure.

A driver's ``loop()`` raises :class:`HelmErrorException` or :class:`FrontSeatErrorException` to push the
interface into HELM_ERROR or FS_ERROR (Goby's ``frontseat::Exception`` with a HelmError/FrontSeatError).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the simulator raises these errors too and must not import protobuf (4 MiB per process)
    from frontseat.protobuf import frontseat_pb2 as fs_pb


class FrontSeatException(Exception):
    """Root of every frontseat error."""


class HelmErrorException(FrontSeatException):
    """The helm is in error; carries a ``HelmError`` enum value."""

    def __init__(self, helm_error: fs_pb.HelmError.ValueType) -> None:
        from frontseat.protobuf import frontseat_pb2 as fs_pb

        self.helm_error = helm_error
        super().__init__(fs_pb.HelmError.Name(helm_error))


class FrontSeatErrorException(FrontSeatException):
    """The frontseat is in error; carries a ``FrontSeatError`` enum value."""

    def __init__(self, frontseat_error: fs_pb.FrontSeatError.ValueType) -> None:
        from frontseat.protobuf import frontseat_pb2 as fs_pb

        self.frontseat_error = frontseat_error
        super().__init__(fs_pb.FrontSeatError.Name(frontseat_error))


class SimulatorLineError(FrontSeatException, ValueError):
    """A basic-simulator protocol line that is malformed or cannot be acted on; the message names the cause."""


class DriverConfigError(FrontSeatException):
    """A configuration value is missing or out of range."""
