"""Start launch entries as child processes, watch them, and stop them in reverse order.

Each entry runs as ``bash -c "exec <command>"`` in its own session (so a terminal's Ctrl-C reaches only
the launcher, which then stops the children in order), with stdout and stderr in one log file per
process. Shutdown follows goby_launch: a line's ``kill=`` method, by default ``goby_terminate`` when the launch file
has exactly one broker line (the broker itself gets SIGTERM) and SIGTERM otherwise.  ``goby_terminate`` runs
``goby-terminate --target_pid PID`` with the broker's ``interprocess`` block (read at start-up from the broker line run
with ``--app 'debug_cfg: true'``, as goby_launch does) and waits up to ``terminate_timeout_s`` (``-m``); a process that
does not quit then gets SIGTERM.  A signal is followed by SIGKILL after ``kill_timeout_s`` (``-k``).
"""

from __future__ import annotations

import logging
import os
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from launch.errors import LaunchError, ProcessDiedError
from launch.launchfile import KILL_SIGNALS, LaunchEntry, expand_vars
from util.process import ChildProcess, ProcessError
from util.reactor import Reactor

log = logging.getLogger(__name__)

Reporter = Callable[[str], None]
_ASSIGNMENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*=")
POLL_PERIOD_S = 0.1
# The line a launcher prints per launch (``_report_launched``): pid and name, for tools reading its output.
LAUNCHED_LINE = re.compile(r"^Launched \((\d+)\) (\S+):", re.M)
BROKER_PROGRAMS = frozenset({"goby-broker", "gobyd"})
TERMINATE_COMMAND = (sys.executable, "-m", "gateway.apps.goby_terminate")
BROKER_CONFIG_TIMEOUT_S = 30.0  # for the broker line's ``--app 'debug_cfg: true'`` run
_INTERPROCESS_BLOCK = re.compile(r"^interprocess\s*\{", re.M)


def interprocess_block(config_text: str) -> str | None:
    """The inside of the top-level ``interprocess { ... }`` block of a printed configuration, on one line."""
    match = _INTERPROCESS_BLOCK.search(config_text)
    if match is None:
        return None
    depth, start = 1, match.end()
    for index in range(start, len(config_text)):
        char = config_text[index]
        depth += {"{": 1, "}": -1}.get(char, 0)
        if depth == 0:
            return " ".join(config_text[start:index].split())
    return None


def _print(line: str) -> None:
    print(line, flush=True)


@dataclass
class ManagedProcess:
    """One launched entry: its child process (``util.process.ChildProcess``) and whether its end was reported."""

    name: str
    entry: LaunchEntry
    child: ChildProcess
    started_at: float = field(default_factory=time.monotonic)
    reported: bool = False
    respawns: int = 0  # how often a supervisor started it again after it died

    @property
    def pid(self) -> int:
        return self.child.pid

    @property
    def log_path(self) -> Path:
        return self.child.log_path

    @property
    def returncode(self) -> int | None:
        return self.child.poll()

    @property
    def running(self) -> bool:
        return self.child.running

    @property
    def stop_requested(self) -> bool:
        return self.child.stop_requested

    @property
    def exited_cleanly(self) -> bool:
        """True once it ended on its own with status 0, or on our stop signal without needing SIGKILL."""
        code = self.child.poll()
        if code is None or self.child.killed:
            return False
        return code == 0 or (self.child.stop_requested and code == -self.entry.kill_signal)

    def log_tail(self, lines: int = 20) -> str:
        """The last lines of the process's log, for error reports."""
        return self.child.tail(lines)


class ProcessGroup:
    """The processes of one launch file: started in order, stopped in reverse order.

    Methods are meant to be called from one thread (the launcher's main thread); ``stop_event``
    may be set from any thread or a signal handler to interrupt start-up or supervision.
    """

    def __init__(
        self,
        entries: Sequence[LaunchEntry],
        log_dir: str | Path,
        *,
        platform: str = "",
        launch_delay_s: float = 0.01,
        kill_timeout_s: float = 10.0,
        startup_check_s: float = 1.0,
        base_env: Mapping[str, str] | None = None,
        cwd: str | Path | None = None,
        parallel_stop: bool = False,
        report: Reporter = _print,
        on_wait: Callable[[], None] | None = None,
        preamble: str = "",
        terminate_timeout_s: float = 10.0,
    ) -> None:
        if not entries:
            raise LaunchError("nothing to launch: the launch file has no commands")
        self.entries = list(entries)
        self.log_dir = Path(log_dir)
        self.platform = platform
        self.launch_delay_s = launch_delay_s
        self.kill_timeout_s = kill_timeout_s
        self.startup_check_s = startup_check_s
        self.base_env = dict(os.environ if base_env is None else base_env)
        self.cwd = Path(cwd) if cwd is not None else None
        self.parallel_stop = parallel_stop
        self.report = report
        # Called on the starting thread while start() waits between launches (e.g. to read mail meanwhile).
        self.on_wait = on_wait
        # Shell run before each command (goby_launch sources a preseed.goby found next to the launch file).
        self.preamble = preamble
        self.terminate_timeout_s = terminate_timeout_s
        # The broker's interprocess block for goby-terminate; None: goby_terminate is not used (SIGTERM instead)
        self.terminate_interprocess: str | None = None
        self.processes: list[ManagedProcess] = []
        self.stop_event = threading.Event()
        self.stop_reason: str | None = None  # why a stop was requested, reported by the thread that stops
        self._named_once = False
        self._reactor: Reactor | None = None

    # -- start-up -------------------------------------------------------------------------------

    def _unique_name(self, entry: LaunchEntry, env: Mapping[str, str]) -> str:
        # name= may use the line's variables (e.g. ${GOBY_LAUNCH_PLATFORM}.helm)
        base = expand_vars(entry.name, env) if entry.name else ""
        base = base or os.path.basename(expand_vars(entry.binary, env)) or "process"
        if self.platform and not entry.name:
            base = f"{self.platform}.{base}"
        taken = {p.name for p in self.processes}
        name, n = base, 1
        while name in taken:
            n += 1
            name = f"{base}.{n}"
        return name

    def _spawn(self, entry: LaunchEntry) -> ManagedProcess:
        env = entry.environment(self.base_env)
        name = self._unique_name(entry, env)
        # `exec` makes the program itself the pid we signal; bash cannot exec an assignment prefix.
        script = entry.command if _ASSIGNMENT.match(entry.command) else f"exec {entry.command}"
        if self.preamble:
            script = f"{self.preamble}\n{script}"
        child = ChildProcess(["/bin/bash", "-c", script], self.log_dir / f"{name}.log", name=name, env=env,
                             cwd=self.cwd, new_session=True)
        try:
            child.start()
        except ProcessError as exc:
            raise LaunchError(f"cannot start {name!r} ({entry.command}): {exc}") from exc
        process = ManagedProcess(name=name, entry=entry, child=child)
        self.processes.append(process)
        self._report_launched(process)
        log.info("launched %s pid %d, log %s", name, child.pid, child.log_path)
        return process

    def _report_launched(self, process: ManagedProcess) -> None:
        """``Launched (<pid>) <name>: <command>``, as goby_launch prints it (``LAUNCHED_LINE`` reads it back)."""
        self.report(f"Launched ({process.pid}) {process.name}: {process.entry.command}")

    def start(self) -> None:
        """Launch every entry in order with the launch delay, then check that all are still up.

        On a death during start-up, stops what was started and raises ProcessDiedError.
        """
        self.terminate_interprocess = self._broker_interprocess()
        try:
            for entry in self.entries:
                if self.stop_event.is_set():
                    return
                self._spawn(entry)
                self._wait_checking(self.launch_delay_s)
            self._wait_checking(self.startup_check_s)
        except ProcessDiedError:
            self.stop()
            raise

    def _wait_checking(self, seconds: float) -> None:
        deadline = time.monotonic() + seconds
        while True:
            died = self.check()
            if died is not None:
                raise ProcessDiedError(died.name, died.returncode, died.log_tail())
            if self.on_wait is not None:
                self.on_wait()
            remaining = deadline - time.monotonic()
            if remaining <= 0 or self.stop_event.wait(min(POLL_PERIOD_S, remaining)):
                return

    def _broker_interprocess(self) -> str | None:
        """The interprocess block of the one broker line, for goby-terminate (None: use SIGTERM), as goby_launch."""
        brokers = [e for e in self.entries if self._is_broker(e)]
        if len(brokers) != 1:
            self.report(f"Note: {'no line' if not brokers else 'more than one line'} launching a broker - will use "
                        "SIGTERM instead of goby_terminate to stop processes (unless marked with [kill=...])")
            return None
        entry = brokers[0]
        script = f"{entry.command} --app 'debug_cfg: true'"
        if not _ASSIGNMENT.match(entry.command):
            script = f"exec {script}"
        if self.preamble:
            script = f"{self.preamble}\n{script}"
        try:
            run = subprocess.run(["/bin/bash", "-c", script], env=entry.environment(self.base_env), cwd=self.cwd,
                                 stdin=subprocess.DEVNULL, capture_output=True, text=True,
                                 timeout=BROKER_CONFIG_TIMEOUT_S, check=False)
            block = interprocess_block(run.stdout) if run.returncode == 0 else None
        except (OSError, subprocess.TimeoutExpired) as exc:
            log.warning("cannot read the broker's configuration: %s", exc)
            block = None
        if block is None:
            self.report(f"Note: cannot read the interprocess configuration of {entry.command!r} - will use SIGTERM "
                        "instead of goby_terminate to stop processes")
        return block

    def _is_broker(self, entry: LaunchEntry) -> bool:
        """Whether a line runs a broker (ours or gobyd), its variables expanded: ``${TRAIL_GOBY_BROKER:-goby-broker}``."""
        return os.path.basename(expand_vars(entry.binary, entry.environment(self.base_env))) in BROKER_PROGRAMS

    def kill_method(self, process: ManagedProcess) -> str:
        """How ``process`` is stopped: its ``kill=``, else goby_terminate (one broker line; not the broker) or SIGTERM."""
        entry = process.entry
        method = entry.kill if entry.kill_given else "goby_terminate"
        if method == "goby_terminate" and (self.terminate_interprocess is None or self._is_broker(entry)):
            return "SIGTERM"
        return method

    def _terminate(self, processes: Sequence[ManagedProcess]) -> list[ManagedProcess]:
        """Run goby-terminate for ``processes`` and wait; returns those still running afterwards."""
        assert self.terminate_interprocess is not None
        args = [*TERMINATE_COMMAND, "--response_timeout", f"{self.terminate_timeout_s:g}",
                "--interprocess", self.terminate_interprocess]
        for process in processes:
            process.child.stop_requested = True
            args += ["--target_pid", str(process.pid)]
        tool = ChildProcess(args, self.log_dir / "goby-terminate.log", name="goby-terminate", env=self.base_env,
                            cwd=self.cwd)
        try:
            tool.start()
        except ProcessError as exc:
            log.warning("cannot run goby-terminate: %s", exc)
            return [p for p in processes if p.running]
        if tool.wait(self.terminate_timeout_s + BROKER_CONFIG_TIMEOUT_S) is None:
            log.warning("goby-terminate did not end; stopping it")
        tool.stop(grace=2.0)
        for process in processes:
            if process.child.wait(1.0) is not None:  # goby-terminate saw it end: reap it and close its log
                process.child.stop()
        return [p for p in processes if p.running]

    # -- supervision ----------------------------------------------------------------------------

    def check(self) -> ManagedProcess | None:
        """The first process that ended unexpectedly (non-zero status, not asked to stop), if any.

        A process that exits with status 0 on its own has finished its job; that is reported once.
        """
        for process in self.processes:
            code = process.returncode
            if code is None or process.stop_requested or process.reported:
                continue
            process.reported = True
            if code == 0:
                self.report(f"[{self.platform}] {time.strftime('%H:%M:%S')}: {process.name} finished")
                continue
            return process
        return None

    def running(self) -> list[ManagedProcess]:
        return [p for p in self.processes if p.running]

    def respawn(self, process: ManagedProcess) -> ManagedProcess:
        """Start a process that ended again, same entry and name (its log is appended to); returns it.

        For supervisors that restart what dies (``supervise(respawn_limit=)``, the chaos soak in
        bench/bench_chaos.py); by default the launcher stops everything when one process dies, as goby_launch does.
        """
        if process.running:
            raise LaunchError(f"{process.name} is still running; stop it before respawning it")
        process.child.stop()  # reap it; helpers left in its group (process substitution) go too
        try:
            process.child.start()
        except ProcessError as exc:
            raise LaunchError(f"cannot start {process.name!r} ({process.entry.command}): {exc}") from exc
        process.reported = False
        process.started_at = time.monotonic()
        process.respawns += 1
        self._report_launched(process)
        return process

    def supervise(self, status_period_s: float = 5.0, respawn_limit: int = 0) -> int:
        """Watch the processes until ``request_stop()``, one dies, or all finish; then stop them all.

        Sleeps on a reactor until a child ends (a pidfd per child) or the status line is due: no polling.
        A process that dies is started again (its log appended to) while it has died no more than
        ``respawn_limit`` times; past that, or with the default 0, the others are stopped as goby_launch does.
        Returns the exit status for the launcher: 0 after a requested stop or when every process
        finished cleanly, 1 when a process died for good (named in the report with the tail of its log).
        """
        reactor = Reactor(f"launch-{self.platform or 'group'}")
        self._reactor = reactor
        watched: dict[int, int] = {}  # pid -> pidfd
        outcome = {"status": 0}

        def watch(process: ManagedProcess) -> None:
            try:
                fd = os.pidfd_open(process.pid)
            except OSError:  # already reaped: the next check() sees it
                reactor.call_later(0.0, review)
                return
            watched[process.pid] = fd
            reactor.add_reader(fd, review)

        def unwatch_ended() -> None:
            for process in self.processes:
                fd = watched.get(process.pid)
                if fd is not None and not process.running:
                    reactor.remove_reader(fd)
                    os.close(fd)
                    del watched[process.pid]

        def review() -> None:
            died = self.check()
            unwatch_ended()
            if died is not None:
                stamp = f"[{self.platform}] {time.strftime('%H:%M:%S')}: {died.name} died unexpectedly " \
                        f"(exit status {died.returncode})"
                tail = f"Last lines of {died.log_path}:\n{died.log_tail()}"
                if died.respawns < respawn_limit:
                    self.report(f"{stamp}; respawning it ({died.respawns + 1} of {respawn_limit}). {tail}")
                    watch(self.respawn(died))
                    reactor.call_later(0.0, review)  # another may have died meanwhile
                    return
                self.report(f"{stamp}; stopping the others. {tail}")
                outcome["status"] = 1
                reactor.stop()
                return
            if not self.running():
                self.report(f"[{self.platform}]: All processes exited")
                reactor.stop()

        try:
            for process in self.processes:
                if process.running:
                    watch(process)
            self._report_status()
            reactor.call_every(status_period_s, self._report_status, align=False)
            reactor.call_later(0.0, review)
            if not self.stop_event.is_set():
                reactor.run(until=self.stop_event.is_set)
        finally:
            self._reactor = None
            reactor.close()
            for fd in watched.values():
                os.close(fd)
            if self.stop_reason is not None:
                self.report(self.stop_reason)
            self.stop()
        return outcome["status"]

    def request_stop(self, reason: str | None = None) -> None:
        """Ask ``start()``/``supervise()`` to stop everything (thread- and signal-safe: no I/O here); ``reason`` is
        reported by the stopping thread (a print inside a signal handler can meet the same stream mid-write)."""
        if reason is not None and self.stop_reason is None:
            self.stop_reason = reason
        self.stop_event.set()
        reactor = self._reactor
        if reactor is not None:
            reactor.stop()

    def _report_status(self) -> None:
        stamp = time.strftime("%H:%M:%S")
        running = self.running()
        if len(running) == len(self.processes):
            names = "" if self._named_once else ": " + ", ".join(p.name for p in running)
            self._named_once = True
            self.report(f"[{self.platform}] {stamp}: All processes running ({len(running)}){names}")
            return
        for process in self.processes:
            if not process.running:
                self.report(f"[{self.platform}] {stamp}: Missing PID: {process.pid} (was: {process.name})")

    # -- shutdown -------------------------------------------------------------------------------

    def _stop_all(self, processes: Sequence[ManagedProcess]) -> None:
        """goby-terminate those stopped that way (one run for all), then signal the rest at once and give them
        ``kill_timeout_s`` together before SIGKILL."""
        by_terminate = [p for p in processes if self.kill_method(p) == "goby_terminate"]
        left = self._terminate(by_terminate) if by_terminate else []
        for process in left:
            self.report(f"=== WARNING ===: {process.name} ({process.pid}) did not respond to goby_terminate, "
                        "sending SIGTERM")
        signalled = [p for p in processes if p not in by_terminate or p in left]
        for process in signalled:
            process.child.stop_requested = True
            process.child.send_signal(self._signal_of(process))
        deadline = time.monotonic() + self.kill_timeout_s
        for process in signalled:
            self._stop_one(process, max(0.0, deadline - time.monotonic()))

    def _signal_of(self, process: ManagedProcess) -> signal.Signals:
        method = self.kill_method(process)
        return signal.SIGTERM if method == "goby_terminate" else KILL_SIGNALS[method]

    def _stop_one(self, process: ManagedProcess, grace: float) -> None:
        sig = self._signal_of(process)
        process.child.stop(grace=grace, sig=sig)
        if process.child.killed:
            self.report(f"WARNING: {process.name} ({process.pid}) did not respond to "
                        f"{sig.name} after {self.kill_timeout_s:g} s, sending SIGKILL")

    def _stop_in_turn(self, process: ManagedProcess) -> None:
        """goby_launch's do_killone: goby_terminate first if that is the method, then the signal."""
        if self.kill_method(process) == "goby_terminate":
            self.report(f"goby_terminate: {process.pid} (was {process.name})")
            if not self._terminate([process]):
                self.report(f"goby_terminate: {process.pid} (was {process.name}) .... success")
                return
            self.report(f"=== WARNING ===: Process {process.pid} did not respond to goby_terminate, sending SIGTERM")
        self.report(f"{self._signal_of(process).name}: {process.pid} (was {process.name})")
        self._stop_one(process, self.kill_timeout_s)

    def stop(self) -> None:
        """Stop every running process (reverse launch order, or all at once if parallel_stop)."""
        order = list(reversed(self.processes))
        for process in order:
            if not process.running:
                process.child.stop()  # reap it and close its log
        live = [p for p in order if p.running]
        if not live:
            return
        self.report("Cleaning up...")
        if self.parallel_stop:
            # All at once, except the brokers: they go last, as goby_launch -P kills gobyd last, so the other
            # processes can still talk to them while they shut down.
            brokers = [p for p in live if self._is_broker(p.entry)]
            for wave in ([p for p in live if p not in brokers], brokers):
                self._stop_all(wave)
        else:
            for process in live:
                self._stop_in_turn(process)
        for process in live:
            verdict = "success" if process.exited_cleanly else f"exit status {process.returncode}"
            log.info("%s stopped: %s", process.name, verdict)

    def __enter__(self) -> ProcessGroup:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def child_environment() -> dict[str, str]:
    """Our environment, with this interpreter's bin directory first on PATH.

    So a launch file finds the console scripts of the same installation (``moos-db``, ``ivp-helm``, ...)
    and ``python`` is this interpreter, even when the virtualenv is not activated.
    """
    env = dict(os.environ)
    bin_dir = os.path.dirname(sys.executable)
    path = env.get("PATH", "").split(os.pathsep)
    if bin_dir not in path:
        env["PATH"] = os.pathsep.join([bin_dir, *[p for p in path if p]])
    return env
