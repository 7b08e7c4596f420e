"""A mission's record, read from its logs: goby-logger's ``.goby`` files and moos-logger's ``.alog`` files.

Every platform of both missions runs goby-logger on its broker and (when it has a MOOSDB) moos-logger, into the
platform's log directory (``<run_dir>/logs/<platform>``, docs/logging.md). The demos read those files, nothing
else: :func:`read_platform` after the run (what the summaries, CSVs and pictures are computed from), and a
:class:`PlatformLogs` kept open during the run (``poll()`` reads what the loggers appended since the last poll:
the progress lines and the wait for the helm taking command).

Times are sim seconds on the MOOS time base (the Unix time times the warp, what MOOS and the mission's Goby apps,
``reference_microtime: 0``, call now) minus an ``origin`` (a mission's :class:`SimClock` origin: sim seconds since
the mission started): an alog row is its ``LOGSTART`` plus its time, a ``.goby`` entry (written by a goby-logger on
real time) its timestamp times the warp.
"""

from __future__ import annotations

import io
import itertools
import logging
import shlex
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from frontseat import groups as frontseat_groups
from frontseat.protobuf.frontseat_pb2 import InterfaceState, InterfaceStatus
from gateway.goby.log import EntryDecoder, LogEntry
from gateway.goby.log.descriptors import LogDescriptorPool
from gateway.goby.log.follow import LogFollower
from gateway.moos.alog import AlogReader
from launch.record import MissionRecord
from translators.usv import groups as usv_groups

log = logging.getLogger(__name__)

NAV_VARS = ("NAV_X", "NAV_Y", "NAV_HEADING", "NAV_SPEED", "NAV_DEPTH")
EVENT_VARS = (
    "DEPLOY_STATE",
    "POLYGON_UPDATES",
    "IVPHELM_STATE",
    "VIEW_POLYGON",
    "VIEW_SEGLIST",
    "LOITER_MODE",
    "WPT_INDEX",
    "AUV_DEPLOY_STATE",
    "DEPLOY_DEPTH_UPDATES",
)
# Posted every helm iteration; only changes are worth keeping. (Command variables are kept every time:
# the same command twice is two commands.)
CHANGES_ONLY = frozenset({"IVPHELM_STATE", "VIEW_POLYGON", "VIEW_SEGLIST", "LOITER_MODE", "WPT_INDEX"})
#: NAV_* values posted within this many sim seconds of each other are one fix (a gateway posts a fix's variables
#: one after the other, each with its own MOOS time).
SAME_FIX_S = 0.05
#: The group of the course's NodeStatus as the topside republishes it (``goby::middleware::frontseat::node_status``).
NODE_STATUS_TYPE = "goby.middleware.frontseat.protobuf.NodeStatus"


class SimClock:
    """Sim seconds since construction, on the logs' time base: the Unix time times the warp (MOOSTime with
    MOOSTimeWarp) minus :attr:`origin`, that product at construction."""

    def __init__(self, warp: float) -> None:
        self.warp = warp
        self.origin = time.time() * warp

    def now(self) -> float:
        return time.time() * self.warp - self.origin


def goby_log_path(directory: Path, platform: str) -> Path | None:
    """The platform's newest ``.goby`` log in ``directory`` (goby-logger's ``<platform>_<time>.goby``), if any."""
    logs = sorted(p for p in directory.glob(f"{platform}_*.goby") if not p.is_symlink())
    return logs[-1] if logs else None


def alog_path(directory: Path) -> Path | None:
    """The newest ``.alog`` of moos-logger's session directories in ``directory``, if any."""
    logs = sorted(directory.glob("*/*.alog"), key=lambda p: p.stat().st_mtime)
    return logs[-1] if logs else None


class _AlogTail:
    """The rows of an alog appended since the last poll (complete lines only; the banner read first)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._file = open(path, "rb")  # noqa: SIM115 - kept open across polls, closed by close()
        self._banner = b""
        self._rest = b""
        self.logstart: float | None = None

    def poll(self) -> list[tuple[float, str, str, Any]]:
        """``(absolute time, variable, source, value)`` of the new rows."""
        data = self._rest + self._file.read()
        cut = data.rfind(b"\n") + 1
        complete, self._rest = data[:cut], data[cut:]
        if not complete:
            return []
        if self.logstart is None:  # the banner: the leading % lines
            lines = complete.splitlines(keepends=True)
            banner = list(itertools.takewhile(lambda line: line.startswith(b"%"), lines))
            self._banner += b"".join(banner)
            if b"LOGSTART" not in self._banner:
                return []
            complete = b"".join(lines[len(banner):])
        reader = AlogReader(io.BytesIO(self._banner + complete))
        if reader.header.logstart is None:
            return []
        self.logstart = reader.header.logstart
        return [(self.logstart + row.time, row.var, row.source, row.value) for row in reader]

    def close(self) -> None:
        self._file.close()


class PlatformLogs:
    """One platform's logs filed into ``record``: the ``.alog`` (track and MOOS events, ``moos_variables`` when
    given) and the ``.goby`` (the frontseat interface's state, the USV's command acknowledgements and, with
    ``node_status``, every NodeStatus: on the trail's topside, the vehicles' as it republishes them). ``poll()``
    reads what was appended since the last poll; the files may appear later.
    """

    def __init__(self, directory: Path, platform: str, warp: float, record: MissionRecord | None = None,
                 moos: bool = True, moos_variables: tuple[str, ...] | None = None, node_status: bool = False,
                 origin: float = 0.0) -> None:
        self.directory = directory
        self.platform = platform
        self.warp = warp
        self.origin = origin
        self.record = record if record is not None else MissionRecord()
        self.moos = moos
        self.moos_variables = frozenset(moos_variables if moos_variables is not None else (*NAV_VARS, *EVENT_VARS))
        self._goby: LogFollower | None = None
        self._alog: _AlogTail | None = None
        self._decoder = EntryDecoder(LogDescriptorPool())
        self._last: dict[str, str] = {}
        self._last_state: int | None = None
        self._nav_t: float | None = None
        self.counts: dict[str, int] = {}  # MOOS rows per variable
        self._handlers: dict[str, Callable[[float, Any], None]] = {
            str(frontseat_groups.status): self._on_status,
            str(usv_groups.usv_command_ack): self._on_ack,
        }
        if node_status:
            self._handlers[str(frontseat_groups.node_status)] = self._on_node_status

    @property
    def goby_path(self) -> Path | None:
        return None if self._goby is None else Path(self._goby.path)

    @property
    def alog_path(self) -> Path | None:
        return None if self._alog is None else self._alog.path

    def poll(self) -> None:
        """File what the loggers appended since the last poll."""
        if self._goby is None and (path := goby_log_path(self.directory, self.platform)) is not None:
            self._goby = LogFollower(path)
            self._decoder = EntryDecoder(self._goby.descriptors)
        if self._goby is not None:
            for entry in self._goby.poll():
                self._file_entry(entry)
        if self.moos and self._alog is None and (path := alog_path(self.directory)) is not None:
            self._alog = _AlogTail(path)
        if self._alog is not None:
            for t, var, source, value in self._alog.poll():
                self._file_row(t - self.origin, var, source, value)

    def close(self) -> None:
        if self._goby is not None:
            self._goby.close()
        if self._alog is not None:
            self._alog.close()

    # -- .goby ----------------------------------------------------------------------------------------------

    def _file_entry(self, entry: LogEntry) -> None:
        handler = self._handlers.get(entry.group)
        if handler is None:
            return
        decoded = self._decoder.decode(entry)
        t = entry.timestamp_micro / 1e6 * self.warp - self.origin
        for message in decoded.messages:
            handler(t, message)

    def _on_status(self, t: float, status: Any) -> None:
        """Each change of the frontseat interface's state."""
        if isinstance(status, InterfaceStatus) and status.HasField("state") and status.state != self._last_state:
            self._last_state = status.state
            self.record.add_event(t, "interface", "interface_state", InterfaceState.Name(status.state))

    def _on_ack(self, t: float, ack: Any) -> None:
        """The USV's command acknowledgements (USVCommandAck), the satellite link's with its figures."""
        stage = ack.DESCRIPTOR.fields_by_name["stage"].enum_type.values_by_number[ack.stage].name
        posts = ";".join(ack.moos_post)
        if stage.startswith("LINK_"):  # the satellite link's ack (or expiry), sim seconds
            posts = f"slot_wait={ack.slot_wait:.2f};link_latency={ack.link_latency:.2f}"
        self.record.add_event(t, "ack", stage, posts or ack.error, ack.responder)

    def _on_node_status(self, t: float, status: Any) -> None:
        """NodeStatus by vehicle name (on the topside: the topside manager's, over the satellite link)."""
        if status.DESCRIPTOR.full_name == NODE_STATUS_TYPE:
            self.record.add_event(t, self.platform, "node_status", status.name,
                                  f"{status.local_fix.x:.0f},{status.local_fix.y:.0f}")

    # -- .alog ----------------------------------------------------------------------------------------------

    def _file_row(self, t: float, name: str, source: str, value: Any) -> None:
        self.counts[name] = self.counts.get(name, 0) + 1
        if name not in self.moos_variables:
            return
        if name in NAV_VARS:
            if isinstance(value, float):
                # a fix's variables share the time of its first one, so the fix is one row of the track
                if self._nav_t is None or t - self._nav_t > SAME_FIX_S:
                    self._nav_t = t
                self.record.add_nav(self._nav_t, name, value)
            return
        text = value if isinstance(value, str) else f"{value:g}"
        if name in CHANGES_ONLY and self._last.get(name) == text:
            return
        self._last[name] = text
        self.record.add_event(t, "moos", name, text, source)


def read_platform(directory: Path, platform: str, warp: float, moos: bool = True,
                  moos_variables: tuple[str, ...] | None = None, node_status: bool = False,
                  origin: float = 0.0) -> PlatformLogs:
    """A platform's finished logs, read whole (``.record``, ``.goby_path``, ``.alog_path``, ``.counts``)."""
    logs = PlatformLogs(directory, platform, warp, moos=moos, moos_variables=moos_variables, node_status=node_status,
                        origin=origin)
    try:
        logs.poll()
    finally:
        logs.close()
    logs.record.sort()
    return logs


def mcap_command(log_root: Path) -> str:
    """The one shell command that turns every ``.goby`` log under ``log_root`` into an ``.mcap`` next to it
    (goby-log-tool named by absolute path, so it works without an activated virtualenv)."""
    tool = Path(sys.executable).parent / "goby-log-tool"
    program = shlex.quote(str(tool)) if tool.exists() else "goby-log-tool"
    return (f"find {shlex.quote(str(log_root))} -name '*.goby' -type f -exec sh -c "
            f"'{program} \"$1\" \"${{1%.goby}}.mcap\" --format MCAP' _ {{}} \\;")


def logs_lines(log_root: Path, paths: list[Path]) -> list[str]:
    """What the demos print at the end: where the run's logs are and how to open them as MCAP."""
    shown = ", ".join(str(p.relative_to(log_root)) if p.is_relative_to(log_root) else str(p) for p in paths)
    return [f"logs of this run (goby-logger .goby, moos-logger .alog; the summary above is read from them) in "
            f"{log_root}: {shown or 'none found'}",
            f"open them in Foxglove (MCAP): {mcap_command(log_root)}"]
