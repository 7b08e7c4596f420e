"""``ivp-helm`` as a process when something inside it fails: it serves on, or exits non-zero, never idles.

The failures are injected by ``faulty_helm.py`` (a thin wrapper around ``ivp-helm``'s ``main``).
"""

from __future__ import annotations

import contextlib
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

from gateway.moos import MoosClock
from gateway.moos.testing import running_moosdb
from util.process import ChildProcess

from .moos_harness import WARP, Observer, bhv_block, helm_process, observer, write_mission

FAULTY_HELM = Path(__file__).with_name("faulty_helm.py")
WATCH = ["IVPHELM_STATE", "BHV_ERROR", "FAULT_AFTER", "DESIRED_SPEED"]
CRUISE = bhv_block("ConstantSpeed", name="cruise", speed=1.5) + bhv_block("ConstantHeading", name="steer", heading=90)


def _mission(tmp_path: Path, port: int) -> Path:
    bhv = tmp_path / "cruise.bhv"
    bhv.write_text(CRUISE)
    return write_mission(tmp_path, port, bhv)


@contextlib.contextmanager
def _faulty_helm(tmp_path: Path, fault: str, var: str, trigger: bool = True) -> Iterator[tuple[Observer, ChildProcess]]:
    """A MOOSDB, an observer and ``faulty_helm.py`` injecting ``fault`` on ``var``; with ``trigger``, once the helm
    has reached PARK the observer posts ``var=1``."""
    clock = MoosClock(WARP)
    with running_moosdb("alpha", warp=WARP) as db, observer(db.port, clock, WATCH) as obs:
        mission = _mission(tmp_path, db.port)
        with helm_process(mission, tmp_path, [sys.executable, str(FAULTY_HELM), fault, var, str(mission), "-v"]) as proc:
            if trigger:
                assert obs.wait(lambda: obs.last("IVPHELM_STATE") == "PARK"), (tmp_path / "helm.log").read_text()
                obs.post(var, "1")
            yield obs, proc


def _nav(obs) -> None:
    for var, value in (("NAV_X", 0.0), ("NAV_Y", 0.0), ("NAV_HEADING", 0.0), ("NAV_SPEED", 0.0)):
        obs.post(var, value)


def test_a_failure_handling_one_message_is_logged_and_the_helm_serves_on(tmp_path: Path) -> None:
    with _faulty_helm(tmp_path, "mail", "BOOM") as (obs, proc):
        assert obs.wait(lambda: "BOOM" in str(obs.last("BHV_ERROR")))
        _nav(obs)
        obs.post("MOOS_MANUAL_OVERRIDE", "false")  # mail after the failure is still handled...
        assert obs.wait(lambda: obs.last("IVPHELM_STATE") == "DRIVE"), (tmp_path / "helm.log").read_text()
        assert obs.wait(lambda: obs.last("DESIRED_SPEED") == 1.5), obs.mail[-20:]  # ...and it still decides
        assert proc.poll() is None
    log = (tmp_path / "helm.log").read_text()
    assert "handling mail BOOM='1' from test_observer failed" in log
    assert "InjectedFault: injected fault: mail BOOM" in log and "ValueError: root cause of mail BOOM" in log


def test_one_unpostable_value_is_logged_and_the_postings_after_it_still_go_out(tmp_path: Path) -> None:
    with _faulty_helm(tmp_path, "post", "BAD_POST") as (obs, proc):
        assert obs.wait(lambda: obs.last("FAULT_AFTER") == "BAD_POST"), (tmp_path / "helm.log").read_text()
        assert obs.wait(lambda: "BAD_POST" in str(obs.last("BHV_ERROR")))
        states = len(obs.values("IVPHELM_STATE"))
        assert obs.wait(lambda: len(obs.values("IVPHELM_STATE")) > states + 3)  # still iterating
        assert proc.poll() is None
    assert "posting BAD_POST=None failed" in (tmp_path / "helm.log").read_text()


def test_a_failed_start_up_stops_the_helm_and_ivp_helm_exits_non_zero(tmp_path: Path) -> None:
    with _faulty_helm(tmp_path, "startup", "-", trigger=False) as (obs, proc):
        try:
            code = proc.wait(30)
        except subprocess.TimeoutExpired:
            code = None
        assert code == 1, (tmp_path / "helm.log").read_text()
        assert obs.wait(lambda: "stopped" in str(obs.last("BHV_ERROR")), timeout=5)
        assert obs.values("IVPHELM_STATE") == []
    log = (tmp_path / "helm.log").read_text()
    assert "the helm has stopped: start-up failed" in log and "no helm is running" in log
    assert "ValueError: root cause of startup" in log
