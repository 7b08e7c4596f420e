"""``moos-logger``: pLogger's role, reading its ``ProcessConfig = pLogger`` block, writing pLogger's files.

Each session makes ``<PATH>/<root>/`` with ``root = <File>_D_M_YYYY_____HH_MM_SS`` (``FileTimeStamp = false``: just
``<File>``; default ``MOOSLog``; ``::GlobalLogPath`` wins over ``PATH``) and writes ``<root>.alog`` (the rows,
gateway.moos.alog), ``<root>.blog`` (binary data), ``<root>.ylog`` (MOOS_DEBUG and MOOS_SYSTEM), ``<root>._moos``
(the mission, with the banner), ``<root>.xlog`` with ``WildcardExclusionLog``; it posts ``LOGGER_DIRECTORY`` and
writes ``LastOpenedLoggingDirectory=`` to ``LoggingDirectorySummaryFile`` (``./.LastOpenedMOOSLogDirectory``).
``LOGGER_RESTART`` starts a new session; ``<NAME>_CMD = LOG_REQUEST = VAR @ period`` adds a variable.

Parameters (names case-insensitive, booleans ``true`` or a number > 0, as libMOOS reads them): ``Log = VAR @ period
[NOSYNC] [MONITOR]`` (period default 2 s, as pLogger), ``WildCardLogging``, ``WildCardPattern``,
``WildCardOmitPattern`` (``MISSION_FILE`` is always omitted), ``WildcardExclusionLog``, ``LogAuxSrc``,
``MarkExternalCommunityMessages``, ``MarkDataType``, ``DoublePrecision``, ``AsyncLog``, ``File``, ``PATH``,
``FileTimeStamp``, ``UTCLogDirectories``, ``LoggingDirectorySummaryFile``, ``AppTick`` (default 5), ``CommsTick``.
Not written: the ``.slog`` (``SyncLog``) and compressed alogs (``CompressAlogs``): each says so once at start-up.

Differences from pLogger, on purpose: wildcard logging registers ``*`` (or each ``WildCardPattern``) with the DB
instead of polling ``VAR_SUMMARY`` every second, so a new variable's first postings are logged too; a current
value the DB re-sends on a registration is logged once, not again; an unwritable ``PATH`` or a full disk stops the
logger with one line and exit status 1 (pLogger falls back to ``./`` or goes on without its rows).

Threads: one. The logger and its MOOS client live on one :class:`util.reactor.Reactor` (``comms(reactor=...)``): the
AppTick timer fetches the mail received since the last tick, writes it and flushes the files, as pLogger's
``OnNewMail`` + ``Iterate``.
"""

from __future__ import annotations

import logging
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

from gateway.apps.moos_tool_args import parse_moos_app_args
from gateway.moos import MissionFileError, MoosClock
from gateway.moos.alog import (
    DEFAULT_DOUBLE_PRECISION,
    DEFAULT_STEM,
    AlogError,
    AlogWriter,
    format_banner,
    format_system_row,
    log_root_name,
)
from gateway.moos.message import BINARY, DOUBLE, STRING, MoosMessage
from gateway.moos.mission_file import MissionFile
from gateway.moos.reactor_app import MoosReactorApp, serve
from gateway.moos.wildcard import wild_match
from util.reactor import Timer

log = logging.getLogger(__name__)
DEFAULT_APP_NAME = "pLogger"
DEFAULT_PERIOD = 2.0  # MOOS_LOGGER_DEFAULT_PERIOD: "Log = VAR" without "@ period"
MONITOR_PERIOD = 10.0  # DEFAULT_MONITOR_TIME: MONITOR checks and LOGGER_DIRECTORY
SYSTEM_VARS = ("MOOS_DEBUG", "MOOS_SYSTEM")
_LEADING_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


def _moos_bool(value: str) -> bool:
    """libMOOS's ``GetConfigurationParam(bool&)``: ``TRUE`` (any case) or a number above 0."""
    value = value.strip()
    if value.upper() == "TRUE":
        return True
    try:
        return float(value) > 0
    except ValueError:
        return False


def _atof(text: str) -> float:
    """C's ``atof``: the leading number, 0 if none."""
    match = _LEADING_NUMBER.match(text.strip())
    return float(match.group(0)) if match else 0.0


@dataclass(frozen=True)
class LogRequest:
    """One ``Log = VAR @ period [NOSYNC] [MONITOR]`` line."""

    var: str
    period: float = DEFAULT_PERIOD
    monitor: bool = False

    @classmethod
    def parse(cls, text: str) -> LogRequest | None:
        """pLogger's ``HandleLogRequest`` on the line's value (whitespace removed, as libMOOS gives it)."""
        squeezed = re.sub(r"[ \t]+", "", text)
        var, at, rest = squeezed.partition("@")
        if not var:
            return None
        period = _atof(rest.partition(",")[0]) if at and rest else DEFAULT_PERIOD
        return cls(var, max(0.0, period) if math.isfinite(period) else DEFAULT_PERIOD, "MONITOR" in rest.upper())


@dataclass
class LoggerConfig:
    """The ``ProcessConfig = pLogger`` block, read as pLogger reads it (the first value of a name wins)."""

    logs: list[LogRequest] = field(default_factory=list)
    wildcard: bool = False
    accept: list[str] = field(default_factory=list)
    omit: list[str] = field(default_factory=lambda: ["MISSION_FILE"])
    exclusion_log: bool = False
    log_aux_src: bool = False
    mark_external: bool = False
    mark_data_type: bool = False
    double_precision: int = DEFAULT_DOUBLE_PRECISION
    async_log: bool = True
    stem: str = DEFAULT_STEM
    path: str = "./"
    file_timestamp: bool = True
    utc: bool = False
    summary_file: str = "./.LastOpenedMOOSLogDirectory"
    app_tick: float = 5.0
    comms_tick: float = 5.0
    unsupported: list[str] = field(default_factory=list)

    @classmethod
    def from_mission(cls, mission: MissionFile, block: str) -> LoggerConfig:
        pairs = mission.process_config(block)
        where = f"{mission.path}: ProcessConfig = {block}"
        cfg = cls()
        if not mission.has_process_config(block):
            log.warning("%s: no such block; logging every variable (pLogger's WildCardLogging default)", where)
            cfg.wildcard = True
        first: dict[str, str] = {}
        for key, value in pairs:
            name = key.strip().upper()
            first.setdefault(name, value.strip())
            if name == "LOG":
                request = LogRequest.parse(value)
                if request is None:
                    log.warning("%s: 'Log = %s' names no variable; ignored", where, value)
                elif any(r.var == request.var for r in cfg.logs):
                    log.warning("%s: ignoring request to log %s - already requested", where, request.var)
                else:
                    cfg.logs.append(request)
            elif name == "WILDCARDPATTERN":
                cfg.accept += [p.strip() for p in value.split(",") if p.strip()]
            elif name == "WILDCARDOMITPATTERN":
                cfg.omit += [p.strip() for p in value.split(",") if p.strip()]
        flags = {"WILDCARDLOGGING": "wildcard", "WILDCARDEXCLUSIONLOG": "exclusion_log", "LOGAUXSRC": "log_aux_src",
                 "MARKEXTERNALCOMMUNITYMESSAGES": "mark_external", "MARKDATATYPE": "mark_data_type",
                 "ASYNCLOG": "async_log", "FILETIMESTAMP": "file_timestamp", "UTCLOGDIRECTORIES": "utc"}
        for name, attr in flags.items():
            if name in first:
                setattr(cfg, attr, _moos_bool(first[name]))
        cfg.stem = first.get("FILE") or cfg.stem
        cfg.path = mission.global_value("GlobalLogPath") or first.get("PATH") or cfg.path
        cfg.summary_file = first.get("LOGGINGDIRECTORYSUMMARYFILE") or cfg.summary_file
        cfg.double_precision = int(cls._number(first, "DOUBLEPRECISION", cfg.double_precision, 0, 30, where))
        cfg.app_tick = cls._number(first, "APPTICK", cfg.app_tick, 1e-3, 1000, where)
        cfg.comms_tick = cls._number(first, "COMMSTICK", cfg.comms_tick, 1e-3, 1000, where)
        if cfg.wildcard:
            cfg.async_log = True
        sync = first.get("SYNCLOG", "")
        if _moos_bool(re.sub(r"[ \t]", "", sync).partition("@")[0]):
            cfg.unsupported.append("SyncLog: the .slog is not written (the .alog has every row)")
        if _moos_bool(first.get("COMPRESSALOGS", "false")):
            cfg.unsupported.append("CompressAlogs: alogs are written uncompressed (as pLogger built without zlib)")
        return cfg

    @staticmethod
    def _number(first: dict[str, str], name: str, default: float, low: float, high: float, where: str) -> float:
        if name not in first:
            return default
        try:
            value = float(first[name])
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and low <= value <= high):
            raise MissionFileError(f"{where}: {name} = {first[name]!r} is not a number in [{low:g}, {high:g}]")
        return value

    def wildcard_wants(self, var: str) -> bool:
        accepted = not self.accept or any(wild_match(p.encode(), var.encode()) for p in self.accept)
        return accepted and not any(wild_match(p.encode(), var.encode()) for p in self.omit)


class LogSession:
    """The files of one logging session (pLogger's ``OnNewSession``); raises :class:`AlogError` if it cannot
    make them. One thread."""

    def __init__(self, cfg: LoggerConfig, logstart: float, mission_path: Path | None, when: float | None = None) -> None:
        self.cfg = cfg
        self.root = log_root_name(cfg.stem, when, cfg.utc, cfg.file_timestamp)
        base = cfg.path[:-1] if cfg.path.endswith("/") else cfg.path
        self.directory_name = f"{base}/{self.root}"  # as pLogger names it (posted, and in the banners)
        self.directory = Path(self.directory_name)
        self._files: list[IO[bytes]] = []
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise AlogError(f"cannot create the log directory {self.directory_name}: {exc.strerror or exc}") from exc
        stem = f"{self.directory_name}/{self.root}"
        try:
            self.alog = AlogWriter(stem + ".alog", logstart, double_precision=cfg.double_precision,
                                   mark_data_type=cfg.mark_data_type)
            self.alog.open_blog()
            self.xlog = AlogWriter(stem + ".xlog", logstart, double_precision=cfg.double_precision,
                                   mark_data_type=cfg.mark_data_type, banner=False,
                                   blog_from=self.alog) if cfg.exclusion_log else None
            self.ylog = open(stem + ".ylog", "wb")  # noqa: SIM115 - closed by close()
            self.ylog.write(format_banner(stem + ".ylog", logstart).encode())
        except OSError as exc:
            self.close(quiet=True)
            raise AlogError(f"cannot write in the log directory {self.directory_name}: {exc.strerror or exc}") from exc
        self.logstart = logstart
        if mission_path is not None:
            self._copy_mission(mission_path, stem + "._moos")
        try:
            Path(cfg.summary_file).write_text(f"LastOpenedLoggingDirectory={self.directory_name}\n")
        except OSError as exc:
            log.debug("summary file %s not written: %s", cfg.summary_file, exc)

    def _copy_mission(self, mission: Path, copy: str) -> None:
        """pLogger's ``CopyMissionFile``: the banner, then the mission's lines (its loop adds one more newline)."""
        try:
            text = mission.read_bytes()
            with open(copy, "wb") as out:
                out.write(format_banner(copy, self.logstart).encode() + text + b"\n")
        except OSError as exc:
            log.warning("unable to create a back up of the mission file: %s", exc)

    def write(self, msg: MoosMessage, source: str, to_xlog: bool) -> None:
        writer = self.xlog if to_xlog and self.xlog is not None else self.alog
        kind = msg.data_type
        value: float | str | bytes = msg.dval if kind == DOUBLE else msg.binary_data() if kind == BINARY else msg.string()
        writer.write(msg.time(), msg.key(), source, value)

    def write_system(self, msg: MoosMessage) -> None:
        value: float | str = msg.dval if msg.data_type == DOUBLE else msg.string()
        self.ylog.write(format_system_row(msg.time() - self.logstart, msg.key(), msg.source(), value).encode(
            "utf-8", "surrogateescape"))

    def flush(self) -> None:
        self.alog.flush()
        if self.xlog is not None:
            self.xlog.flush()
        self.ylog.flush()

    def close(self, quiet: bool = False) -> None:
        """Close every file (idempotent); the first error (a full disk on the last flush) is raised unless quiet."""
        first: OSError | None = None
        for closer in (getattr(self, "alog", None), getattr(self, "xlog", None), getattr(self, "ylog", None)):
            if closer is None:
                continue
            try:
                closer.close()
            except OSError as exc:
                first = first or exc
        if first is not None and not quiet:
            raise first


class LoggerApp(MoosReactorApp):
    """One logger on one MOOSDB: :meth:`run` serves on the calling thread until :meth:`stop` (any thread) or a
    failure (:attr:`failure`: the files cannot be written)."""

    def __init__(self, mission_path: str | Path, alias: str | None = None, clock: MoosClock | None = None,
                 host: str | None = None, port: int | None = None) -> None:
        self.mission = MissionFile(mission_path)
        name = alias or DEFAULT_APP_NAME
        block = name if self.mission.has_process_config(name) else DEFAULT_APP_NAME
        self.cfg = LoggerConfig.from_mission(self.mission, block)
        super().__init__(name, clock or MoosClock(self.mission.time_warp), host or self.mission.server_host,
                         port or self.mission.server_port, f"logger-{name}")
        self.comms_tick = self.cfg.comms_tick
        self.command_key = self.name.upper() + "_CMD"
        self.logged: dict[str, LogRequest] = {r.var: r for r in self.cfg.logs}
        for var in SYSTEM_VARS:
            self.logged.setdefault(var, LogRequest(var, 0.0))
        self.session: LogSession | None = None
        self._registered_at = -math.inf  # MOOS time of the last (re)registration
        self._last: dict[str, tuple[float, str, object]] = {}  # per variable: the last row written
        self._seen: dict[str, float] = {}  # per variable: MOOS time it was last received (MONITOR)
        self._timers: list[Timer] = []
        self.logstart = self.clock.time()

    # ---- running ----------------------------------------------------------------------------------------
    def before_connect(self) -> bool:
        """Open the first session (the files must be writable before anything is logged)."""
        for text in self.cfg.unsupported:
            log.warning("%s: %s", self.name, text)
        try:
            self.session = LogSession(self.cfg, self.logstart, self.mission.path)
        except AlogError as exc:
            self.failure = str(exc)
            return False
        log.info("%s logging to %s", self.name, self.session.directory_name)
        return True

    def after_connect(self) -> None:
        self._timers.append(self.reactor.call_every(self._tick_period, self._on_tick))
        self._timers.append(self.reactor.call_every(lambda: MONITOR_PERIOD / self.clock.warp, self._on_monitor,
                                                    align=False))

    def after_close(self) -> None:
        for timer in self._timers:
            timer.cancel()
        if self.session is not None and self.failure is None:
            self._on_tick()  # what arrived since the last tick
        self._close_session()

    def _fail(self, text: str) -> None:
        self.failure = self.failure or text
        self.stop()

    def _close_session(self) -> None:
        if self.session is None:
            return
        try:
            self.session.close(quiet=self.failure is not None)
        except OSError as exc:
            self.failure = self.failure or f"cannot write {self.session.directory_name}: {exc.strerror or exc}"
        self.session = None

    def _tick_period(self) -> float:
        """Real seconds between AppTicks: ``AppTick`` per MOOS second."""
        return 1.0 / (self.cfg.app_tick * self.clock.warp)

    # ---- reactor work ----------------------------------------------------------------------------------
    def on_connect(self) -> bool:
        """Every (re)connection: the wildcard patterns first, then the named variables (their periods win)."""
        self._registered_at = self.clock.time()
        if self.cfg.wildcard:
            for pattern in self.cfg.accept or ["*"]:
                self.comms.register(pattern, "*", 0.0)
        for request in self.logged.values():
            self.comms.register(request.var, request.period)
        self.comms.register("LOGGER_RESTART", 0.5)
        self.comms.register(self.command_key, 0.0)
        if self.session is not None:
            self.comms.notify("LOGGER_DIRECTORY", self.session.directory_name)
        return True

    def _on_tick(self) -> None:
        """pLogger's OnNewMail (sorted by time) and Iterate (flush)."""
        session = self.session
        if session is None:
            return
        mail = self.comms.fetch()
        mail.sort(key=MoosMessage.time)
        restart = False
        try:
            for msg in mail:
                key = msg.key()
                if key == self.command_key:
                    self._on_command(msg)
                    continue
                self._log(session, msg, key)
                restart = restart or key == "LOGGER_RESTART"
            session.flush()
        except OSError as exc:
            self._fail(f"cannot write the log in {session.directory_name}: {exc.strerror or exc}")
            return
        if restart:
            self._restart()

    def _log(self, session: LogSession, msg: MoosMessage, key: str) -> None:
        self._seen[key] = msg.time()
        if key in SYSTEM_VARS:
            session.write_system(msg)
        request = self.logged.get(key)
        to_xlog = False
        if request is None:
            if not self.cfg.wildcard:
                return
            if not self.cfg.wildcard_wants(key):
                if not self.cfg.exclusion_log:
                    return
                to_xlog = True
        elif not self._due(request, msg.time()):
            return
        if not self.cfg.async_log:
            return
        value = msg.dval if msg.data_type == DOUBLE else msg.raw_sval
        row = (msg.time(), msg.source(), value)
        if msg.time() <= self._registered_at and self._last.get(key) == row:
            return  # the DB re-sent the current value on a registration: it is in the log already
        self._last[key] = row
        session.write(msg, self._source_column(msg), to_xlog)

    def _due(self, request: LogRequest, msg_time: float) -> bool:
        """With wildcard logging the DB sends every posting, so a named variable's period is kept here."""
        if not self.cfg.wildcard or request.period <= 0:
            return True
        last = self._last.get(request.var)
        return last is None or msg_time - last[0] >= request.period

    def _source_column(self, msg: MoosMessage) -> str:
        source = msg.source()
        if self.cfg.log_aux_src and msg.source_aux():
            source += ":" + msg.source_aux()
        if self.cfg.mark_external and msg.community() != self.comms.get_community_name():
            source += "@" + msg.community()
        return source

    def _on_command(self, msg: MoosMessage) -> None:
        """``<NAME>_CMD = LOG_REQUEST = VAR @ period``: log one more variable from now on."""
        if msg.data_type != STRING:
            log.warning("%s only accepts string command messages", self.name)
            return
        task, _, param = msg.string().partition("=")
        if task.strip().upper() != "LOG_REQUEST":
            log.warning("dynamic command %s is not supported", task.strip())
            return
        request = LogRequest.parse(param)
        if request is None or request.var in self.logged:
            log.warning("ignoring request to log %r: %s", param, "already requested" if request else "no variable")
            return
        self.logged[request.var] = request
        self.comms.register(request.var, request.period)
        log.info("processed dynamic log request on %s", request.var)

    def _restart(self) -> None:
        """LOGGER_RESTART: close this session, open a new one."""
        old = self.session
        log.info("closing %s", old.directory_name if old else "")
        self._close_session()
        if self.failure is not None:
            self.stop()
            return
        try:
            self.session = LogSession(self.cfg, self.logstart, self.mission.path)
        except AlogError as exc:
            self._fail(str(exc))
            return
        self.comms.notify("LOGGER_DIRECTORY", self.session.directory_name)
        self.comms.notify("MOOS_DEBUG", f"Now Logging to : {self.session.root}")

    def _on_monitor(self) -> None:
        """Every 10 MOOS seconds: warn about MONITOR variables not seen for 10 s; post LOGGER_DIRECTORY."""
        now = self.clock.time()
        missing = [r.var for r in self.logged.values()
                   if r.monitor and now - self._seen.get(r.var, -math.inf) > MONITOR_PERIOD]
        for var in missing:
            log.warning('Monitored Variable "%s" is not appearing', var)
        if missing:
            plural = " is" if len(missing) == 1 else "s are"
            self.comms.notify("MOOS_DEBUG", f"{len(missing)} monitored variable{plural} not being logged")
        if self.session is not None:
            self.comms.notify("LOGGER_DIRECTORY", self.session.directory_name)


def main(argv: list[str] | None = None) -> int:
    args = parse_moos_app_args(argv, "moos-logger", "A pLogger-compatible MOOS logger writing .alog files.",
                               DEFAULT_APP_NAME)
    return serve(lambda: LoggerApp(args.mission, alias=args.alias),
                 lambda app: f"{app.name} connecting to {app.host}:{app.port}", "moos-logger")


if __name__ == "__main__":
    raise SystemExit(main())
