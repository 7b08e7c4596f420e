"""Errors of the helm: one root, one subclass per kind, each naming where the problem is."""

from __future__ import annotations


class IvPHelmError(Exception):
    """Root of every error the helm raises."""


class BehaviorFileError(IvPHelmError):
    """A .bhv file (or a helm config line) that cannot be used; names the file, the line and the token."""

    def __init__(self, path: str, line: int, token: str, reason: str) -> None:
        self.path, self.line, self.token, self.reason = path, line, token, reason
        super().__init__(f"{path}:{line}: {reason} (at '{token}')")


class ParamError(IvPHelmError):
    """A behaviour or helm parameter with a bad value; the caller adds file and line."""


class UnknownParamError(ParamError):
    """A parameter name the behaviour (or the helm) does not have."""


class ConditionError(IvPHelmError):
    """A logic condition that does not parse; ``token`` is the offending part."""

    def __init__(self, text: str, token: str, reason: str) -> None:
        self.text, self.token, self.reason = text, token, reason
        super().__init__(f"bad condition '{text}': {reason} (at '{token}')")
