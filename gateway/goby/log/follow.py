"""``LogFollower``: the entries of a ``.goby`` log while goby-logger is still writing it (``tail -f`` for logs).

Each :meth:`LogFollower.poll` reads what was appended since the last one and returns the entries completed by
it; a partial last entry waits for the next poll. Index entries are remembered across polls (a follower that
started at the beginning knows every group and type), descriptor entries fill :attr:`LogFollower.descriptors`.
Spans that are not whole valid entries (bytes between entries, a CRC mismatch, an impossible size) are reported in
:attr:`LogFollower.skipped` and reading goes on at the next ``GBY3``, as :class:`LogReader` does; a partial entry
at the end is not reported (it is still being written). Read a finished log with :class:`LogReader`.
"""

from __future__ import annotations

import logging
import os
from typing import BinaryIO

from gateway.goby.log.descriptors import LogDescriptorPool
from gateway.goby.log.entry import VERSION, LogEntry, SkippedSpan
from gateway.goby.log.reader import EntryParser, read_version

log = logging.getLogger(__name__)


class LogFollower:
    """Follow the log at ``path`` (it may not exist yet: polls return nothing until it does)."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = os.fspath(path)
        self.version: int | None = None
        self.descriptors = LogDescriptorPool()
        self.skipped: list[SkippedSpan] = []
        self._file: BinaryIO | None = None
        self._buf = b""  # read, not yet parsed: an entry still being written
        self._offset = 0  # the file offset of _buf[0]
        self._parser: EntryParser | None = None

    def poll(self) -> list[LogEntry]:
        """The entries completed since the last poll (LogFormatError for a file that is not a log)."""
        if self._file is None:
            try:
                self._file = open(self.path, "rb")  # noqa: SIM115 - kept open across polls, closed by close()
            except FileNotFoundError:
                return []
        self._buf += self._file.read()
        if self._parser is None:
            if len(self._buf) < VERSION.size:
                return []
            self.version = read_version(self._buf[:4], self.path)
            self._parser = EntryParser(self.version, self.path, self._skip, self.descriptors)
            if self.version > 1:
                self._buf = self._buf[VERSION.size:]
                self._offset = VERSION.size
        parser = self._parser
        entries = list(parser.entries(self._buf, 0, final=False, base=self._offset))
        self._buf = self._buf[parser.position:]
        self._offset += parser.position
        return entries

    def _skip(self, span: SkippedSpan) -> None:
        self.skipped.append(span)
        log.warning("%s: %s", self.path, span)

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None

    def __enter__(self) -> LogFollower:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
