"""Logging set-up shared by every console script: Goby-style verbosity flags mapped onto ``logging``.

``-v`` shows INFO, ``-vv`` DEBUG, ``-vvv`` TRACE (a level below DEBUG for per-message detail).
Each component logs through its own logger (``logging.getLogger(__name__)``); this module only
configures the root handler once per process.
"""

from __future__ import annotations

import argparse
import logging

TRACE = 5
logging.addLevelName(TRACE, "TRACE")

_LEVELS = {0: logging.WARNING, 1: logging.INFO, 2: logging.DEBUG}


def add_verbosity_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``-v/--verbose`` (repeatable) to ``parser``; read it back as ``args.verbose``."""
    parser.add_argument(
        "-v", "--verbose", action="count", default=0, help="more output: -v info, -vv debug, -vvv trace"
    )


def level_for(verbosity: int) -> int:
    """The logging level for a count of ``-v`` flags."""
    return _LEVELS.get(verbosity, TRACE)


def configure_logging(verbosity: int = 0, app_name: str | None = None) -> None:
    """Configure the root logger for a process; call once from a console script's ``main``."""
    prefix = f"{app_name} " if app_name else ""
    logging.basicConfig(
        level=level_for(verbosity),
        format=f"%(asctime)s {prefix}%(name)s %(levelname)s: %(message)s",
        force=True,
    )
