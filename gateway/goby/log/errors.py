"""The errors of the ``.goby`` log layer: a file that cannot be read as a log, and a log that cannot be written."""

from __future__ import annotations

from gateway.errors import GatewayError


class LogError(GatewayError):
    """Root of every error ``gateway.goby.log`` raises."""


class LogFormatError(LogError, ValueError):
    """A file that is not a ``.goby`` log this reader can read (its message names the file and the cause)."""


class NewerVersionError(LogFormatError):
    """A log written in a newer version of the format than this reader knows (Goby's LogEntry version)."""

    def __init__(self, message: str, version: int) -> None:
        super().__init__(message)
        self.version = version


class LogWriteError(LogError):
    """An entry that cannot be written: the disk is full, the file went away, or an index is exhausted."""
