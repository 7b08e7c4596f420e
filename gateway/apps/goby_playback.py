"""``goby-playback``: publish a ``.goby`` log's entries on a broker with their original groups, types and relative
timing (goby_playback's role and config).

Config: ``PlaybackConfig`` (gateway/goby/log/protobuf/logger_config.proto, Goby's fields): ``input_file``
(positional, ``-i`` or ``--input_file``), ``rate`` (2 = twice as fast), ``playback_start_delay`` (s before the
first entry), ``start_from_offset`` (s of the log skipped), ``group_regex``, ``type_filter { scheme regex }``,
``load_shared_library``; ``app {}``, ``interprocess {}`` or ``GOBY_INTERPROCESS``; ``-c`` for a config file.

Entry *k* is published when ``(now - start) * rate >= t_k - t_first`` on the application's clock, so a warp
(``app.simulation.time``) speeds playback up by its factor too; ``start`` is ``playback_start_delay`` after the
broker released the hold (Goby counts from construction, and entries due before the release would wait in the
hold queue).  Each entry is a timer on the application's
reactor (no polling loop); Goby's internal groups (``goby::zeromq::_internal_*``) and the descriptor entries are
not replayed.  Skipped spans of a damaged log are reported; playback ends (exit 0) after the last entry.
"""

from __future__ import annotations

import logging
import math
import re
import sys
from collections.abc import Iterator

from gateway.apps.goby_log_tool import positional_argv
from gateway.apps.goby_logger import compile_regex, load_protobuf_modules
from gateway.goby.log.entry import LogEntry
from gateway.goby.log.errors import LogFormatError
from gateway.goby.log.protobuf.logger_config_pb2 import PlaybackConfig
from gateway.goby.log.reader import LogReader
from gateway.goby.portal import SingleThreadApplication, StartError, run_application
from gateway.goby.portal.timeutil import si_to_micro, time_str

log = logging.getLogger(__name__)

INTERNAL_GROUPS = re.compile(r"goby::zeromq::_internal_.*")


class GobyPlayback(SingleThreadApplication):
    """Publish the entries of ``cfg.input_file`` at their recorded pace (times ``rate``)."""

    def __init__(self, cfg: PlaybackConfig) -> None:
        super().__init__(cfg)
        if not (math.isfinite(cfg.rate) and cfg.rate > 0):
            raise StartError(f"rate {cfg.rate} must be a finite number > 0")
        load_protobuf_modules(list(cfg.load_shared_library))
        self._group_re = compile_regex(cfg.group_regex, "group_regex")
        self._type_filters: list[tuple[int, re.Pattern[str]]] = [
            (f.scheme, compile_regex(f.regex, "type_filter.regex")) for f in cfg.type_filter]
        try:
            self._reader = LogReader(cfg.input_file)
        except LogFormatError as exc:
            raise StartError(str(exc)) from None
        self._entries: Iterator[LogEntry] = iter(self._reader)
        self._next = next(self._entries, None)
        self.published = 0
        self._start_micro: int | None = None  # set when the broker releases the hold
        if self._next is None:
            log.warning("%s has no entries to play back", cfg.input_file)
            self._log_start = 0
        else:
            self._log_start = self._next.timestamp_micro + si_to_micro(cfg.start_from_offset)
            while self._next is not None and self._next.timestamp_micro < self._log_start:
                self._next = next(self._entries, None)

    def run_once(self) -> None:
        """Start the timeline once the broker has released the hold (the release wakes this thread), so no entry
        waits in the hold queue and the first ones keep their spacing."""
        super().run_once()
        if self._start_micro is None and not self.interprocess().hold_state():
            delay = si_to_micro(self.cfg().playback_start_delay)
            self._start_micro = self.context.clock.now_micro() + delay
            self._schedule()

    def _due_micro(self, entry: LogEntry) -> int:
        """When ``entry`` is due on the application's clock."""
        assert self._start_micro is not None
        return self._start_micro + int((entry.timestamp_micro - self._log_start) / self.cfg().rate)

    def _schedule(self) -> None:
        if self._next is None:
            log.info("Reached EOF: %d entries played back", self.published)
            if self._reader.skipped:
                log.warning("%d damaged span(s) of %s were skipped", len(self._reader.skipped), self.cfg().input_file)
            self.quit()
            return
        clock = self.context.clock
        wait_s = (self._due_micro(self._next) - clock.now_micro()) / 1e6 / clock.effective_warp
        self.reactor.call_later(max(0.0, wait_s), self._play_due)

    def _play_due(self) -> None:
        now = self.context.clock.now_micro()
        while self._next is not None and self._due_micro(self._next) <= now:
            entry = self._next
            if not self._filtered(entry):
                log.debug("Playing back: %d | %s | %s | %s", entry.scheme, entry.group, entry.type_name,
                          time_str(entry.timestamp_micro))
                self.interprocess().publish_serialized(entry.group, entry.scheme, entry.type_name, entry.data)
                self.published += 1
            self._next = next(self._entries, None)
        self._schedule()

    def _filtered(self, entry: LogEntry) -> bool:
        if INTERNAL_GROUPS.fullmatch(entry.group) or not self._group_re.fullmatch(entry.group):
            return True
        if not self._type_filters:
            return False
        return not any(scheme == entry.scheme and regex.fullmatch(entry.type_name)
                       for scheme, regex in self._type_filters)

    def close(self) -> None:
        super().close()
        self._reader.close()


def main(argv: list[str] | None = None) -> int:
    prog = "goby-playback"
    args = list(sys.argv[1:] if argv is None else argv)
    args = [("--input_file" if a == "-i" else a) for a in args]
    return run_application(GobyPlayback, PlaybackConfig, positional_argv(PlaybackConfig, args, ["input_file"], prog),
                           prog=prog)


if __name__ == "__main__":
    sys.exit(main())
