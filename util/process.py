"""One process lifecycle for every console script, launcher, test harness and benchmark.

* :func:`handle_signals`: SIGINT/SIGTERM handlers for the life of a ``with`` block; the previous handlers always
  come back (console scripts, ``run_application``, ``goby-launch``).
* :class:`ChildProcess`: one child with its output in a log file; wait until ready (a regex on its output or a
  listening port), stop with SIGTERM then SIGKILL after a grace period, exit status and log tail for reports.
* :func:`free_port`, :func:`port_open`, :func:`wait_until`: the only copies of those helpers.

Nothing here knows any program of this project: callers give the command line and what "ready" looks like.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import signal
import socket
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import IO, TYPE_CHECKING, TypeVar

if TYPE_CHECKING:  # imported where a child is started: most processes only use handle_signals (0.5 MiB each)
    import subprocess

log = logging.getLogger(__name__)

T = TypeVar("T")
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class ProcessError(Exception):
    """A child process did not start, did not become ready, or a wait timed out; the message names which and why."""


class WaitTimeout(ProcessError, TimeoutError):
    """:func:`wait_until` gave up; the message names what it waited for."""


def free_port(host: str = "127.0.0.1") -> int:
    """A TCP port that was free a moment ago on ``host``."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind((host, 0))
        return sock.getsockname()[1]


def port_open(port: int, host: str = "127.0.0.1") -> bool:
    """True when something accepts TCP connections on ``host:port``."""
    with socket.socket() as sock:
        sock.settimeout(0.2)
        return sock.connect_ex((host, port)) == 0


def pid_alive(pid: int) -> bool:
    """True while process ``pid`` exists and is not a zombie (``/proc``; a reaped or unknown pid is not alive)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


def wait_until(predicate: Callable[[], T], timeout: float = 20.0, what: str = "", *, interval: float = 0.02) -> T:
    """Poll ``predicate`` until it returns something truthy, and return that.

    Raises :class:`WaitTimeout` (a ``TimeoutError``) naming ``what`` after ``timeout`` seconds; the predicate is
    always tried once more at the deadline, so a slow machine never fails a condition that holds.
    """
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() >= deadline:
            raise WaitTimeout(f"timed out after {timeout:g} s waiting for {what or getattr(predicate, '__name__', predicate)}")
        time.sleep(interval)


@contextlib.contextmanager
def handle_signals(callback: Callable[[int], None] | None = None,
                   signals: Sequence[signal.Signals] = STOP_SIGNALS) -> Iterator[threading.Event]:
    """Install handlers for ``signals`` (SIGINT and SIGTERM) for the ``with`` block; yield an event they set.

    ``callback(signum)``, when given, runs in the handler (on the main thread, between two bytecodes of whatever
    it was doing: keep it to setting flags). The previous handlers are restored on exit, even on an exception.
    Off the main thread (a test calling ``main()`` from a worker) nothing is installed and the event is only set
    by the caller.
    """
    event = threading.Event()
    if threading.current_thread() is not threading.main_thread():
        yield event
        return

    def handler(signum: int, _frame: object) -> None:
        log.debug("received %s", signal.Signals(signum).name)
        event.set()
        if callback is not None:
            callback(signum)

    previous = {}
    try:
        for sig in signals:
            previous[sig] = signal.signal(sig, handler)
        yield event
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


Ready = str | re.Pattern[str]


class ChildProcess:
    """One child process whose stdout (and stderr, unless ``stderr_path`` is given) goes to ``log_path``.

    The first ``start()`` truncates the log; a later one (a restart after the child ended) appends to it, and the
    output of the current run is what :meth:`output`, :meth:`wait_for_output` and :meth:`wait_ready` read. With
    ``new_session=True`` the child leads its own process group (a terminal's Ctrl-C does not reach it) and signals
    go to the whole group, so helpers it spawned stop with it. Use from one thread. A context manager: ``with
    ChildProcess(...) as child`` starts it and stops it.
    """

    def __init__(self, args: Sequence[str], log_path: str | os.PathLike[str], *, name: str | None = None,
                 env: Mapping[str, str] | None = None, cwd: str | os.PathLike[str] | None = None,
                 stderr_path: str | os.PathLike[str] | None = None, new_session: bool = False) -> None:
        self.args = [str(a) for a in args]
        self.log_path = Path(log_path)
        self.stderr_path = Path(stderr_path) if stderr_path is not None else None
        self.name = name or Path(self.args[0]).name
        self.env = dict(env) if env is not None else None
        self.cwd = cwd
        self.new_session = new_session
        self.popen: subprocess.Popen[bytes] | None = None
        self.killed = False  # the last stop needed SIGKILL
        self.stop_requested = False
        self._files: list[IO[bytes]] = []
        self._offset = 0  # where this run's output starts in the log

    # -- starting -------------------------------------------------------------------------------

    def start(self) -> ChildProcess:
        """Start the child (no-op while it runs); raises :class:`ProcessError` if it cannot be executed."""
        if self.running:
            return self
        self._close_files()
        self.log_path.parent.mkdir(parents=True, exist_ok=True)
        mode = "ab" if self.popen is not None else "wb"  # a restart appends to the first run's log
        out = open(self.log_path, mode)  # noqa: SIM115 - closed when the child is reaped
        self._offset = out.tell()
        self._files = [out]
        import subprocess

        err: IO[bytes] | int = subprocess.STDOUT
        if self.stderr_path is not None:
            err = open(self.stderr_path, mode)  # noqa: SIM115
            self._files.append(err)
        env = self.env
        if env is not None:
            env = {**env, "PYTHONUNBUFFERED": env.get("PYTHONUNBUFFERED", "1")}
        else:
            env = {**os.environ, "PYTHONUNBUFFERED": os.environ.get("PYTHONUNBUFFERED", "1")}
        self.killed = self.stop_requested = False
        try:
            self.popen = subprocess.Popen(self.args, stdin=subprocess.DEVNULL, stdout=out, stderr=err, env=env,
                                          cwd=self.cwd, start_new_session=self.new_session)
        except OSError as exc:
            self._close_files()
            raise ProcessError(f"cannot start {self.name} ({' '.join(self.args)}): {exc}") from exc
        log.debug("started %s pid %d, log %s", self.name, self.popen.pid, self.log_path)
        return self

    def wait_for_output(self, pattern: Ready | Callable[[str], bool], timeout: float = 30.0) -> re.Match[str] | None:
        """Wait until this run's output matches ``pattern`` and return the match; None when ``timeout`` passes or the
        child ends without printing it.

        A regex (a ``str`` is compiled with ``re.MULTILINE``, so ``^``/``$`` are line ends) is searched in the
        complete lines printed so far, so it may span lines; a predicate is tried on each line (the match is then
        the whole line).
        """
        if callable(pattern) and not isinstance(pattern, re.Pattern):
            test = pattern

            def find(text: str) -> re.Match[str] | None:
                line = next((line for line in text.splitlines() if test(line)), None)
                return None if line is None else re.fullmatch(".*", line)
        else:
            regex = re.compile(pattern, re.MULTILINE) if isinstance(pattern, str) else pattern

            def find(text: str) -> re.Match[str] | None:
                return regex.search(text)
        deadline = time.monotonic() + timeout
        while True:
            ended = not self.running  # read once more after the child ended: it may have printed just before
            text = self.output()
            found = find(text if ended else text[: text.rfind("\n") + 1])
            if found or ended or time.monotonic() >= deadline:
                return found
            time.sleep(0.02)

    def wait_ready(self, pattern: Ready | None = None, *, port: int | None = None, host: str = "127.0.0.1",
                   timeout: float = 30.0) -> re.Match[str] | None:
        """Wait until the output matches ``pattern`` and/or ``port`` accepts connections; return the match.

        On failure (the child ended, or ``timeout`` passed) the child is stopped and :class:`ProcessError` raised,
        naming the child, its exit status and the tail of its log.
        """
        deadline = time.monotonic() + timeout
        found = None
        if pattern is not None:
            found = self.wait_for_output(pattern, timeout)
            if found is None:
                self._fail(f"did not print {getattr(pattern, 'pattern', pattern)!r}", timeout)
        if port is not None:
            try:
                wait_until(lambda: port_open(port, host) or not self.running, max(0.0, deadline - time.monotonic()),
                           f"{self.name} to listen on {host}:{port}")
            except WaitTimeout:
                self._fail(f"did not listen on {host}:{port}", timeout)
            if not self.running:
                self._fail(f"did not listen on {host}:{port}", timeout)
        return found

    def _fail(self, what: str, timeout: float) -> None:
        code = self.poll()
        reason = f"exited with status {code}" if code is not None else f"still running after {timeout:g} s"
        self.stop(grace=2.0)
        raise ProcessError(f"{self.name} {what} ({reason}); last lines of {self.log_path}:\n{self.tail()}")

    # -- state ----------------------------------------------------------------------------------

    @property
    def pid(self) -> int:
        assert self.popen is not None, "not started"
        return self.popen.pid

    def poll(self) -> int | None:
        """The exit status (negative: killed by that signal), or None while it runs or before it started."""
        return self.popen.poll() if self.popen is not None else None

    @property
    def returncode(self) -> int | None:
        return self.poll()

    @property
    def running(self) -> bool:
        return self.popen is not None and self.popen.poll() is None

    def output(self) -> str:
        """What this run wrote to ``log_path`` so far."""
        for f in self._files:
            if not f.closed:
                f.flush()
        try:
            with open(self.log_path, "rb") as f:
                f.seek(self._offset)
                return f.read().decode(errors="replace")
        except OSError:
            return ""

    def lines(self) -> list[str]:
        return self.output().splitlines()

    def stderr_text(self) -> str:
        """What this child wrote to ``stderr_path`` (all runs), or "" without one."""
        if self.stderr_path is None or not self.stderr_path.exists():
            return ""
        return self.stderr_path.read_text(errors="replace")

    def tail(self, lines: int = 20, indent: str = "    ") -> str:
        """The last ``lines`` lines of this run's log (and stderr file), indented, for error reports."""
        text = self.output() + (self.stderr_text() if self.stderr_path is not None else "")
        last = text.splitlines()[-lines:]
        return "\n".join(indent + line for line in last) if last else f"{indent}(log is empty)"

    # -- stopping -------------------------------------------------------------------------------

    def send_signal(self, sig: int) -> None:
        """Signal the child (its whole group with ``new_session``); no-op once it ended."""
        if not self.running:
            return
        assert self.popen is not None
        if self.new_session:
            with contextlib.suppress(ProcessLookupError):
                try:
                    os.killpg(self.popen.pid, sig)
                except PermissionError:
                    self.popen.send_signal(sig)
        else:
            self.popen.send_signal(sig)

    def wait(self, timeout: float | None = None) -> int | None:
        """Wait for the child to end by itself; its exit status, or None on timeout."""
        if self.popen is None:
            return None
        import subprocess

        try:
            return self.popen.wait(timeout)
        except subprocess.TimeoutExpired:
            return None

    def stop(self, grace: float = 10.0, sig: int = signal.SIGTERM) -> int | None:
        """Send ``sig``, wait ``grace`` seconds, then SIGKILL; close the log; return the exit status. Idempotent."""
        if self.popen is None:
            return None
        if self.running:
            self.stop_requested = True
            self.send_signal(sig)
            if self.wait(grace) is None:
                log.warning("%s (%d) did not end %g s after %s; sending SIGKILL", self.name, self.popen.pid, grace,
                            signal.Signals(sig).name)
                self.killed = True
                self._kill_now()
        self.popen.wait()
        self._reap_group()
        self._close_files()
        return self.popen.returncode

    def kill(self) -> int | None:
        """SIGKILL now (as a crash would) and wait; returns the exit status."""
        if self.popen is None:
            return None
        if self.running:
            self.killed = True
            self._kill_now()
        return self.stop()

    def _kill_now(self) -> None:
        assert self.popen is not None
        if self.new_session:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(self.popen.pid, signal.SIGKILL)
        with contextlib.suppress(ProcessLookupError):
            self.popen.kill()
        self.popen.wait()

    def _reap_group(self) -> None:
        """The program is gone; helpers left in its group (a shell's process substitution) go too."""
        if self.new_session and self.popen is not None:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(self.popen.pid, signal.SIGKILL)

    def _close_files(self) -> None:
        for f in self._files:
            f.close()
        self._files = []

    def __enter__(self) -> ChildProcess:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def __repr__(self) -> str:
        state = "not started" if self.popen is None else f"pid {self.popen.pid}, exit {self.poll()}"
        return f"ChildProcess({self.name!r}, {state})"
