"""``goby-logger``: record everything published on a platform's broker into a ``.goby`` log (goby_logger's role).

Config: ``LoggerConfig`` (gateway/goby/log/protobuf/logger_config.proto, Goby's fields): ``log_dir`` (required),
``type_regex``, ``group_regex``, ``omit { file_timestamp latest_symlink }``, ``load_shared_library`` (Python
modules whose protobuf types are described in the log), ``log_at_startup``; ``app {}``, ``interprocess {}`` or
``GOBY_INTERPROCESS``; ``--example_config``.  Writes ``<log_dir>/<platform>_<YYYYMMDDTHHMMSS>.goby`` and the
``<platform>_latest.goby`` symlink; ``goby::logger::request`` (``LoggerRequest``) starts, stops and rotates.

Everything runs on the application's one thread: the regex subscription's callback serializes each entry into a
buffer, and a zero-delay timer on the thread's reactor writes the buffer after each batch of received messages,
so the file holds every entry up to the last batch (a killed logger leaves at most one partial entry, which the
reader reports and skips).  A full disk or an unwritable ``log_dir`` ends the logger with one line, exit code 1.
"""

from __future__ import annotations

import logging
import os
import re
import stat
import sys

from gateway.goby.log.errors import LogWriteError
from gateway.goby.log.protobuf.logger_config_pb2 import LoggerConfig
from gateway.goby.log.protobuf.logger_pb2 import LoggerRequest
from gateway.goby.log.writer import LogWriter
from gateway.goby.portal import SingleThreadApplication, StartError, run_application
from gateway.goby.portal.interprocess import PROBE_GROUP
from gateway.goby.portal.marshalling import Scheme
from gateway.goby.portal.timeutil import file_str
from util.extensions import ExtensionPoint, load_module
from util.reactor import Timer

log = logging.getLogger(__name__)

#: Goby3's ``goby::middleware::groups::logger_request`` (src/middleware/log/groups.h).
LOGGER_REQUEST_GROUP = "goby::logger::request"
PROTO_MODULES = ExtensionPoint(group="goby_log.protobuf", what="library", source="load_shared_library")
#: The logger's receive queue (ZMQ_RCVHWM, messages) when ``interprocess { receive_queue_size }`` is not given:
#: Goby's default of 1000 is 20 ms at 50,000 messages/s, so a logger descheduled that long on a busy machine lost
#: messages (bench/bench_logger.py); ZeroMQ's I/O thread keeps reading into this queue while the logger's thread
#: waits for a CPU.
LOGGER_RECEIVE_QUEUE = 50_000


def load_protobuf_modules(specs: list[str]) -> None:
    """Import the modules ``load_shared_library`` names (their protobuf types join the default pool)."""
    for spec in specs:
        load_module(PROTO_MODULES, spec)


def compile_regex(pattern: str, name: str) -> re.Pattern[str]:
    try:
        return re.compile(pattern)
    except re.error as exc:
        raise StartError(f"{name} {pattern!r} is not a valid regular expression: {exc}") from None


class GobyLogger(SingleThreadApplication):
    """Subscribe to every (group, type) matching the regexes and append them to the log."""

    def __init__(self, cfg: LoggerConfig) -> None:
        super().__init__(cfg)
        load_protobuf_modules(list(cfg.load_shared_library))
        group_re = compile_regex(cfg.group_regex, "group_regex")
        type_re = compile_regex(cfg.type_regex, "type_regex")
        self._base = os.path.join(cfg.log_dir, cfg.interprocess.platform)
        self._fd: int | None = None
        self._path = ""
        self._writer: LogWriter | None = None
        self._pending = bytearray()
        self._flush_timer: Timer | None = None
        self._failed = False
        self.open_log()
        self._logging = cfg.log_at_startup
        ipc = self.context.interprocess_cfg
        if not ipc.HasField("receive_queue_size"):  # before the portal's sockets exist (first interprocess())
            ipc.receive_queue_size = LOGGER_RECEIVE_QUEUE
        self.interprocess().subscribe_regex(self._log, group_re.pattern, type_re.pattern, (Scheme.ALL_SCHEMES,))
        self.interprocess().subscribe(LOGGER_REQUEST_GROUP, LoggerRequest, self._on_request)

    # --------------------------------------------------------------------------------------- the file
    def open_log(self) -> None:
        cfg: LoggerConfig = self.cfg()
        stamp = "" if cfg.omit.file_timestamp else "_" + file_str(self.context.clock.now_micro())
        path = f"{self._base}{stamp}.goby"
        try:
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_CLOEXEC, 0o644)
        except OSError as exc:
            raise StartError(f"Failed to open log in directory: {cfg.log_dir} ({path}: {exc.strerror})") from None
        self._fd, self._path = fd, path
        self._writer = LogWriter(self._pending.extend, self.context.clock.now_micro)
        log.info("Logging to: %s", path)
        if not cfg.omit.latest_symlink:
            link = f"{self._base}_latest.goby"
            try:
                if os.path.islink(link) or os.path.exists(link):
                    os.remove(link)
                os.symlink(os.path.realpath(path), link)
            except OSError as exc:
                log.warning("Cannot create symlink to latest file (%s). Continuing onwards anyway", exc.strerror)

    def close_log(self) -> None:
        if self._fd is None:
            return
        self._flush()
        log.info("Closing log at: %s", self._path)
        fd, self._fd, self._writer = self._fd, None, None
        try:
            os.close(fd)
            if stat.S_ISREG(os.stat(self._path).st_mode):  # read-only as Goby leaves it (never a device)
                os.chmod(self._path, stat.S_IRUSR | stat.S_IRGRP)
        except OSError as exc:
            log.warning("closing %s: %s", self._path, exc.strerror)

    # ------------------------------------------------------------------------------------- logging
    def _log(self, payload: bytes, scheme: int, type_name: str, group: str) -> None:
        if not self._logging or self._writer is None or group == PROBE_GROUP:
            return
        try:
            self._writer.write(payload, scheme, type_name, group)
        except LogWriteError as exc:
            log.error("not logged: %s", exc)
            return
        if self._flush_timer is None:  # write after this batch of receptions (the timer runs after the poll)
            self._flush_timer = self.reactor.call_later(0.0, self._flush)

    def _flush(self) -> None:
        self._flush_timer = None
        if not self._pending or self._fd is None:
            return
        view = memoryview(self._pending)
        try:
            while view:
                written = os.write(self._fd, view)
                view = view[written:]
        except OSError as exc:
            if not self._failed:
                self._failed = True
                log.critical("cannot write %s: %s; stopping", self._path, exc.strerror)
            self._writer = None
            self.quit(1)
        finally:
            view.release()
            self._pending.clear()

    def _on_request(self, request: LoggerRequest) -> None:
        state = request.requested_state
        if state == LoggerRequest.START_LOGGING:
            if self._logging:
                log.warning("Received START_LOGGING but we are already logging")
            else:
                log.info("Logging started")
            if self._fd is None:
                self._open_or_quit()
            self._logging = True
        elif state == LoggerRequest.STOP_LOGGING:
            if not self._logging:
                log.warning("Received STOP_LOGGING but we were already stopped")
            else:
                log.info("Logging stopped")
            self._logging = False
            if request.close_log:
                self.close_log()
        elif state == LoggerRequest.ROTATE_LOG:
            log.info("Log rotated")
            self.close_log()
            self._open_or_quit()

    def _open_or_quit(self) -> None:
        try:
            self.open_log()
        except StartError as exc:
            log.critical("%s; stopping", exc)
            self.quit(1)

    def finalize(self) -> None:
        self.close_log()

    def close(self) -> None:
        self.close_log()
        super().close()


def main(argv: list[str] | None = None) -> int:
    return run_application(GobyLogger, LoggerConfig, argv, prog="goby-logger")


if __name__ == "__main__":
    sys.exit(main())
