"""``choose_client``: our client or the real pymoos (when importable), chosen at run time, with its time source.

Our client can live on its user's reactor (``reactor=``: no thread of its own, callbacks on that reactor's thread);
the real pymoos always runs its own I/O thread. :class:`ClientChoice` says which happened (``reactor``), so its user
knows whether the callbacks arrive on its own thread or must be handed over.
"""

from __future__ import annotations

import importlib
import logging
import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .clock import MoosClock
from .errors import MoosError

if TYPE_CHECKING:
    from util.reactor import Reactor

log = logging.getLogger(__name__)

ENV_VAR = "GOBY_MOOS_CLIENT"
KINDS = ("auto", "ours", "pymoos")


@dataclass(frozen=True)
class ClientChoice:
    """What :func:`choose_client` made: the pymoos-compatible ``comms`` object, the ``MOOSTime`` function that
    matches it (its own clock for our client, ``pymoos.time`` for the real one), which kind it is, and the reactor
    its callbacks run on (None: the client's own I/O thread)."""

    comms: Any
    moos_time: Callable[[], float]
    kind: str  # "ours" or "pymoos"
    reactor: Reactor | None = None


def pymoos_available() -> bool:
    """True when a real (compiled) ``pymoos`` module can be imported."""
    try:
        importlib.import_module("pymoos")
    except ImportError:
        return False
    return True


def choose_client(kind: str | None = None, *, clock: MoosClock | None = None,
                  reactor: Reactor | None = None) -> ClientChoice:
    """A new client: ``"ours"`` (this package), ``"pymoos"`` (the real binding) or ``"auto"``.

    ``kind=None`` reads ``GOBY_MOOS_CLIENT`` (default ``"ours"``). ``"auto"`` prefers the real pymoos when it is
    importable and falls back to ours. Asking for ``"pymoos"`` when it is missing raises MoosError.

    ``clock`` gives our client its own :class:`MoosClock` (its warp, and the skew it learns; default: pymoos's
    process-wide one). The real pymoos has only libMOOS's process-wide clock: there ``clock``'s warp is applied
    to it (``pymoos.set_moos_timewarp``, as Goby's ``SetMOOSTimeWarp``).

    ``reactor`` puts our client on that reactor (``comms(reactor=...)``: no I/O thread; its callbacks run on the
    reactor's thread, and ``wait_until_connected`` may not wait there). The real pymoos cannot: it keeps its own
    I/O thread, and the choice's ``reactor`` is None.
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

    client = comms(clock=clock, reactor=reactor)
    return ClientChoice(client, client.clock.time, "ours", reactor)
