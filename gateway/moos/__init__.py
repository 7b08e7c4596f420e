"""MOOS v10 in pure Python: wire codec, a pymoos-compatible client (``comms``), a MOOSDB-compatible server,
``.moos`` mission files, and the ``moos-db`` / ``moos-poke`` / ``moos-scope`` tools.

``from gateway.moos import comms`` is a drop-in for ``import pymoos; pymoos.comms``. To use the real pymoos
when it is importable, call :func:`choose_client` (or set ``GOBY_MOOS_CLIENT=pymoos``).
:data:`DEFAULT_CLOCK` exists for pymoos's process-wide API only (``time()``, ``set_moos_timewarp()``, ``comms()``
without ``clock=``); everything else gives its client a clock of its own.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .clock import DEFAULT_CLOCK, MoosClock
from .errors import (
    ConnectionClosedError,
    HandshakeError,
    MissionFileError,
    MoosError,
    PoisonedError,
    ProtocolError,
)
from .message import MoosMessage

if TYPE_CHECKING:
    from .client import comms
    from .factory import ClientChoice, choose_client

# The client (and its engine) load on first use: moos-db, which only serves, never pays for them (2 MiB).
_LAZY = {"comms": ".client", "ClientChoice": ".factory", "choose_client": ".factory"}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value

moos_msg = MoosMessage  # pymoos's name for the message class
pyMOOSException = MoosError  # pymoos's exception name  # noqa: N816


def time(apply_timewarping: bool = True, **kwargs: bool) -> float:
    """MOOS time (warped unix time plus the skew learned from the DB), as ``pymoos.time()``.

    pymoos spells the keyword ``apply_timewartping``; both spellings are accepted.
    """
    return DEFAULT_CLOCK.time(kwargs.get("apply_timewartping", apply_timewarping))


def local_time(apply_timewarping: bool = True, **kwargs: bool) -> float:
    """Warped unix time without skew, as ``pymoos.local_time()`` (either keyword spelling)."""
    return DEFAULT_CLOCK.local_time(kwargs.get("apply_timewartping", apply_timewarping))


def set_moos_timewarp(warp: float) -> None:
    """Set the process-wide time warp used by :func:`time` and by clients built without their own clock.

    As ``pymoos.set_moos_timewarp``; code that shares a process with others should use its own
    :class:`MoosClock` (``comms(clock=MoosClock(warp))``) instead.
    """
    DEFAULT_CLOCK.set_warp(warp)


def get_moos_timewarp() -> float:
    return DEFAULT_CLOCK.warp


def is_little_end_in() -> bool:
    """pymoos's (misspelled) byte-order query; MOOS is little-endian on the wire whatever the host."""
    import sys

    return sys.byteorder == "little"


__all__ = [
    "ClientChoice",
    "ConnectionClosedError",
    "HandshakeError",
    "MissionFileError",
    "MoosClock",
    "MoosError",
    "MoosMessage",
    "PoisonedError",
    "ProtocolError",
    "choose_client",
    "comms",
    "get_moos_timewarp",
    "is_little_end_in",
    "local_time",
    "moos_msg",
    "pyMOOSException",
    "set_moos_timewarp",
    "time",
]
