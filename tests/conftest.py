"""Suite-wide fixtures: every test must stop the threads and child processes it started."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

LEAK_GRACE_S = 5.0

# Property tests check results, not speed: on a loaded 2-core CI machine an example may take longer than
# hypothesis's 200 ms default deadline, and that must not fail a correct test (speed is measured in bench/).
settings.register_profile("suite", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("suite")


def _child_pids() -> set[int]:
    """Live (non-zombie) direct children of this process, read from /proc."""
    me = os.getpid()
    children: set[int] = set()
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        state, ppid = fields[0], int(fields[1])
        if ppid == me and state != "Z":
            children.add(int(stat.parent.name))
    return children


@pytest.fixture(autouse=True)
def no_leaked_threads_or_processes(request: pytest.FixtureRequest):
    """Fail a test that leaves a thread or a child process running (like python-can's channel check)."""
    threads_before = set(threading.enumerate())
    children_before = _child_pids()
    yield
    deadline = time.monotonic() + LEAK_GRACE_S
    while True:
        threads = [t for t in threading.enumerate() if t not in threads_before and t.is_alive()]
        children = _child_pids() - children_before
        if not threads and not children:
            return
        if time.monotonic() > deadline:
            break
        time.sleep(0.05)
    problems = []
    if threads:
        problems.append("threads still running: " + ", ".join(t.name for t in threads))
    if children:
        problems.append("child processes still running: " + ", ".join(map(str, sorted(children))))
    pytest.fail(f"{request.node.nodeid} leaked " + "; ".join(problems), pytrace=False)
