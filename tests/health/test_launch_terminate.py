"""goby-launch stops Goby applications with goby-terminate when its launch file has one broker line (as goby_launch),
and falls back to SIGTERM for a process that does not answer."""

from __future__ import annotations

import re
import shutil
import sys
from pathlib import Path

from gateway.goby.portal.testing import app_process
from launch.process_group import LAUNCHED_LINE
from tests.goby3_real import short_ipc_dir


def test_goby_launch_stops_apps_with_goby_terminate(tmp_path: Path) -> None:
    ipc_dir = short_ipc_dir()
    ipc = ipc_dir / "goby_launched"
    interprocess = f'platform: "launched" socket_name: "{ipc}"'
    app = f"{sys.executable} -m tests.health.apps.health_app --interprocess '{interprocess}'"
    launch_file = tmp_path / "health.launch"
    launch_file.write_text(
        f"goby-broker --interprocess '{interprocess}'\n"
        f"{app} --role=single --app 'name: \"one\"'\n"
        f"{app} --role=threads --app 'name: \"two\"'\n"
        f"{sys.executable} -c 'import time; time.sleep(600)'\n"  # not a Goby app: never answers goby_terminate
    )
    logs = tmp_path / "logs"
    launcher = app_process([sys.executable, "-m", "launch.apps.goby_launch", "-m", "3", "-k", "5", "-L", str(logs),
                            str(launch_file)], tmp_path / "launcher.log")
    try:
        launcher.wait_ready("All processes running", timeout=60)
        pids = {name: int(pid) for pid, name in LAUNCHED_LINE.findall(launcher.output())}
        launcher.send_signal(2)
        assert launcher.wait(90) == 0, launcher.tail(40)
        out = launcher.output()
        for name in ("health.python", "health.python.2"):  # the two apps: goby-terminate, they quit
            assert f"goby_terminate: {pids[name]} (was {name}) .... success" in out
        sleeper = "health.python.3"
        assert f"goby_terminate: {pids[sleeper]} (was {sleeper})" in out
        assert f"Process {pids[sleeper]} did not respond to goby_terminate, sending SIGTERM" in out
        broker = "health.goby-broker"
        assert re.search(rf"^SIGTERM: {pids[broker]} \(was {broker}\)", out, re.M)  # the broker: a signal
        last_run = (logs / "goby-terminate.log").read_text().splitlines()  # the last goby-terminate: for "one"
        assert last_run[-1] == f'target_name: "one" target_pid: {pids["health.python"]} result: PROCESS_CLEANLY_QUIT'
    finally:
        launcher.stop()
        shutil.rmtree(ipc_dir, ignore_errors=True)
