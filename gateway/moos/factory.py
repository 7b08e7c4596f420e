"""``choose_client``: our client or the real pymoos (when importable), chosen at run time, with its time source."""

from __future__ import annotations

import importlib
import logging
import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .clock import MoosClock
from .errors import MoosError

log = logging.getLogger(__name__)

ENV_VAR = "GOBY_MOOS_CLIENT"
KINDS = ("auto", "ours", "pymoos")


@dataclass(frozen=True)
class ClientChoice:
    """What :func:`choose_client` made: the pymoos-compatible ``comms`` object, the ``MOOSTime`` function that
    matches it (its own clock for our client, ``pymoos.time`` for the real one) and which kind it is."""

    comms: Any
    moos_time: Callable[[], float]
    kind: str  # "ours" or "pymoos"


def pymoos_available() -> bool:
    """True when a real (compiled) ``pymoos`` module can be imported."""
    try:
        importlib.import_module("pymoos")
    except ImportError:
        return False
    return True


def choose_client(kind: str | None = None, *, clock: MoosClock | None = None) -> ClientChoice:
    """A new client: ``"ours"`` (this package), ``"pymoos"`` (the real binding) or ``"auto"``.

    ``kind=None`` reads ``GOBY_MOOS_CLIENT`` (default ``"ours"``). ``"auto"`` prefers the real pymoos when it is
    importable and falls back to ours. Asking for ``"pymoos"`` when it is missing raises MoosError.

    ``clock`` gives our client its own :class:`MoosClock` (its warp, and the skew it learns; default: pymoos's
    process-wide one). The real pymoos has only libMOOS's process-wide clock: there ``clock``'s warp is applied
    to it (``pymoos.set_moos_timewarp``, as Goby's ``SetMOOSTimeWarp``).
    """
    chosen = (kind or os.environ.get(ENV_VAR) or "ours").strip().lower()
    if chosen not in KINDS:
        raise MoosError(f"unknown MOOS client kind {chosen!r}; expected one of {', '.join(KINDS)} ({ENV_VAR})")
    if chosen in ("pymoos", "auto"):
        try:
            pymoos = importlib.import_module("pymoos")
        except ImportError as exc:
            if chosen == "pymoos":
                raise MoosError(f"the real pymoos was requested but cannot be imported: {exc}") from exc
        else:
            log.debug("using the real pymoos from %s", getattr(pymoos, "__file__", "?"))
            if clock is not None:
                pymoos.set_moos_timewarp(clock.warp)
            return ClientChoice(pymoos.comms(), pymoos.time, "pymoos")
    from .client import comms

    client = comms(clock=clock)
    return ClientChoice(client, client.clock.time, "ours")
