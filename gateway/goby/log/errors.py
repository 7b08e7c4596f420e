"""The errors of the ``.goby`` log layer: a file that cannot be read as a log, a log that cannot be written, and an
output format whose library is not installed."""

from __future__ import annotations

import importlib
from typing import Any

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


class ExportUnavailable(LogError):
    """An output format's library (h5py for HDF5, mcap for MCAP) is not installed: the message names the extra."""


def import_optional(module: str, output: str) -> Any:
    """``module``, imported now (the log extra's libraries load only when their format is asked for), or
    :class:`ExportUnavailable` saying how to install it."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        package = module.split(".")[0]
        raise ExportUnavailable(f"{output} output needs {package} ({exc}): install the 'log' extra "
                                f"(pip install 'goby-moos-py[log]' or pip install {package})") from None
