"""ProcessGroup.respawn: what a supervisor (the chaos soak) uses to restart a process that was killed."""

from __future__ import annotations

import signal
import time
from pathlib import Path

import pytest

from launch.errors import LaunchError
from launch.launchfile import parse_lines
from launch.process_group import ProcessGroup


def test_respawn_restarts_under_the_same_name_and_appends_the_log(tmp_path: Path) -> None:
    entries = parse_lines(["[name=sleeper] bash -c 'echo started $$; exec sleep 60'"]).entries
    with ProcessGroup(entries, tmp_path, report=lambda _: None, startup_check_s=0.2) as group:
        group.start()
        (first,) = group.processes
        with pytest.raises(LaunchError, match="still running"):
            group.respawn(first)
        first.popen.send_signal(signal.SIGKILL)
        first.popen.wait(10)
        second = group.respawn(first)
        assert group.processes == [second] and second.name == "sleeper" and second.running
        assert second.pid != first.pid
        time.sleep(0.3)
        assert second.running
    text = (tmp_path / "sleeper.log").read_text()
    assert text.count("started") == 2  # the first run's output is kept
