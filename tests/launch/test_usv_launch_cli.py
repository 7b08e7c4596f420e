"""The user's entry points on the real USV launch file: goby-launch, and the demo until Ctrl-C."""

from __future__ import annotations

import csv
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import urllib.request
from pathlib import Path

import pytest

from gateway.goby.intervehicle.testing import random_multicast
from launch.process_group import LAUNCHED_LINE, child_environment
from launch.usv.mission import LAUNCH_FILE
from launch.usv.settings import UsvSettings
from util.process import ChildProcess, free_port, pid_alive, wait_until


def expect(run: ChildProcess, pattern: str, timeout: float = 90.0) -> re.Match[str]:
    """The first match of ``pattern`` in the run's output; fails with the output so far if it never comes."""
    match = run.wait_for_output(pattern, timeout)
    assert match is not None, f"never saw {pattern!r}; output so far:\n{run.output()}"
    return match


def finish(run: ChildProcess, timeout: float = 90.0) -> str:
    """Wait for the run to end by itself (stopped after ``timeout``); its output."""
    run.wait(timeout)
    run.stop()
    return run.output()


def start_demo(tmp_path: Path, out_dir: Path, *args: str) -> ChildProcess:
    """``python -m launch.usv.demo`` at warp 20 with our MOOSDB and helm, every port free, output in ``run.out``."""
    return ChildProcess(
        [sys.executable, "-m", "launch.usv.demo", "--out", str(out_dir), "--warp", "20", *args,
         "--moosdb", "ours", "--helm", "ours", "--moos-port", str(free_port()),
         "--sim-port", str(free_port()), "--liaison-port", str(free_port()),
         "--topside-liaison-port", str(free_port())],
        tmp_path / "run.out",
    ).start()


def test_goby_launch_runs_the_usv_launch_file_and_names_a_process_that_dies(tmp_path):
    socket_dir = Path(tempfile.mkdtemp(prefix="usvl-", dir="/tmp"))
    settings = UsvSettings(run_dir=tmp_path / "run", warp=10, moos_port=free_port(), sim_port=free_port(),
                           liaison_port=free_port(), moosdb="moos-db", helm="ivp-helm",
                           socket_name=str(socket_dir / "goby_usv"), sat_port=random_multicast()[1])
    env = child_environment() | settings.to_env()
    proc = ChildProcess(
        [sys.executable, "-m", "launch.apps.goby_launch", "-d", "200", "--status-period", "1", "-L", str(tmp_path / "logs"),
         str(LAUNCH_FILE)],
        tmp_path / "run.out", env=env,
    ).start()
    try:
        expect(proc, r"All processes running \(17\)")  # with goby-logger x2, moos-logger
        helm_pid = int(expect(proc, r"^Launched \((\d+)\) usv\.helm:").group(1))
        moosdb_log = tmp_path / "logs" / "usv.moosdb.log"
        # ten Python processes starting at once: the DB may still be importing
        wait_until(lambda: moosdb_log.exists() and "listening" in moosdb_log.read_text(), 60, "the MOOSDB listening")
        os.kill(helm_pid, signal.SIGKILL)
        text = finish(proc)
    finally:
        proc.stop()
        shutil.rmtree(socket_dir, ignore_errors=True)
    assert proc.returncode == 1, text
    assert "usv.helm died unexpectedly (exit status -9)" in text
    pids = [int(pid) for pid, _ in LAUNCHED_LINE.findall(text)]
    assert len(pids) == 17
    assert not any(pid_alive(pid) for pid in pids), text
    logs = sorted(p.name for p in (tmp_path / "logs").iterdir())
    assert "usv.frontseat-interface.log" in logs and "usv.shore.log" in logs
    assert "MOOSDB usv listening" in (tmp_path / "logs" / "usv.moosdb.log").read_text()


def test_demo_without_a_duration_runs_until_ctrl_c_and_still_writes_its_outputs(tmp_path):
    out_dir = tmp_path / "o"
    proc = start_demo(tmp_path, out_dir, "--forever")
    try:
        expect(proc, r"^t=\s*(1\d\d|[2-9]\d\d) s sim \| interface INTERFACE_COMMAND \| helm DRIVE")
        proc.send_signal(signal.SIGINT)
        text = finish(proc)
    finally:
        proc.stop()
    assert proc.returncode == 0, text
    assert "=== USV mission summary" in text
    assert "processes: 17/17 exited cleanly" in text
    assert "logs of this run" in text and "--format MCAP" in text, text
    assert re.search(r"^topside page \(goby-liaison, commands over the satellite link\): home http://127\.0\.0\.1:\d+/",
                     text, flags=re.M), text
    assert "1. t=" in text and "POLYGON_UPDATES=polygon=radial::x=0,y=0,radius=200,pts=6" in text
    rows = list(csv.DictReader(open(out_dir / "track.csv")))
    assert len(rows) > 50
    assert max(float(r["x"]) ** 2 + float(r["y"]) ** 2 for r in rows) > 100**2  # it moved out toward the ring
    assert (out_dir / "track.png").stat().st_size > 10_000
    assert (out_dir / "events.csv").exists()


def test_demo_names_a_component_that_dies_and_exits_non_zero(tmp_path):
    proc = start_demo(tmp_path, tmp_path / "o", "--duration", "0")
    try:
        sim_pid = int(expect(proc, r"^Launched \((\d+)\) usv\.frontseat-sim:").group(1))
        expect(proc, r"^t=\s*\d+/?\S* s sim \| interface INTERFACE_COMMAND")
        os.kill(sim_pid, signal.SIGKILL)
        text = finish(proc)
    finally:
        proc.stop()
    assert proc.returncode == 1, text
    assert "process 'usv.frontseat-sim' died (exit status -9)" in text
    assert "FAILED: process 'usv.frontseat-sim' died" in text  # the summary says so too
    assert "=== USV mission summary" in text
    assert (tmp_path / "o" / "track.png").exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--origin", "abc"], "argument --origin: 'abc' is not LAT,LON"),
        (["--origin", "95,10"], "argument --origin: '95,10' is not a latitude,longitude"),
        (["--schedule", "10:loiter"], "argument --schedule: bad schedule entry '10:loiter'"),
        (["--schedule", " "], "argument --schedule: empty schedule ' ': give"),
        (["--schedule", ""], "argument --schedule: empty schedule '': give"),
        (["--schedule", "0:polygon:6:200,800:polygon:12:400"], "argument --schedule: bad schedule entry '800:polygon:12:400': USVCommand.polygon_sides=12 is outside"),
        (["--warp", "0"], "argument --warp: must be >= 1"),
    ],
)
def test_demo_refuses_bad_arguments_before_starting_anything(tmp_path, args, message):
    out_dir = tmp_path / "o"
    proc = subprocess.run(
        [sys.executable, "-m", "launch.usv.demo", "--out", str(out_dir), "--moos-port", str(free_port()),
         "--sim-port", str(free_port()), *args],
        capture_output=True, text=True, timeout=60,
    )
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert "python -m launch.usv.demo: error: " + message in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and "Launched" not in proc.stdout, proc.stdout + proc.stderr
    assert not out_dir.exists()  # nothing ran: no run directory, no logs


def test_demo_with_no_schedule_prints_a_usv_command_line_that_reaches_this_run(tmp_path):
    out_dir = tmp_path / "o"
    proc = start_demo(tmp_path, out_dir, "--forever", "--schedule", "none")
    sent: subprocess.CompletedProcess[str] | None = None
    try:
        commander = expect(proc, r"Command it from the browser: (http://127\.0\.0\.1:\d+/\?_=/commander) \(over the "
                           r"satellite link\)")
        assert urllib.request.urlopen(commander.group(1), timeout=10).status == 200  # the page is served
        block = expect(proc, r"or, in another terminal \(bash\):\n"
                             r"  (export .*)\n  (.* waypoints .*)\n  (.* polygon .*)\n")
        export, waypoints = block.group(1), block.group(2)
        expect(proc, r"^t=\s*\d+ s sim \| interface INTERFACE_COMMAND \| helm DRIVE")
        # The user's other terminal: none of the run's USV_* variables, another directory, the printed lines only.
        user_env = {k: v for k, v in os.environ.items() if not k.startswith("USV_")}
        sent = subprocess.run(["bash", "-c", f"{export}\n{waypoints}"], cwd=tmp_path, env=user_env,
                              capture_output=True, text=True, timeout=90)
        expect(proc, r"^t=\s*\d+ s sim \| .*\| DEPLOY_STATE WAYPOINTS \|")
        proc.send_signal(signal.SIGINT)
        text = finish(proc)
    finally:
        proc.stop()
    assert sent is not None
    assert sent.returncode == 0, sent.stdout + sent.stderr
    assert "acked over the satellite link by satellite modem 2" in sent.stdout, sent.stdout + sent.stderr
    assert proc.returncode == 0, text
    assert "shore schedule: none (no commands: send them from the commander page or with usv-command)" in text
    # The only command MOOS saw is the user's, and its acknowledgement was recorded by the demo.
    assert re.search(r"^  1\. t=\d+ s: DEPLOY_STATE=WAYPOINTS$", text, flags=re.M), text
    assert "  2. t=" not in text and "acknowledgements: 1 posted to MOOS, 0 refused" in text, text
    assert re.search(r"^waypoints phase t=\d+\.\.\d+ s \(\d+ s, until the end of the run\)", text, flags=re.M), text
    assert "processes: 17/17 exited cleanly" in text
    assert "logs of this run" in text and "--format MCAP" in text, text
    assert re.search(r"^topside page \(goby-liaison, commands over the satellite link\): home http://127\.0\.0\.1:\d+/",
                     text, flags=re.M), text
    shore_log = (out_dir / "run" / "logs" / "usv.shore.log").read_text()
    assert "no commands planned" in shore_log and "sent " not in shore_log, shore_log
    headings = [float(h) for h in re.findall(r"hdg=\s*([-\d.]+)", text)]
    assert headings and all(0 <= h < 360 for h in headings), headings
