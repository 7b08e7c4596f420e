"""The root of every error the ``translators`` package raises on purpose.

Each kind also derives from ``ValueError`` where it reports bad input (a MOOS string, a setpoint, a command),
so callers that treat bad input as a value error keep working.
"""

from __future__ import annotations


class TranslatorError(Exception):
    """Root of every error raised on purpose by ``translators`` (techniques, helm conversion, USV commands)."""
