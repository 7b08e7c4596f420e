"""Run the USV mission from Python: launch usv.launch's processes (their loggers among them), stop them, read the logs.

Used by the demo (``launch.usv.demo``) and the end-to-end test, so both run exactly what a user's
``goby-launch launch/usv/usv.launch`` runs, with the same generated configs.
"""

from __future__ import annotations

import logging
import re
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from launch.errors import LaunchError, ProcessDiedError
from launch.launchfile import parse_file
from launch.liaison.portal_side import READY_PREFIX as LIAISON_READY
from launch.mission import ProcessOutcome, choose_program, outcomes, scan_logs
from launch.process_group import ProcessGroup, child_environment
from launch.record import MissionRecord, shifted, until
from launch.recorder import PlatformLogs, SimClock, read_platform
from launch.usv.config import data_log_dir
from launch.usv.settings import USV_DIR, UsvSettings

log = logging.getLogger(__name__)

LAUNCH_FILE = USV_DIR / "usv.launch"
__all__ = ["LAUNCH_FILE", "MissionResult", "UsvMission", "choose_program"]


@dataclass
class MissionResult:
    """Everything the demo prints and the test asserts: the record read from the logs (t=0 at COMMAND), the
    shutdown, and the logs it was read from."""

    record: MissionRecord
    command_time: float | None
    outcomes: list[ProcessOutcome] = field(default_factory=list)
    log_errors: list[str] = field(default_factory=list)
    failure: str | None = None
    logs: list[Path] = field(default_factory=list)  # the .goby and .alog files the record was read from


def read_mission_logs(settings: UsvSettings, origin: float = 0.0) -> tuple[MissionRecord, list[Path]]:
    """The USV mission's record from its logs after the run: the USV's .goby and .alog (track, helm, commands,
    interface state, command acks) and the topside's .goby (the satellite link's acks); sim seconds after
    ``origin`` (see ``launch.recorder``), unshifted."""
    record = MissionRecord()
    paths: list[Path] = []
    for platform, moos in ((settings.platform, True), (settings.topside_platform, False)):
        logs = read_platform(data_log_dir(settings, platform), platform, settings.warp, moos=moos, origin=origin)
        paths += [p for p in (logs.goby_path, logs.alog_path) if p is not None]
        record.nav += logs.record.nav
        record.events += logs.record.events
    record.sort()
    return record, paths


def liaison_page_urls(base: str) -> dict[str, str]:
    """A goby-liaison's pages (home, scope, commander, map) under ``base`` (``http://host:port``)."""
    base = base.rstrip("/")
    return {"home": f"{base}/", "scope": f"{base}/?_=/scope", "commander": f"{base}/?_=/commander",
            "map": f"{base}/?_=/map"}


class UsvMission:
    """One run of the USV mission. Call ``start()``, then ``run()``, and always ``stop()`` (or use ``with``)."""

    def __init__(
        self,
        settings: UsvSettings,
        launch_file: Path = LAUNCH_FILE,
        report: Callable[[str], None] = print,
        launch_delay_s: float = 0.2,
    ) -> None:
        self.settings = settings
        self.launch_file = launch_file
        self.report = report
        self.launch_delay_s = launch_delay_s
        self.record = MissionRecord()  # the live view, read from the logs as they grow
        self.clock = SimClock(settings.warp)
        self.group: ProcessGroup | None = None
        self.live = [PlatformLogs(directory, platform, settings.warp, self.record, moos=platform == settings.platform,
                                  origin=self.clock.origin) for platform, directory in self.log_dirs().items()]
        self.command_time: float | None = None
        # Set from any thread or a signal handler to end start-up, the wait for COMMAND, or the run.
        self.stop_event = threading.Event()
        self._stopped_result: MissionResult | None = None

    def start(self) -> None:
        """Start every process of the launch file (goby-logger and moos-logger among them)."""
        self.settings.run_dir.mkdir(parents=True, exist_ok=True)
        env = child_environment() | self.settings.to_env()
        self.group = ProcessGroup(
            parse_file(self.launch_file).entries,
            self.settings.log_dir,
            platform=self.settings.platform,
            launch_delay_s=self.launch_delay_s,
            kill_timeout_s=10.0,
            base_env=env,
            cwd=self.settings.run_dir,
            report=self.report,
        )
        self.group.stop_event = self.stop_event
        # the logs are read while the launch waits between processes, so the live view starts with the run
        self.group.on_wait = self.poll_logs
        self.group.start()

    def log_dirs(self) -> dict[str, Path]:
        """Where each platform's goby-logger (and the USV's moos-logger) write."""
        return {platform: data_log_dir(self.settings, platform)
                for platform in (self.settings.platform, self.settings.topside_platform)}

    def poll_logs(self) -> None:
        """Read what the loggers appended since the last poll into the live record."""
        for logs in self.live:
            logs.poll()

    def liaison_urls(self, timeout_s: float = 30.0, process_name: str = "goby-liaison") -> dict[str, str]:
        """The URLs a goby-liaison serves (home, scope, commander, map), read from its ready line in its log:
        the USV's (``goby-liaison``) or the topside's (``process_name="topside.liaison"``)."""
        assert self.group is not None
        process = next((p for p in self.group.processes if p.name.endswith(process_name)), None)
        if process is None:
            raise LaunchError(f"the launch file starts no {process_name}")
        deadline = time.monotonic() + timeout_s
        while True:
            self._check()
            try:
                text = process.log_path.read_text(errors="replace")
            except OSError:
                text = ""
            match = re.search(rf"{re.escape(LIAISON_READY)} (\S+)", text)
            if match:
                return liaison_page_urls(match.group(1))
            if time.monotonic() > deadline or self.stop_event.is_set():
                raise LaunchError(f"goby-liaison did not report its address within {timeout_s:g} s "
                                  f"(log {process.log_path})")
            time.sleep(0.1)

    def _check(self) -> None:
        assert self.group is not None
        died = self.group.check()
        if died is not None:
            raise ProcessDiedError(died.name, died.returncode, died.log_tail())

    def poll(self) -> None:
        """Read what the loggers appended and check that every process is alive (raises ProcessDiedError)."""
        self.poll_logs()
        self._check()
        if self.command_time is None:
            states = self.record.events_named("interface_state", source="interface")
            command = next((e.t for e in states if e.value == "INTERFACE_COMMAND"), None)
            self.command_time = command

    def wait_for_command(self, timeout_s: float = 120.0) -> float | None:
        """Block until the frontseat interface reports INTERFACE_COMMAND; returns that sim time.

        Returns None if ``stop_event`` is set first.
        """
        deadline = time.monotonic() + timeout_s
        while self.command_time is None:
            if self.stop_event.is_set():
                return None
            self.poll()
            if time.monotonic() > deadline:
                seen = [e.value for e in self.record.events_named("interface_state")]
                raise LaunchError(
                    f"the frontseat interface did not reach INTERFACE_COMMAND within {timeout_s:g} s "
                    f"(states seen: {', '.join(dict.fromkeys(seen)) or 'none'}; logs in {self.settings.log_dir})"
                )
            time.sleep(0.05)
        return self.command_time

    def run(
        self,
        duration_s: float | None,
        progress: Callable[[float], None] | None = None,
        progress_period_s: float = 2.0,
    ) -> None:
        """Run for ``duration_s`` sim seconds after COMMAND (None: until ``stop_event`` is set)."""
        t0 = self.wait_for_command()
        if t0 is None:
            return
        next_progress = 0.0
        while not self.stop_event.is_set():
            self.poll()
            elapsed = self.clock.now() - t0
            if progress is not None and time.monotonic() >= next_progress:
                progress(elapsed)
                next_progress = time.monotonic() + progress_period_s
            if duration_s is not None and elapsed >= duration_s:
                return
            time.sleep(0.05)

    def stop(self, failure: str | None = None) -> MissionResult:
        """Stop the processes (reverse order), check exit statuses and logs, then read the mission's logs."""
        if self._stopped_result is not None:
            return self._stopped_result
        end = self.clock.now()  # the run ends here: the logs go on while the processes stop
        for logs in self.live:
            logs.close()
        ended: list[ProcessOutcome] = []
        errors: list[str] = []
        if self.group is not None:
            self.group.stop()
            ended = outcomes(self.group.processes)
            errors = scan_logs(self.group.processes)
        record, paths = read_mission_logs(self.settings, self.clock.origin)
        record = until(record, end)
        states = record.events_named("interface_state", source="interface")
        command = next((e.t for e in states if e.value == "INTERFACE_COMMAND"), None)
        self._stopped_result = MissionResult(shifted(record, command or 0.0), command, ended, errors, failure, paths)
        return self._stopped_result

    def __enter__(self) -> UsvMission:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
