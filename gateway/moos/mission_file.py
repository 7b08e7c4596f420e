"""``MissionFile``: read a ``.moos`` mission file the way libMOOS's CMOOSFileReader does.

Global parameters follow ``GetValue``: whitespace is removed from the whole line, the name is matched
case-insensitively, and the first match anywhere in the file wins (inside ProcessConfig blocks too).
Process blocks follow ``GetConfigurationAndPreserveSpace``: file order, keys as written, values trimmed
with their internal spaces kept. A file that is not text (a NUL byte, or mostly bytes that are neither UTF-8 nor
printable) is refused, naming file and line: libMOOS would read it as an empty mission and serve on defaults.
"""

from __future__ import annotations

import functools
import logging
import math
import os
import re
from pathlib import Path

from .errors import MissionFileError

log = logging.getLogger(__name__)

MAX_LINE_CHARS = 2000
MAX_NON_TEXT_FRACTION = 0.1  # a stray Latin-1 byte in a comment is fine; a binary file is not
_CONTROL = re.compile(r"[\x00-\x08\x0b\x0e-\x1f\x7f]|[\udc80-\udcff]")
_DEFINE = re.compile(r"^define\s*:\s*([^=\s]+)\s*=\s*(.*)$", re.IGNORECASE)
_REFERENCE = re.compile(r"\$\{([^}]*)\}")
_WHITESPACE = re.compile(r"[ \t]+")


def _strip_comment(line: str) -> str:
    """Remove a ``//`` comment; the first double-quoted section is unquoted and kept verbatim."""
    first = line.find('"')
    second = line.find('"', first + 1) if first >= 0 else -1
    comment = line.find("//")
    if first < 0 or second < 0 or (0 <= comment < first):
        return line[:comment] if comment >= 0 else line
    before, quoted, after = line[:first], line[first + 1 : second], line[second + 1 :]
    cut = after.find("//")
    if cut >= 0:
        after = after[:cut]
    return before + quoted + after


class MissionFile:
    """A parsed ``.moos`` file. Names of globals and of process blocks are case-insensitive."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        try:
            text = self.path.read_text(encoding="utf-8", errors="surrogateescape")
        except OSError as exc:
            raise MissionFileError(f"cannot read mission file {self.path}: {exc.strerror or exc}") from exc
        self._lines, self._numbers = self._valid_lines(text)

    def _check_text(self, text: str) -> None:
        """Raise ``MissionFileError`` for a file that is not text: a NUL, or too many control/undecodable bytes."""
        nul = text.find("\0")
        bad = nul if nul >= 0 else -1
        if bad < 0:
            odd = _CONTROL.findall(text)
            if len(odd) <= MAX_NON_TEXT_FRACTION * max(len(text), 1):
                return
            bad = _CONTROL.search(text).start()  # type: ignore[union-attr]
        line = text.count("\n", 0, bad) + 1
        what = "a NUL byte" if nul >= 0 else "mostly control characters or bytes that are not UTF-8"
        raise MissionFileError(f"{self.path}:{line}: not a text mission file ({what}); is it the right file?")

    @classmethod
    def from_text(cls, text: str, name: str = "<string>") -> MissionFile:
        """Parse mission-file text that is not on disk (handy for generated missions and tests)."""
        self = cls.__new__(cls)
        self.path = Path(name)
        self._lines, self._numbers = self._valid_lines(text)
        return self

    def _valid_lines(self, text: str) -> tuple[list[str], list[int]]:
        """The lines ``GetNextValidLine`` would return (trimmed, uncommented, defines expanded) and their numbers."""
        self._check_text(text)
        defines: dict[str, str] = {}
        lines: list[str] = []
        numbers: list[int] = []
        for number, raw in enumerate(text.splitlines(), start=1):
            if len(raw) > MAX_LINE_CHARS:
                log.warning("%s:%d: line longer than %d characters is cut", self.path, number, MAX_LINE_CHARS)
                raw = raw[:MAX_LINE_CHARS]
            line = raw.strip()
            if not line or line.startswith("//"):
                continue
            line = _strip_comment(line).strip()
            if not line:
                continue
            line = _REFERENCE.sub(functools.partial(self._substitute, defines=defines, number=number), line)
            match = _DEFINE.match(line)
            if match:
                defines[match.group(1)] = match.group(2).strip()
                continue
            lines.append(line)
            numbers.append(number)
        return lines, numbers

    def _substitute(self, match: re.Match[str], defines: dict[str, str], number: int) -> str:
        return self._lookup(match.group(1), defines, number)

    def _lookup(self, name: str, defines: dict[str, str], number: int) -> str:
        if name in defines:
            return defines[name]
        if name in os.environ:
            return os.environ[name]
        log.error("%s:%d: ${%s} is neither defined in the file nor in the environment", self.path, number, name)
        return ""

    # ---- global parameters ------------------------------------------------------------------------
    def global_value(self, name: str) -> str | None:
        """The value of global ``name`` (whitespace removed, as MOOS does), or None if absent."""
        found = self._global(name)
        return None if found is None else found[0]

    def _global(self, name: str) -> tuple[str, int] | None:
        """(value, line number) of global ``name``, or None."""
        wanted = name.strip().lower()
        for line, number in zip(self._lines, self._numbers, strict=True):
            squeezed = _WHITESPACE.sub("", line)
            token, sep, value = squeezed.partition("=")
            if sep and token.lower() == wanted:
                return value, number
        return None

    def global_number(self, name: str, low: float = -math.inf, high: float = math.inf,
                      low_inclusive: bool = True) -> float | None:
        """Global ``name`` as a finite number within [low, high] (or (low, high]), or None if absent or empty.

        Raises ``MissionFileError`` naming the file, the line and the value otherwise.
        """
        found = self._global(name)
        if found is None or found[0] == "":
            return None
        value, number = found
        try:
            result = float(value)
        except ValueError:
            result = math.nan
        in_range = (result >= low if low_inclusive else result > low) and result <= high
        if not (math.isfinite(result) and in_range):
            bounds = f"{'[' if low_inclusive else '('}{low:g}, {high:g}]"
            raise MissionFileError(f"{self.path}:{number}: {name} = {value!r} is not a number in {bounds}")
        return result

    def check(self) -> None:
        """Raise ``MissionFileError`` (file:line) for a malformed ``ProcessConfig`` block anywhere in the file."""
        for name in self.process_names():
            self._block_lines(name)

    @property
    def server_host(self) -> str:
        """``ServerHost`` (default ``localhost``, as libMOOS's ``LOCALHOST``)."""
        return self.global_value("ServerHost") or "localhost"

    @property
    def server_port(self) -> int:
        """``ServerPort`` (default 9000)."""
        value = self.global_number("ServerPort", 0, 65535)
        return 9000 if value is None else int(value)

    @property
    def community(self) -> str:
        """``Community`` (default ``#1``, the MOOSDB default)."""
        return self.global_value("Community") or "#1"

    @property
    def time_warp(self) -> float:
        """``MOOSTimeWarp`` (default 1.0)."""
        value = self.global_number("MOOSTimeWarp", 0, math.inf, low_inclusive=False)
        return 1.0 if value is None else value

    @property
    def lat_origin(self) -> float | None:
        return self.global_number("LatOrigin", -90, 90)

    @property
    def long_origin(self) -> float | None:
        return self.global_number("LongOrigin", -180, 180)

    # ---- process blocks ---------------------------------------------------------------------------
    def process_names(self) -> list[str]:
        """Names of every ``ProcessConfig = name`` block, in file order."""
        names = []
        for line in self._lines:
            token, sep, value = _WHITESPACE.sub("", line).partition("=")
            if sep and token.lower() == "processconfig":
                names.append(value)
        return names

    def has_process_config(self, app: str) -> bool:
        return self._block_lines(app) is not None

    def _block_lines(self, app: str) -> list[str] | None:
        header = "processconfig=" + _WHITESPACE.sub("", app).lower()
        lines = self._lines
        for i, line in enumerate(lines):
            if _WHITESPACE.sub("", line).lower() != header:
                continue
            where = f"{self.path}:{self._numbers[i]}"
            if i + 1 >= len(lines) or not lines[i + 1].startswith("{"):
                raise MissionFileError(f"{where}: 'ProcessConfig = {app}' is not followed by '{{'")
            body: list[str] = []
            for inner in lines[i + 2 :]:
                if inner.startswith("}"):
                    return body
                body.append(inner)
            raise MissionFileError(f"{where}: block 'ProcessConfig = {app}' has no closing '}}'")
        return None

    def process_config(self, app: str) -> list[tuple[str, str]]:
        """The ``(key, value)`` pairs of app's block in file order, or ``[]`` if there is no such block."""
        body = self._block_lines(app)
        if body is None:
            return []
        pairs = []
        for line in body:
            token, _, value = line.partition("=")
            token, value = token.strip(), value.strip()
            if not value and "[" not in line and "]" not in line:
                continue
            pairs.append((token, value))
        return pairs

    def process_param(self, app: str, name: str) -> str | None:
        """The first value of ``name`` (case-insensitive) in app's block, or None."""
        wanted = name.strip().lower()
        for token, value in self.process_config(app):
            if token.lower() == wanted:
                return value
        return None
