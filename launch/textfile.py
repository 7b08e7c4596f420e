"""Reading a text file the launcher was pointed at, with a launch error that names it when it cannot be read."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from launch.errors import LaunchError


def read_text(path: Path, error: Callable[[str], LaunchError], message: str) -> str:
    """The text of ``path``; if it cannot be read, raises ``error(message)`` with ``{path}`` and ``{reason}`` filled."""
    try:
        return path.read_text()
    except OSError as exc:
        raise error(message.format(path=path, reason=exc.strerror or exc)) from exc
