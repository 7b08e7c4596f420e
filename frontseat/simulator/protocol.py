"""Codec of the basic simulator's line protocol (``KEY,NAME:value,NAME:value`` lines ended by ``\\r\\n``).

Pure functions of text, shared by the simulator and its driver, with Goby's conversion rules: a number that
does not parse reads as NaN (doubles) or INT_MAX (ints) instead of raising, the first occurrence of a
duplicated field wins, and a field without ``:`` makes the whole line invalid.
"""

from __future__ import annotations

import math
import re

from frontseat.errors import SimulatorLineError

DELIMITER = b"\r\n"
INT_MAX = 2**31 - 1
INT_MIN = -(2**31)

CTRL_PAYLOAD = "CTRL,STATE:PAYLOAD"
CTRL_IDLE = "CTRL,STATE:IDLE"
CMD_OK = "CMD,RESULT:OK"
CMD_ERROR = "CMD,RESULT:ERROR"
START_ERROR = "START,RESULT:ERROR"  # ours: Goby's simulator answers an invalid START with nothing

_DOUBLE = re.compile(r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)", re.IGNORECASE)
_INT = re.compile(r"[+-]?\d+")


class LineSplitter:
    """Bytes in, complete lines out: the one ``\\r\\n`` framing of the protocol (simulator, driver, test client).

    Lines are decoded as UTF-8 (invalid bytes replaced). A line longer than ``max_line`` bytes is discarded up to its
    next delimiter; :attr:`overflowed` is True after the :meth:`feed` that started discarding one (to log it once).
    :attr:`partial` is the number of bytes of an unfinished, not discarded line.
    """

    def __init__(self, max_line: int = 64 * 1024) -> None:
        self.max_line = max_line
        self.overflowed = False
        self._buffer = bytearray()
        self._discarding = False

    @property
    def partial(self) -> int:
        return 0 if self._discarding else len(self._buffer)

    def feed(self, data: bytes) -> list[str]:
        """The lines completed by ``data``, in order."""
        self._buffer += data
        lines = []
        while (end := self._buffer.find(DELIMITER)) >= 0:
            raw = bytes(self._buffer[:end])
            del self._buffer[: end + len(DELIMITER)]
            if self._discarding:
                self._discarding = False
                continue
            lines.append(raw.decode("utf-8", errors="replace"))
        self.overflowed = False
        if len(self._buffer) > self.max_line:
            self.overflowed = not self._discarding
            self._discarding = True
            del self._buffer[:-1]  # keep the last byte: it may be the '\\r' of a delimiter split across reads
        return lines


def encode_lines(lines: list[str] | tuple[str, ...]) -> bytes:
    """Lines as bytes on the wire, each ended by ``\\r\\n``."""
    return b"".join(line.encode() + DELIMITER for line in lines)


def line_key(line: str) -> str:
    """The first comma-separated token (the message type), even for a line whose fields are malformed."""
    return line.split(",", 1)[0]


def parse_line(line: str) -> tuple[str, dict[str, str]]:
    """Split ``KEY,A:1,B:2`` into ``("KEY", {"A": "1", "B": "2"})``.

    Parts of a field after a second ``:`` are ignored. Raises :class:`SimulatorLineError` for a field with no
    ``:`` (including the empty field of ``,,`` or of a trailing comma).
    """
    key, *tokens = line.split(",")
    fields: dict[str, str] = {}
    for token in tokens:
        name, sep, rest = token.partition(":")
        if not sep:
            raise SimulatorLineError(f"field {token!r} has no ':'")
        fields.setdefault(name, rest.split(":", 1)[0])
    return key, fields


def as_double(text: str | None) -> float:
    """Goby's ``as<double>``: the value, or NaN when absent or not a number."""
    if text is None or not _DOUBLE.fullmatch(text):
        return math.nan
    return float(text)


def as_int(text: str | None) -> int:
    """Goby's ``as<int>``: the value, or INT_MAX when absent, not an integer, or outside int32."""
    if text is None or not _INT.fullmatch(text):
        return INT_MAX
    value = int(text)
    return value if INT_MIN <= value <= INT_MAX else INT_MAX


def is_int(text: str) -> bool:
    """True if ``text`` is an integer that fits int32 (what ``as<int>`` converts without falling back)."""
    return bool(_INT.fullmatch(text)) and INT_MIN <= int(text) <= INT_MAX


def format_g(value: float, digits: int = 6) -> str:
    """C's ``%.<digits>g`` (what an ostream prints); NaN prints as ``nan``."""
    return format(value, f".{digits}g")


def nav_line(lat: float, lon: float, depth: float, heading: float, speed: float) -> str:
    """The simulator's navigation report, every value at 10 significant digits."""
    return (
        f"NAV,LAT:{format_g(lat, 10)},LON:{format_g(lon, 10)},DEPTH:{format_g(depth, 10)},"
        f"HEADING:{format_g(heading, 10)},SPEED:{format_g(speed, 10)}"
    )


def start_line(
    lat: float,
    lon: float,
    duration: int,
    freq: int,
    accel: float,
    hdg_rate: float,
    z_rate: float,
    warp: int,
) -> str:
    """The driver's START line (doubles at ``%g``, i.e. 6 significant digits)."""
    return (
        f"START,LAT:{format_g(lat)},LON:{format_g(lon)},DURATION:{duration},FREQ:{freq},"
        f"ACCEL:{format_g(accel)},HDG_RATE:{format_g(hdg_rate)},Z_RATE:{format_g(z_rate)},WARP:{warp}"
    )


def command_line(heading: float, speed: float, depth: float) -> str:
    """The driver's desired-course command (``%g``)."""
    return f"CMD,HEADING:{format_g(heading)},SPEED:{format_g(speed)},DEPTH:{format_g(depth)}"
