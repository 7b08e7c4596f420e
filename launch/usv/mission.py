"""Run the USV mission from Python: launch usv.launch's processes, record them, stop them, check the logs.

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

from gateway.goby.portal.endpoints import ipc_manager_path
from launch.errors import LaunchError, ProcessDiedError
from launch.launchfile import parse_file
from launch.liaison.portal_side import READY_PREFIX as LIAISON_READY
from launch.mission import ProcessOutcome, choose_program, outcomes, scan_logs
from launch.process_group import ProcessGroup, child_environment
from launch.record import MissionRecord, shifted
from launch.recorder import MoosRecorder, PortalRecorder, SimClock
from launch.usv.settings import USV_DIR, UsvSettings

log = logging.getLogger(__name__)

LAUNCH_FILE = USV_DIR / "usv.launch"
__all__ = ["LAUNCH_FILE", "MissionResult", "UsvMission", "choose_program"]


@dataclass
class MissionResult:
    """Everything the demo prints and the test asserts: the record (t=0 at COMMAND) and the shutdown."""

    record: MissionRecord
    command_time: float | None
    outcomes: list[ProcessOutcome] = field(default_factory=list)
    log_errors: list[str] = field(default_factory=list)
    failure: str | None = None


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
        self.record = MissionRecord()
        self.clock = SimClock(settings.warp)
        self.group: ProcessGroup | None = None
        self.moos: MoosRecorder | None = None
        self.portal: PortalRecorder | None = None
        self.topside: PortalRecorder | None = None
        self.command_time: float | None = None
        # Set from any thread or a signal handler to end start-up, the wait for COMMAND, or the run.
        self.stop_event = threading.Event()
        self._stopped_result: MissionResult | None = None

    def start(self) -> None:
        """Start every process of the launch file, then the recorders."""
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
        # The MOOS client retries until the MOOSDB is up, so it sees everything from the first posting; its mail
        # is read while the launch waits between processes, so start-up events get their real times.
        self.moos = MoosRecorder(self.record, self.clock, self.settings.moos_port)
        self.moos.start()
        self.group.on_wait = self._record_start_up
        self.group.start()
        self._wait_for_brokers()

    def _record_start_up(self) -> None:
        """While the launch waits between processes: read MOOS mail, and start each portal recorder as soon as its
        broker is up, so it listens before the shore (launched after both brokers) can send anything."""
        assert self.moos is not None
        self.moos.poll()
        self._start_portal_recorders()

    def _start_portal_recorders(self) -> list[str]:
        """The USV broker's recorder (interface state) and the topside's (the satellite link's acks), each once its
        broker is up; returns the manager sockets still missing."""
        if self.portal is None:
            self.portal = self._recorder_if_up(self.settings.platform, self.settings.ipc_base)
        if self.topside is None:
            self.topside = self._recorder_if_up(self.settings.topside_platform, self.settings.topside_ipc_base)
        return [ipc_manager_path(base) for recorder, base in ((self.portal, self.settings.ipc_base),
                                                              (self.topside, self.settings.topside_ipc_base))
                if recorder is None]

    def _recorder_if_up(self, platform: str, ipc_base: str) -> PortalRecorder | None:
        """A started recorder on the broker at ``ipc_base``, or None while its manager socket does not exist."""
        if not Path(ipc_manager_path(ipc_base)).exists():
            return None
        recorder = PortalRecorder(self.record, self.clock, platform, ipc_base)
        recorder.start()
        return recorder

    def _wait_for_brokers(self, timeout_s: float = 120.0) -> None:
        """Block until both portal recorders have started, i.e. both brokers (the USV's, the topside's) have their
        manager socket: the topside's is launched late, and a portal client gives up if its broker does not
        answer."""
        deadline = time.monotonic() + timeout_s
        while missing := self._start_portal_recorders():
            if self.stop_event.is_set():
                return
            self._check()
            if time.monotonic() > deadline:
                raise LaunchError(f"no broker at {', '.join(missing)} within {timeout_s:g} s "
                                  f"(logs in {self.settings.log_dir})")
            time.sleep(0.1)

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
        for recorder in (self.portal, self.topside):
            if recorder is not None and recorder.error is not None:
                raise LaunchError(f"the demo's portal recorder failed: {recorder.error}")

    def poll(self) -> None:
        """File new MOOS mail and check that every process is alive (raises ProcessDiedError)."""
        if self.moos is not None:
            self.moos.poll()
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
        """Stop the recorders, then the processes (reverse order); check exit statuses and logs."""
        if self._stopped_result is not None:
            return self._stopped_result
        if self.moos is not None:
            self.moos.poll()
            self.moos.close()
        for recorder in (self.portal, self.topside):
            if recorder is not None:
                recorder.close()
        ended: list[ProcessOutcome] = []
        errors: list[str] = []
        if self.group is not None:
            self.group.stop()
            ended = outcomes(self.group.processes)
            errors = scan_logs(self.group.processes)
        t0 = self.command_time or 0.0
        self._stopped_result = MissionResult(shifted(self.record, t0), self.command_time, ended, errors, failure)
        return self._stopped_result

    def __enter__(self) -> UsvMission:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
