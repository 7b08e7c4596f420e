"""``make_comms``: choose our client or the real pymoos (when importable) at run time."""

from __future__ import annotations

import importlib
import logging
import os
from typing import Any

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


def make_comms(kind: str | None = None) -> Any:
    """A new comms object: ``"ours"`` (this package), ``"pymoos"`` (the real binding) or ``"auto"``.

    ``kind=None`` reads ``GOBY_MOOS_CLIENT`` (default ``"ours"``). ``"auto"`` prefers the real pymoos when it is
    importable and falls back to ours. Asking for ``"pymoos"`` when it is missing raises MoosError.
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
            return pymoos.comms()
    from .client import comms

    return comms()
