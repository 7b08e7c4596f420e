"""``make_comms``: choose our client or the real pymoos (when importable) at run time."""

from __future__ import annotations

import importlib
import logging
import os
from collections.abc import Callable
from typing import Any

from .clock import DEFAULT_CLOCK, MoosClock
from .errors import MoosError

log = logging.getLogger(__name__)

ENV_VAR = "GOBY_MOOS_CLIENT"
KINDS = ("auto", "ours", "pymoos")


def pymoos_available() -> bool:
    """True when a real (compiled) ``pymoos`` module can be imported."""
    try:
        importlib.import_module("pymoos")
    except ImportError:
        return False
    return True


def make_comms(kind: str | None = None, *, clock: MoosClock | None = None) -> Any:
    """A new comms object: ``"ours"`` (this package), ``"pymoos"`` (the real binding) or ``"auto"``.

    ``kind=None`` reads ``GOBY_MOOS_CLIENT`` (default ``"ours"``). ``"auto"`` prefers the real pymoos when it is
    importable and falls back to ours. Asking for ``"pymoos"`` when it is missing raises MoosError.

    ``clock`` gives our client its own :class:`MoosClock` (its warp, and the skew it learns; default: the
    process-wide one). The real pymoos has only libMOOS's process-wide clock: there ``clock``'s warp is applied to
    it (``pymoos.set_moos_timewarp``, as Goby's ``SetMOOSTimeWarp``) and :func:`moos_time_source` reads it.
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
            return pymoos.comms()
    from .client import comms

    return comms(clock=clock)


def moos_time_source(client: Any) -> Callable[[], float]:
    """The ``MOOSTime`` function matching ``client``: its own clock's ``time`` for our client, ``pymoos.time``
    for the real pymoos (whose time is process-wide)."""
    from .engine import ClientEngine

    if isinstance(client, ClientEngine):
        return client.clock.time
    module = importlib.import_module(type(client).__module__.split(".")[0])
    source = getattr(module, "time", None)
    return source if callable(source) else DEFAULT_CLOCK.time
