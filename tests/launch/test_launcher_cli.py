"""goby-launch as a user runs it: real child processes, real signals, real log files."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from launch.process_group import LAUNCHED_LINE
from util.process import ChildProcess, pid_alive, wait_until

# A child that records the signal it got in its log, so the test can see the shutdown order.
CHILD = textwrap.dedent(
    """
    import signal, sys, time
    name = sys.argv[1]
    def bye(signum, frame):
        print(f"{name} got {signal.Signals(signum).name} at {time.monotonic():.6f}", flush=True)
        sys.exit(0)
    signal.signal(signal.SIGTERM, bye)
    signal.signal(signal.SIGINT, bye)
    print(f"{name} up", flush=True)
    while True:
        time.sleep(0.05)
    """
)


def start_launcher(launch_file: Path, log_dir: Path, *extra: str) -> ChildProcess:
    """goby-launch as a child process, its output in ``goby-launch.out`` next to ``log_dir``."""
    return ChildProcess([sys.executable, "-m", "launch.apps.goby_launch", "-d", "50", "--status-period", "0.5",
                         "-L", str(log_dir), *extra, str(launch_file)], log_dir.parent / "goby-launch.out").start()


def finish(run: ChildProcess, timeout: float = 60.0) -> str:
    """Wait for the launcher to end by itself (SIGKILL after ``timeout``); its output."""
    if run.wait(timeout) is None:
        run.kill()
    run.stop()
    return run.output()


def _launched_pids(output: str) -> list[int]:
    return [int(pid) for pid, _ in LAUNCHED_LINE.findall(output)]


@pytest.fixture
def child_script(tmp_path: Path) -> Path:
    path = tmp_path / "child.py"
    path.write_text(CHILD)
    return path


def test_starts_in_order_and_stops_in_reverse_on_sigint(tmp_path, child_script):
    launch_file = tmp_path / "three.launch"
    launch_file.write_text(
        f"# three children\n"
        f"[name=first] {sys.executable} {child_script} first\n"
        f"[name=second, env=GREETING=hello] bash -c 'echo $GREETING; cat <(echo substituted); "
        f"exec {sys.executable} {child_script} second'\n"
        f"[name=third, kill=SIGINT] {sys.executable} {child_script} third\n"
    )
    logs = tmp_path / "logs"
    run = start_launcher(launch_file, logs)
    try:
        run.wait_ready(re.escape("All processes running (3): first, second, third"), timeout=60)
        wait_until(lambda: all("up" in (logs / f"{n}.log").read_text() for n in ("first", "second", "third")), 60,
                  "all three children up")
        run.send_signal(signal.SIGINT)
    finally:
        output = finish(run)
    assert run.returncode == 0, output
    second_log = (logs / "second.log").read_text()
    assert "hello" in second_log and "substituted" in second_log
    stamps = {}
    for name, sig in (("first", "SIGTERM"), ("second", "SIGTERM"), ("third", "SIGINT")):
        match = re.search(rf"{name} got {sig} at ([0-9.]+)", (logs / f"{name}.log").read_text())
        assert match, f"{name} did not get {sig}"
        stamps[name] = float(match.group(1))
    assert stamps["third"] < stamps["second"] < stamps["first"], stamps
    assert all(not pid_alive(pid) for pid in _launched_pids(output))


def test_a_dying_process_is_named_with_its_log_tail_and_the_rest_are_stopped(tmp_path, child_script):
    launch_file = tmp_path / "dies.launch"
    launch_file.write_text(
        f"[name=survivor] {sys.executable} {child_script} survivor\n"
        f"[name=doomed] bash -c 'sleep 2; echo boom: cannot reach the MOOSDB >&2; exit 3'\n"
    )
    logs = tmp_path / "logs"
    run = start_launcher(launch_file, logs)
    output = finish(run)
    assert run.returncode == 1, output
    assert "doomed died unexpectedly (exit status 3)" in output
    assert "boom: cannot reach the MOOSDB" in output
    assert "survivor got SIGTERM" in (logs / "survivor.log").read_text()
    assert all(not pid_alive(pid) for pid in _launched_pids(output))


def test_death_during_startup_fails_the_launch(tmp_path, child_script):
    launch_file = tmp_path / "bad.launch"
    launch_file.write_text(
        f"[name=ok] {sys.executable} {child_script} ok\n"
        "[name=missing] no-such-program-xyz --flag\n"
    )
    run = start_launcher(launch_file, tmp_path / "logs")
    output = finish(run)
    assert run.returncode == 1
    assert "failed to launch" in output and "'missing'" in output
    assert "no-such-program-xyz" in output  # bash's "not found" from the log tail
    assert all(not pid_alive(pid) for pid in _launched_pids(output))


def test_sigkill_after_the_kill_timeout(tmp_path):
    launch_file = tmp_path / "stubborn.launch"
    launch_file.write_text("[name=stubborn] bash -c 'trap \"echo ignoring TERM\" TERM; while true; do sleep 0.1; done'\n")
    logs = tmp_path / "logs"
    run = start_launcher(launch_file, logs, "-k", "1")
    try:
        run.wait_ready(re.escape("All processes running"), timeout=60)
        started = time.monotonic()
        run.send_signal(signal.SIGTERM)
    finally:
        output = finish(run)
    assert "did not respond to SIGTERM after 1 s, sending SIGKILL" in output
    assert time.monotonic() - started >= 1.0
    assert "ignoring TERM" in (logs / "stubborn.log").read_text()


@pytest.mark.parametrize(
    ("content", "flag", "message"),
    [
        ("[kill=SIGUSR1] sleep 5\n", None, "invalid kill=SIGUSR1"),
        ("# nothing\n", None, "no commands to launch"),
        ("sleep 5\n", "-s", "-s (GNU screen) is not supported"),
    ],
)
def test_bad_launch_files_and_options_exit_non_zero_with_the_cause(tmp_path, content, flag, message):
    launch_file = tmp_path / "x.launch"
    launch_file.write_text(content)
    args = [sys.executable, "-m", "launch.apps.goby_launch", *([flag] if flag else []), str(launch_file)]
    result = subprocess.run(args, capture_output=True, text=True, timeout=60)
    assert result.returncode != 0
    assert message in result.stderr


def test_a_process_that_finishes_with_status_zero_is_not_a_failure(tmp_path):
    launch_file = tmp_path / "oneshot.launch"
    launch_file.write_text("[name=oneshot] bash -c 'sleep 1.5; echo done'\n")
    run = start_launcher(launch_file, tmp_path / "logs")
    output = finish(run)
    assert run.returncode == 0, output
    assert "oneshot finished" in output
    assert "All processes exited" in output


def test_preseed_next_to_the_launch_file_is_sourced_for_every_command(tmp_path):
    (tmp_path / "preseed.goby").write_text("export FROM_PRESEED=seeded\n")
    launch_file = tmp_path / "seeded.launch"
    launch_file.write_text("[name=one] bash -c 'echo one=$FROM_PRESEED'\n[name=two] bash -c 'echo two=$FROM_PRESEED'\n")
    logs = tmp_path / "logs"
    run = start_launcher(launch_file, logs)
    output = finish(run)
    assert run.returncode == 0, output
    assert "Sourcing" in output
    assert "one=seeded" in (logs / "one.log").read_text()
    assert "two=seeded" in (logs / "two.log").read_text()


def test_respawn_starts_an_ended_process_again_and_appends_to_its_log(tmp_path):
    from launch.launchfile import parse_lines
    from launch.process_group import ProcessGroup

    entry = parse_lines(["[name=once] bash -c 'sleep 0.3; echo run $$; exit 3'"], source="t").entries[0]
    with ProcessGroup([entry], tmp_path / "logs", launch_delay_s=0, startup_check_s=0, report=lambda _l: None) as group:
        group.start()
        (first,) = group.processes
        wait_until(lambda: not first.running, 20, "the first run to end")
        pid = first.pid
        again = group.respawn(first)
        assert again is group.processes[0] and again.pid != pid
        wait_until(lambda: not again.running, 20, "the second run to end")
        assert again.returncode == 3
    assert (tmp_path / "logs" / "once.log").read_text().count("run ") == 2


def test_respawn_flag_restarts_a_killed_process_up_to_its_limit(tmp_path, child_script):
    launch_file = tmp_path / "two.launch"
    launch_file.write_text(f"[name=steady] {sys.executable} {child_script} steady\n"
                           f"[name=victim] {sys.executable} {child_script} victim\n")
    logs = tmp_path / "logs"
    run = start_launcher(launch_file, logs, "--respawn", "1")
    try:
        wait_until(lambda: "Use <CTRL+C>" in run.output(), 30, "start-up done")  # a death before is a failure
        steady, victim = _launched_pids(run.output())
        os.kill(victim, signal.SIGKILL)
        wait_until(lambda: len(_launched_pids(run.output())) == 3, 30, "the victim launched again")
        again = _launched_pids(run.output())[2]
        wait_until(lambda: _read(logs / "victim.log").count("victim up") == 2, 30, "the second victim up")
        assert "respawning it (1 of 1)" in run.output()
        assert pid_alive(steady) and run.running
        os.kill(again, signal.SIGKILL)  # the second death is past the limit: everything stops, exit 1
        output = finish(run)
    finally:
        run.stop()
    assert run.returncode == 1, output
    assert "victim died unexpectedly (exit status -9); stopping the others" in output
    assert not pid_alive(steady)


def test_respawn_comes_from_the_environment_for_nested_launchers(tmp_path, child_script):
    launch_file = tmp_path / "one.launch"
    launch_file.write_text(f"[name=victim] {sys.executable} {child_script} victim\n")
    logs = tmp_path / "logs"
    run = ChildProcess([sys.executable, "-m", "launch.apps.goby_launch", "-d", "50", "-L", str(logs), str(launch_file)],
                       tmp_path / "goby-launch.out", env=os.environ | {"GOBY_LAUNCH_RESPAWN": "2"}).start()
    try:
        wait_until(lambda: "Use <CTRL+C>" in run.output(), 30, "start-up done")
        os.kill(_launched_pids(run.output())[0], signal.SIGKILL)
        wait_until(lambda: "respawning it (1 of 2)" in run.output(), 30, "the respawn")
    finally:
        run.send_signal(signal.SIGINT)
        output = finish(run)
    assert run.returncode == 0, output


def test_respawn_refuses_a_bad_count(tmp_path):
    launch_file = tmp_path / "one.launch"
    launch_file.write_text("sleep 1\n")
    result = subprocess.run([sys.executable, "-m", "launch.apps.goby_launch", "--respawn", "-1", str(launch_file)],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2 and "--respawn" in result.stderr
    result = subprocess.run([sys.executable, "-m", "launch.apps.goby_launch", str(launch_file)], capture_output=True,
                            text=True, timeout=60, env=os.environ | {"GOBY_LAUNCH_RESPAWN": "-1"})
    assert result.returncode == 2 and "GOBY_LAUNCH_RESPAWN: '-1' is not a finite number" in result.stderr


def _read(path: Path) -> str:
    return path.read_text() if path.exists() else ""
