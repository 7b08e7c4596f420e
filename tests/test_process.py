"""util.process: the signal context manager, ChildProcess, free_port and wait_until, with real child processes."""

from __future__ import annotations

import os
import signal
import socket
import sys
import threading
import time
from pathlib import Path

import pytest

from util.process import (
    ChildProcess,
    ProcessError,
    WaitTimeout,
    free_port,
    handle_signals,
    port_open,
    wait_until,
)

PY = sys.executable


def _script(tmp_path: Path, body: str) -> list[str]:
    path = tmp_path / "child.py"
    path.write_text(body)
    return [PY, str(path)]


def test_handle_signals_sets_the_event_calls_back_and_restores_the_previous_handlers() -> None:
    def before(_signum: int, _frame: object) -> None:
        raise AssertionError("the previous handler must not run inside the block")

    old_int = signal.signal(signal.SIGINT, before)
    old_term = signal.getsignal(signal.SIGTERM)
    seen: list[int] = []
    try:
        with handle_signals(seen.append) as stop:
            assert not stop.is_set()
            os.kill(os.getpid(), signal.SIGTERM)
            assert wait_until(stop.is_set, 5, "SIGTERM to set the event")
            assert seen == [signal.SIGTERM]
        assert signal.getsignal(signal.SIGINT) is before
        assert signal.getsignal(signal.SIGTERM) == old_term
    finally:
        signal.signal(signal.SIGINT, old_int)


def test_handle_signals_restores_even_when_the_block_raises() -> None:
    previous = signal.getsignal(signal.SIGINT)
    with pytest.raises(RuntimeError), handle_signals():
        assert signal.getsignal(signal.SIGINT) is not previous
        raise RuntimeError("boom")
    assert signal.getsignal(signal.SIGINT) is previous


def test_handle_signals_off_the_main_thread_installs_nothing() -> None:
    previous = signal.getsignal(signal.SIGINT)
    during: list[object] = []

    def worker() -> None:
        with handle_signals() as stop:
            during.append(signal.getsignal(signal.SIGINT))
            during.append(stop.is_set())

    thread = threading.Thread(target=worker)
    thread.start()
    thread.join(10)
    assert during == [previous, False]


def test_free_port_is_bindable_and_port_open_sees_a_listener() -> None:
    port = free_port()
    assert not port_open(port)
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", port))
        sock.listen()
        assert port_open(port)


def test_wait_until_returns_the_value_or_names_what_timed_out() -> None:
    start = time.monotonic()
    assert wait_until(lambda: time.monotonic() - start > 0.05 and "done", 5, "time") == "done"
    with pytest.raises(WaitTimeout, match="waiting for the impossible") as err:
        wait_until(lambda: False, 0.1, "the impossible")
    assert isinstance(err.value, TimeoutError)


def test_child_waits_ready_on_a_regex_and_stops_with_sigterm(tmp_path: Path) -> None:
    args = _script(tmp_path, "import signal, sys, time\n"
                             "signal.signal(signal.SIGTERM, lambda *_: sys.exit(3))\n"
                             "print('noise'); print('ready on port 4321', flush=True)\n"
                             "while True: time.sleep(0.05)\n")
    with ChildProcess(args, tmp_path / "child.log", name="child") as child:
        match = child.wait_ready(r"ready on port (\d+)", timeout=20)
        assert match is not None and match.group(1) == "4321"
        assert child.running
    assert child.returncode == 3 and not child.killed
    assert "noise" in child.tail()


def test_child_waits_ready_on_a_listening_port(tmp_path: Path) -> None:
    port = free_port()
    args = _script(tmp_path, "import socket, time\n"
                             f"s = socket.socket(); s.bind(('127.0.0.1', {port})); s.listen()\n"
                             "time.sleep(60)\n")
    with ChildProcess(args, tmp_path / "listener.log") as child:
        child.wait_ready(port=port, timeout=20)
        assert port_open(port)


def test_a_child_that_ignores_sigterm_is_killed_after_the_grace(tmp_path: Path) -> None:
    args = _script(tmp_path, "import signal, time\n"
                             "signal.signal(signal.SIGTERM, signal.SIG_IGN)\n"
                             "print('up', flush=True)\n"
                             "time.sleep(60)\n")
    child = ChildProcess(args, tmp_path / "stubborn.log").start()
    child.wait_ready("up", timeout=20)
    started = time.monotonic()
    assert child.stop(grace=0.3) == -signal.SIGKILL
    assert child.killed and time.monotonic() - started < 10
    assert child.stop() == -signal.SIGKILL  # idempotent


def test_a_child_that_dies_before_ready_raises_with_its_status_and_log_tail(tmp_path: Path) -> None:
    args = _script(tmp_path, "import sys\nprint('bad config: no such file', file=sys.stderr)\nsys.exit(2)\n")
    child = ChildProcess(args, tmp_path / "dies.log", name="dier").start()
    with pytest.raises(ProcessError, match=r"dier did not print 'ready' \(exited with status 2\)") as err:
        child.wait_ready("ready", timeout=20)
    assert "bad config: no such file" in str(err.value)
    assert not child.running


def test_a_child_that_is_not_ready_in_time_is_stopped(tmp_path: Path) -> None:
    args = _script(tmp_path, "import time\ntime.sleep(60)\n")
    child = ChildProcess(args, tmp_path / "slow.log", name="slow").start()
    with pytest.raises(ProcessError, match="still running after 0.3 s"):
        child.wait_ready("never", timeout=0.3)
    assert not child.running


def test_restart_appends_to_the_log_and_reads_only_the_new_run(tmp_path: Path) -> None:
    args = _script(tmp_path, "import os\nprint('run', os.getpid(), flush=True)\n")
    child = ChildProcess(args, tmp_path / "runs.log")
    first = child.start().wait(20)
    first_out = child.output()
    child.start()
    assert child.wait(20) == 0 and first == 0
    assert child.output() != first_out and child.output().startswith("run ")
    assert (tmp_path / "runs.log").read_text().count("run ") == 2
    child.stop()


def test_stderr_can_go_to_its_own_file(tmp_path: Path) -> None:
    args = _script(tmp_path, "import sys\nprint('out'); print('err', file=sys.stderr)\n")
    child = ChildProcess(args, tmp_path / "out.log", stderr_path=tmp_path / "err.log").start()
    assert child.wait(20) == 0
    child.stop()
    assert child.output() == "out\n" and child.stderr_text() == "err\n"


def test_new_session_stops_the_helpers_of_the_child_too(tmp_path: Path) -> None:
    helper_pid = tmp_path / "helper.pid"
    args = ["/bin/bash", "-c", f"sleep 60 & echo $! > {helper_pid}; echo started; wait"]
    with ChildProcess(args, tmp_path / "group.log", new_session=True) as child:
        child.wait_ready("started", timeout=20)
        pid = int(wait_until(lambda: helper_pid.exists() and helper_pid.read_text().strip(), 10, "the helper's pid"))
    assert child.returncode is not None

    def gone() -> bool:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        return Path(f"/proc/{pid}/stat").read_text().split()[2] == "Z"

    assert wait_until(gone, 10, "the helper to end")


def test_a_missing_program_is_one_clear_error(tmp_path: Path) -> None:
    with pytest.raises(ProcessError, match="cannot start no-such-program"):
        ChildProcess(["no-such-program"], tmp_path / "x.log").start()
