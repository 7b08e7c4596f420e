"""The one error the techniques raise."""

from __future__ import annotations

from translators.errors import TranslatorError


class TechniqueError(TranslatorError, ValueError):
    """A MOOS string could not be parsed into (or a message serialized for) the requested technique.

    The message names the technique or format and what was wrong with the input.
    """
