"""One error root for the launcher, so callers can catch launch failures without catching everything."""

from __future__ import annotations


class LaunchError(Exception):
    """Base of every error the launcher raises on purpose."""


class LaunchFileError(LaunchError):
    """A launch file line cannot be understood; the message names the file and line."""


class ProcessDiedError(LaunchError):
    """A launched process exited while it was expected to run; carries its name and log tail."""

    def __init__(self, name: str, returncode: int | None, log_tail: str) -> None:
        self.name = name
        self.returncode = returncode
        self.log_tail = log_tail
        super().__init__(f"process {name!r} died (exit status {returncode}); last lines of its log:\n{log_tail}")


class MissionConfigError(LaunchError):
    """A mission configuration is invalid (a missing setting, an unknown app name)."""
