"""The ``.alog`` format of MOOS's pLogger (as shipped with MOOS-IvP 19.8.1): formatting, a writer and a reader.

pLogger (``MOOSEssentials/Essentials/pLogger/MOOSLogger.cpp``) writes a banner and then one row per message::

    %%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%
    %% LOG FILE:       ./LOG_ALPHA_3_7_2024_____10_07_44/LOG_ALPHA_3_7_2024_____10_07_44.alog
    %% FILE OPENED ON  Wed Jul  3 10:07:44 2024
    %% LOGSTART               1720001264.56
    %%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%
    2.086           NAV_X                uSimMarine      3.50000
    2.087           DEPLOY               uPokeDB:aux     true

A row is the message time minus LOGSTART (left-aligned in 15, fixed, 3 decimals; 5 since MOOS-IvP 24.8), the
variable (20), the source (15; ``source:aux`` with ``LogAuxSrc``, ``...@community`` with
``MarkExternalCommunityMessages``), the value and a space. A double is fixed with ``DoublePrecision`` decimals
(5) left-aligned in 12; a string is written as it is (a newline in it starts a new physical line); binary data
goes to the ``.blog`` file next to the ``.alog`` (the row's first three columns, the bytes, a newline) and the row
says where: ``<MOOS_BINARY>File=<root>.blog,Offset=<o>,Bytes=<n></MOOS_BINARY>``.

One difference, on purpose: pLogger's ``FILE OPENED ON`` is always the epoch (``MOOSGetDate()`` passes -1, which
it turns into time 0); we write the time the file was opened, in the same ``ctime`` form. No reader uses it.

The reader (:class:`AlogReader`) yields :class:`AlogRecord` (time since LOGSTART, variable, source, value as
``float`` or ``str``) from any alog (pLogger's of any release, ours, aloggrep's output). It joins the lines of a
multi-line string value (pLogger writes them raw: ``DB_VARSUMMARY``), and skips what is not a row, a comment or
such a continuation, recording each skipped line as an :class:`AlogProblem` (line number, reason): garbage, a
row without a source, a truncated last line (the process was killed while writing it). Nothing is skipped
without a problem saying so. Pure: no sockets, no threads; the files are the caller's.
"""

from __future__ import annotations

import importlib
import logging
import math
import os
import re
import time as _time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from .errors import MoosError

log = logging.getLogger(__name__)

BANNER_RULE = "%" * 59
DEFAULT_STEM = "MOOSLog"
DEFAULT_DOUBLE_PRECISION = 5
MAX_LINE_BYTES = 16 * 1024 * 1024  # longer physical lines are reported and skipped, not held in memory


class AlogError(MoosError, ValueError):
    """An alog cannot be read at all (missing, a directory, not an alog), or a value cannot be written."""


@dataclass(frozen=True)
class AlogFormat:
    """The release-dependent precisions: row time decimals and LOGSTART significant digits."""

    time_decimals: int = 3
    logstart_digits: int = 12


PLOGGER_19_8 = AlogFormat(3, 12)  # MOOS-IvP 19.8.1 (MOOS_Jul0519)
PLOGGER_24_8 = AlogFormat(5, 16)  # MOOS-IvP 24.8 (MOOS_Jul2724: "mikerb change from 3-5", "12->16")


# ---- formatting (pure) ----------------------------------------------------------------------------------
def _fixed(value: float, decimals: int) -> str:
    """C++ ``std::fixed``: as Python's ``f``, but a negative NaN prints ``-nan`` as glibc does."""
    if math.isnan(value) and math.copysign(1.0, value) < 0:
        return "-nan"
    return f"{value:.{decimals}f}"


def format_banner(log_file: str, logstart: float, opened_on: float | None = None,
                  mark_data_type: bool = False, fmt: AlogFormat = PLOGGER_19_8) -> str:
    """pLogger's ``DoLogBanner``: the header of every file it writes (alog, ylog, slog, ``._moos``)."""
    when = _time.ctime(_time.time() if opened_on is None else opened_on)
    lines = [BANNER_RULE, f"%% LOG FILE:       {log_file}", f"%% FILE OPENED ON  {when}",
             f"%% LOGSTART        {logstart:>20.{fmt.logstart_digits}g}"]
    if mark_data_type:
        lines.append("%% DATATYPE MARKING ON")
    lines.append(BANNER_RULE)
    return "\n".join(lines) + "\n"


def format_prefix(rel_time: float, var: str, source: str, fmt: AlogFormat = PLOGGER_19_8) -> str:
    """The first three columns of a row and their separators (what a binary entry in the ``.blog`` starts with)."""
    return f"{_fixed(rel_time, fmt.time_decimals):<15} {var:<20} {source:<15} "


def format_value(value: float | str, double_precision: int = DEFAULT_DOUBLE_PRECISION,
                 mark_data_type: bool = False) -> str:
    """``CMOOSMsg::GetAsString(12, precision)`` (and ``D:``/``S:`` with ``MarkDataType``), without the trailing space."""
    if isinstance(value, float | int) and not isinstance(value, bool):
        text = f"{_fixed(float(value), double_precision):<12}"
        return "D:" + text if mark_data_type else text
    if not isinstance(value, str):
        raise AlogError(f"an alog value is a float or a str, not {type(value).__name__}")
    return "S:" + value if mark_data_type else value


def format_row(rel_time: float, var: str, source: str, value: float | str,
               double_precision: int = DEFAULT_DOUBLE_PRECISION, mark_data_type: bool = False,
               fmt: AlogFormat = PLOGGER_19_8) -> str:
    """One alog row of a double or a string, newline included."""
    return f"{format_prefix(rel_time, var, source, fmt)}{format_value(value, double_precision, mark_data_type)} \n"


def binary_marker(blog_name: str, offset: int, size: int) -> str:
    """What an alog row holds in place of binary data: where it is in the ``.blog``."""
    return f"<MOOS_BINARY>File={blog_name},Offset={offset},Bytes={size}</MOOS_BINARY>"


def format_system_row(rel_time: float, var: str, source: str, value: float | str) -> str:
    """A ``.ylog`` row (MOOS_DEBUG, MOOS_SYSTEM): pLogger's ``LogSystemMessages`` widths, precision 7."""
    shown = f"{value:<20.7g}" if isinstance(value, float) else f"{value.replace(chr(10), ''):<20}"
    return f"{rel_time:<10.7g} {var:<20} {source:<20} {shown} \n"


def log_root_name(stem: str, when: float | None = None, utc: bool = False, timestamp: bool = True) -> str:
    """pLogger's ``MakeLogName``: ``<File>_D_M_YYYY_____HH_MM_SS`` (local time, or UTC with UTCLogDirectories),
    or the bare stem with ``FileTimeStamp = false``."""
    if not timestamp:
        return stem
    now = _time.time() if when is None else when
    t = _time.gmtime(now) if utc else _time.localtime(now)
    return (f"{stem}_{t.tm_mday}_{t.tm_mon}_{t.tm_year}_____"
            f"{t.tm_hour:02d}_{t.tm_min:02d}_{t.tm_sec:02d}")


def _encode(text: str) -> bytes:
    return text.encode("utf-8", "surrogateescape")


# ---- writing --------------------------------------------------------------------------------------------
class AlogWriter:
    """Writes one alog (and its ``.blog`` when binary data comes): banner on open, rows as pLogger formats them.

    ``logstart`` is the MOOS time rows are relative to; :meth:`write` takes absolute MOOS times. ``banner=False``
    for pLogger's ``.xlog`` (it has none). Buffered: :meth:`flush` (pLogger flushes every AppTick). Errors of the
    file system (``OSError``: a full disk) propagate to the caller. One thread; a context manager.
    """

    def __init__(self, path: str | os.PathLike[str], logstart: float, *, header_name: str | None = None,
                 blog_path: str | os.PathLike[str] | None = None, double_precision: int = DEFAULT_DOUBLE_PRECISION,
                 mark_data_type: bool = False, fmt: AlogFormat = PLOGGER_19_8, opened_on: float | None = None,
                 banner: bool = True, blog_from: AlogWriter | None = None) -> None:
        self.path = Path(path)
        self._blog_from = blog_from  # binary data goes to that writer's .blog (pLogger's .xlog shares the .alog's)
        self.logstart = logstart
        self.double_precision = double_precision
        self.mark_data_type = mark_data_type
        self.fmt = fmt
        self.blog_path = Path(blog_path) if blog_path is not None else self.path.with_suffix(".blog")
        self.rows = 0
        self._blog: IO[bytes] | None = None
        self._file: IO[bytes] = open(self.path, "wb")  # noqa: SIM115 - closed by close()
        if banner:
            name = header_name if header_name is not None else str(self.path)
            self._file.write(_encode(format_banner(name, logstart, opened_on, mark_data_type, fmt)))

    def open_blog(self) -> None:
        """Create the ``.blog`` now (pLogger always creates it, empty if no binary data comes)."""
        if self._blog_from is not None:
            self._blog_from.open_blog()
            self._blog, self.blog_path = self._blog_from._blog, self._blog_from.blog_path
        elif self._blog is None:
            self._blog = open(self.blog_path, "wb")  # noqa: SIM115 - closed by close()

    def write(self, msg_time: float, var: str, source: str, value: float | str | bytes) -> None:
        """One message: ``value`` a float (double), str (string) or bytes (binary, to the ``.blog``)."""
        rel = msg_time - self.logstart
        if isinstance(value, bytes | bytearray | memoryview):
            self._write_binary(rel, var, source, bytes(value))
        else:
            self._file.write(_encode(format_row(rel, var, source, value, self.double_precision,
                                                self.mark_data_type, self.fmt)))
        self.rows += 1

    def _write_binary(self, rel: float, var: str, source: str, data: bytes) -> None:
        self.open_blog()
        assert self._blog is not None
        prefix = _encode(format_prefix(rel, var, source, self.fmt))
        self._blog.write(prefix)
        offset = self._blog.tell()
        self._blog.write(data)
        self._blog.write(b"\n")
        self._file.write(prefix + _encode(binary_marker(self.blog_path.name, offset, len(data))) + b"\n")

    def flush(self) -> None:
        self._file.flush()
        if self._blog is not None:
            self._blog.flush()

    def close(self) -> None:
        """Flush and close (idempotent); a flush error (full disk) is raised after both files are closed."""
        first: OSError | None = None
        for handle in (self._file, self._blog if self._blog_from is None else None):
            if handle is None or handle.closed:
                continue
            try:
                handle.close()
            except OSError as exc:
                first = first or exc
        if first is not None:
            raise first

    def __enter__(self) -> AlogWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


# ---- reading --------------------------------------------------------------------------------------------
@dataclass(frozen=True, slots=True)
class AlogRecord:
    """One row: ``time`` in seconds since LOGSTART, the variable, the source column as written, the value
    (``float`` for a number, else ``str``; a binary entry is its ``<MOOS_BINARY>`` marker: see
    :meth:`AlogReader.read_binary`), and the line it starts on."""

    time: float
    var: str
    source: str
    value: float | str
    line: int

    @property
    def src(self) -> str:
        """The source without ``:aux`` (aloggrep's ``getSourceNameNoAux``)."""
        return self.source.partition(":")[0]

    @property
    def aux(self) -> str:
        """What follows the first ``:`` of the source (the aux source with ``LogAuxSrc``), or ``""``."""
        return self.source.partition(":")[2]

    def is_binary(self) -> bool:
        return isinstance(self.value, str) and self.value.startswith("<MOOS_BINARY>")

    def as_dict(self) -> dict[str, Any]:
        return {"time": self.time, "var": self.var, "source": self.source, "value": self.value}


@dataclass(frozen=True, slots=True)
class AlogProblem:
    """A line the reader skipped, and why."""

    line: int
    reason: str
    text: str

    def __str__(self) -> str:
        return f"line {self.line}: {self.reason}: {self.text[:80]!r}"


@dataclass
class AlogHeader:
    """What the banner says (``None`` where a line is missing)."""

    log_file: str | None = None
    opened_on: str | None = None
    logstart: float | None = None
    data_type_marking: bool = False


_ROW = re.compile(r"([^ \t]+)[ \t]+([^ \t]+)[ \t]+([^ \t]+)(?:[ \t](.*))?", re.DOTALL)
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?|nan|inf)")
_BINARY = re.compile(r"<MOOS_BINARY>File=(.*),Offset=(\d+),Bytes=(\d+)</MOOS_BINARY>")


def _time_of(token: str) -> float | None:
    if not _NUMBER.fullmatch(token):
        return None
    return float(token)


class _Pending:
    """A record being read: a string value may continue on the following lines."""

    __slots__ = ("time", "var", "source", "parts", "line", "is_string", "marked")

    def __init__(self, time: float, var: str, source: str, raw: str, line: int, marking: bool) -> None:
        self.time, self.var, self.source, self.line = time, var, source, line
        self.parts = [raw]
        self.marked: str | None = None
        text = raw.lstrip(" \t")
        if marking and text[:2] in ("D:", "S:"):
            self.marked = text[0]
            text = text[2:]
        self.parts[0] = text
        stripped = text.rstrip(" \t")
        self.is_string = self.marked == "S" or not (
            self.marked == "D" or _NUMBER.fullmatch(stripped) or _BINARY.fullmatch(stripped))

    def record(self) -> AlogRecord:
        text = "\n".join(self.parts)
        if not self.is_string:
            return AlogRecord(self.time, self.var, self.source, _to_value(text.strip(" \t")), self.line)
        if text.endswith(" "):
            text = text[:-1]  # pLogger ends every row with one space
        return AlogRecord(self.time, self.var, self.source, text, self.line)


def _to_value(text: str) -> float | str:
    if _NUMBER.fullmatch(text):
        return float(text)
    return text


class AlogReader:
    """Iterate the records of an alog: ``for rec in AlogReader(path): ...``; then :attr:`problems`.

    ``source``: a path, or a binary file object (then :meth:`read_binary` needs ``blog_dir``). The banner is read
    on construction (:attr:`header`); a file that does not exist or is a directory raises :class:`AlogError`.
    Skipped lines are logged once, as a summary, when the iteration ends. Iterate once.
    """

    def __init__(self, source: str | os.PathLike[str] | IO[bytes], *, blog_dir: str | os.PathLike[str] | None = None,
                 join_continuations: bool = True) -> None:
        self.problems: list[AlogProblem] = []
        self.header = AlogHeader()
        self.join_continuations = join_continuations
        if isinstance(source, str | os.PathLike):
            self.path: Path | None = Path(source)
            try:
                self._file: IO[bytes] = open(self.path, "rb")  # noqa: SIM115 - closed when iteration ends
            except OSError as exc:
                raise AlogError(f"cannot read alog {self.path}: {exc.strerror or exc}") from exc
            self.blog_dir = Path(blog_dir) if blog_dir is not None else self.path.parent
        else:
            self.path = None
            self._file = source
            self.blog_dir = Path(blog_dir) if blog_dir is not None else Path(".")
        self._line_no = 0
        self._first: tuple[bytes, int] | None = None
        self._read_header()

    def _readline(self) -> tuple[bytes, int] | None:
        raw = self._file.readline(MAX_LINE_BYTES)
        if not raw:
            return None
        self._line_no += 1
        if len(raw) == MAX_LINE_BYTES and not raw.endswith(b"\n"):
            rest = 0
            while True:  # skip the remainder of the over-long line without holding it
                more = self._file.readline(MAX_LINE_BYTES)
                rest += len(more)
                if not more or more.endswith(b"\n"):
                    break
            self.problems.append(AlogProblem(self._line_no, f"line longer than {MAX_LINE_BYTES} bytes "
                                             f"({len(raw) + rest} bytes)", raw[:80].decode("latin-1")))
            return b"", self._line_no
        return raw, self._line_no

    def _read_header(self) -> None:
        while True:
            got = self._readline()
            if got is None:
                return
            raw, number = got
            if not raw.startswith(b"%"):
                self._first = got
                return
            self._header_line(raw.decode("utf-8", "surrogateescape").rstrip("\r\n"))

    def _header_line(self, text: str) -> None:
        body = text.lstrip("%").strip()
        if body.startswith("LOG FILE:"):
            self.header.log_file = body[len("LOG FILE:"):].strip()
        elif body.startswith("FILE OPENED ON"):
            self.header.opened_on = body[len("FILE OPENED ON"):].strip()
        elif body.startswith("LOGSTART"):
            value = body[len("LOGSTART"):].strip().split(" ")[0]
            self.header.logstart = float(value) if _NUMBER.fullmatch(value) else None
            if self.header.logstart is None:
                self.problems.append(AlogProblem(self._line_no, "LOGSTART is not a number", text))
        elif body == "DATATYPE MARKING ON":
            self.header.data_type_marking = True

    def _lines(self) -> Iterator[tuple[bytes, int]]:
        if self._first is not None:
            yield self._first
            self._first = None
        while (got := self._readline()) is not None:
            yield got

    def __iter__(self) -> Iterator[AlogRecord]:
        pending: _Pending | None = None
        marking = self.header.data_type_marking
        try:
            for raw, number in self._lines():
                complete = raw.endswith(b"\n")
                text = raw.decode("utf-8", "surrogateescape").rstrip("\n")
                if text.endswith("\r"):
                    text = text[:-1]
                if text.startswith("%"):
                    if pending is not None:
                        yield pending.record()
                        pending = None
                    continue  # a comment (a banner line, or one a tool added)
                match = _ROW.fullmatch(text)
                when = _time_of(match.group(1)) if match else None
                if match and when is not None:
                    if pending is not None:
                        yield pending.record()
                        pending = None
                    if not complete:
                        self.problems.append(AlogProblem(number, "truncated last line (no newline)", text))
                        break
                    pending = _Pending(when, match.group(2), match.group(3), match.group(4) or "", number, marking)
                    continue
                if pending is not None and self.join_continuations and pending.is_string:
                    if not complete:
                        self.problems.append(AlogProblem(pending.line, "truncated last record (no newline at the "
                                                         f"end of the file, line {number})", text))
                        pending = None
                        break
                    pending.parts.append(text)
                    continue
                if pending is not None:
                    yield pending.record()
                    pending = None
                if not complete:
                    self.problems.append(AlogProblem(number, "truncated last line (no newline)", text))
                elif text.strip():
                    self.problems.append(AlogProblem(number, self._why(text), text))
            if pending is not None:
                yield pending.record()
        finally:
            if self.path is not None:
                self._file.close()
            self._report()

    @staticmethod
    def _why(text: str) -> str:
        first = text.split(None, 1)[0] if text.split() else ""
        if _time_of(first) is None:
            return "not an alog row (the first column is not a time)"
        return "not an alog row (fewer than three columns: time, variable, source)"

    def _report(self) -> None:
        if self.problems:
            name = self.path or "alog"
            log.warning("%s: %d line(s) skipped; first: %s", name, len(self.problems), self.problems[0])

    def read_binary(self, record: AlogRecord) -> bytes:
        """The bytes of a binary entry, from the ``.blog`` its marker names (in ``blog_dir``)."""
        match = _BINARY.fullmatch(record.value) if isinstance(record.value, str) else None
        if match is None:
            raise AlogError(f"line {record.line}: {record.var} is not a binary entry")
        path = self.blog_dir / Path(match.group(1)).name
        offset, size = int(match.group(2)), int(match.group(3))
        try:
            with open(path, "rb") as blog:
                blog.seek(offset)
                data = blog.read(size)
        except OSError as exc:
            raise AlogError(f"line {record.line}: cannot read {path}: {exc.strerror or exc}") from exc
        if len(data) != size:
            raise AlogError(f"line {record.line}: {path} holds {len(data)} of the {size} bytes at offset {offset}")
        return data


def read_alog(source: str | os.PathLike[str] | IO[bytes], **kwargs: Any) -> tuple[list[AlogRecord], AlogReader]:
    """All records of an alog and the reader (its ``header`` and ``problems``)."""
    reader = AlogReader(source, **kwargs)
    return list(reader), reader


def records_to_dicts(records: Iterable[AlogRecord]) -> list[dict[str, Any]]:
    """Rows for ``pandas.DataFrame(...)``, ``csv.DictWriter`` or JSON: time, var, source, value."""
    return [r.as_dict() for r in records]


def to_dataframe(source: str | os.PathLike[str] | Iterable[AlogRecord]) -> Any:
    """A ``pandas.DataFrame`` (columns time, var, source, value) of an alog path or of records.

    pandas is not a dependency of this project: this raises :class:`AlogError` saying so when it is missing.
    """
    try:
        pandas = importlib.import_module("pandas")  # optional: not a dependency, not type-checked
    except ImportError as exc:
        raise AlogError("to_dataframe needs pandas, which is not installed (pip install pandas); "
                        "records_to_dicts() gives the same rows without it") from exc
    if isinstance(source, str | os.PathLike):
        source = AlogReader(source)
    return pandas.DataFrame(records_to_dicts(source), columns=["time", "var", "source", "value"])
