"""The trail mission's health, moos-share and AIS wiring (issues 27 and 28), with every process real.

One run of ``all.launch`` (topside, USV, 1 AUV at warp 10; goby-launch respawns a process that dies once) serves
three checks, in this order:

* the topside's goby-opencpn-interface serves ``!AIVDM`` sentences for every vehicle on its AIS port (decoded by
  pyais, an independent decoder): each vehicle's name (type 24) and a position near the origin (type 18);
* the USV's MOOSDB holds a ``NODE_REPORT`` for every AUV, which each AUV's moos-share sent from its
  ``NODE_REPORT_LOCAL`` (read with our MOOS client);
* a usv-manager that stops answering turns what the topside receives over the satellite link to FAILED within two
  coroner request intervals plus one satellite slot cycle (30 s sim); killed, goby-launch respawns it and GOOD comes
  back. It is frozen (SIGSTOP) before it is killed: goby-launch respawns a killed process at once and a new
  usv-manager answers within half a real second, less than one request interval at warp 10, so a plain SIGKILL
  may never be seen by goby-coroner. To the coroner a frozen process is a dead one (no answer: ERROR__PROCESS_DIED).
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import socket
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pyais
import pytest

from gateway.goby.portal.testing import PortalClient
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.moos.testing import collect_mail, connected_comms
from launch.process_group import child_environment
from launch.trail.health_timeline import health_events, health_timeline_lines
from launch.trail.mission import TrailMission, with_free_ports
from launch.trail.settings import KAUAI_ORIGIN, TrailSettings, Vehicle
from translators.trail import groups
from translators.trail.protobuf.health_status_pb2 import HealthStatus

N_AUVS = 1
WARP = 10
REQUEST_INTERVAL_S = 10.0  # goby-coroner's default, simulated seconds (launch/usv/templates/goby_coroner.pb.cfg.in)
SLOT_CYCLE_S = 10.0  # the satellite link's two 5 s slots
NEEDED = ("goby-coroner", "usv-health-monitor", "goby-opencpn-interface", "moos-share", "usv-manager")

pytestmark = pytest.mark.skipif(any(shutil.which(p, path=child_environment()["PATH"]) is None for p in NEEDED),
                                reason=f"not installed: one of {', '.join(NEEDED)}")


class Run:
    """The running mission and a portal client on the topside's broker collecting the USV's health."""

    def __init__(self, mission: TrailMission, topside: PortalClient) -> None:
        self.mission = mission
        self.settings = mission.settings
        self.topside = topside
        self.good: list[tuple[float, HealthStatus]] = []
        self.failed: list[tuple[float, HealthStatus]] = []
        topside.subscribe(groups.health_status_good, HealthStatus, lambda s: self.good.append((mission.now(), s)))
        topside.subscribe(groups.health_status_failed, HealthStatus,
                          lambda s: self.failed.append((mission.now(), s)))

    def wait(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        """Poll the portal (and the launchers) until ``predicate()`` holds or ``timeout_s`` real seconds pass."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.topside.poll_until(predicate, 0.2):
                return True
            self.mission.poll()
        return False


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Run]:
    tmp = tmp_path_factory.mktemp("trail_health")
    settings = with_free_ports(TrailSettings(run_dir=tmp, warp=WARP, socket_dir=tmp), N_AUVS, prefer_course=False)
    mission = TrailMission(settings, N_AUVS, report=lambda line: None, launch_delay_s=0.5,
                           extra_env={"GOBY_LAUNCH_RESPAWN": "1"}, moos_variables=("NAV_X", "NAV_Y"))
    try:
        mission.start()
        cfg = InterProcessPortalConfig(platform="topside", socket_name=Vehicle("topside", N_AUVS).ipc_base(settings),
                                       manager_timeout_seconds=30)
        with PortalClient(cfg, name="health_watch") as topside:
            state = Run(mission, topside)
            assert topside.wait_subscribed()
            assert mission.wait_for_command(timeout_s=180) is not None
            yield state
    finally:
        mission.stop()


def read_ais(port: int, seconds: float) -> list[dict[str, Any]]:
    """Connect to the AIS server, read ``seconds`` of sentences, decode each with pyais."""
    lines: list[str] = []
    buffer = b""
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.settimeout(0.5)
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            try:
                chunk = sock.recv(65536)
            except TimeoutError:
                continue
            if not chunk:
                break
            buffer += chunk
            *complete, buffer = buffer.split(b"\r\n")
            lines.extend(line.decode("ascii") for line in complete if line)
    assert lines and all(line.startswith("!AIVDM,") for line in lines), lines[:5]
    return [pyais.decode(line).asdict() for line in lines]


def test_ais_clients_get_every_vehicle(run: Run) -> None:
    # static reports every 30 s sim (3 s real): read long enough for one round after the first
    decoded = read_ais(run.settings.ais_port, 2 * 30 / WARP + 1)
    names = {m["mmsi"]: m["shipname"] for m in decoded if m["msg_type"] == 24 and m["partno"] == 0}
    assert sorted(names.values()) == ["AUV_0", "USV"], names
    assert all(988700000 <= mmsi < 988700000 + 10 for mmsi in names), names  # from mmsi_start
    for mmsi, name in names.items():
        positions = [m for m in decoded if m["msg_type"] == 18 and m["mmsi"] == mmsi]
        assert positions, f"no position report for {name}"
        lat, lon = positions[-1]["lat"], positions[-1]["lon"]
        assert abs(lat - KAUAI_ORIGIN[0]) < 0.05 and abs(lon - KAUAI_ORIGIN[1]) < 0.05, (name, lat, lon)


def test_usv_moosdb_has_every_auvs_node_report(run: Run) -> None:
    usv = Vehicle("usv", N_AUVS)
    with connected_comms(usv.moos_port(run.settings), "uNodeReportWatch", ["NODE_REPORT"]) as client:
        mail = collect_mail(client, ["NODE_REPORT"], until=lambda got: len(_shared(got)) >= N_AUVS, timeout=30)
    # the USV's gateway posts NODE_REPORTs too (the vehicles' nav); moos-share keeps the source of what it shares:
    # the AUV's node-reporter
    assert _shared(mail) == {f"auv{i}" for i in range(N_AUVS)}, [m.string() for m in mail][:5]


def _shared(mail: list[Any]) -> set[str]:
    return {_name(m.string()) for m in mail if m.source() == "pNodeReporter"}


def _name(report: str) -> str:
    match = re.search(r"NAME=([^,]+)", report)
    return match[1].lower() if match else ""


def _pid_of(program: str, ancestor: int) -> int:
    """The pid of the descendant of ``ancestor`` (this run's USV launcher) whose command line runs ``program``."""
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            children.setdefault(int(stat.rsplit(")", 1)[1].split()[1]), []).append(int(entry.name))
    todo, found = [ancestor], []
    while todo:
        pid = todo.pop()
        try:
            argv = (Path("/proc") / str(pid) / "cmdline").read_bytes().split(b"\0")
        except OSError:
            argv = []
        if any(os.path.basename(a.decode(errors="replace")) == program for a in argv[:2]):
            found.append(pid)
        todo.extend(children.get(pid, []))
    assert len(found) == 1, f"{program} under {ancestor}: {found}"
    return found[0]


def test_dead_usv_manager_turns_topside_view_failed_then_good_after_respawn(run: Run) -> None:
    assert run.wait(lambda: bool(run.good), 60), "the topside never received GOOD"
    assert run.good[-1][1].state == HealthStatus.GOOD
    assert run.mission.group is not None
    launcher = next(p for p in run.mission.group.processes if p.name == "usv")
    victim = _pid_of("usv-manager", launcher.pid)
    killed_at = run.mission.now()
    run.failed.clear()
    os.kill(victim, signal.SIGSTOP)  # silent from now on, as a dead process (see the module's text)

    bound = 2 * REQUEST_INTERVAL_S + SLOT_CYCLE_S
    assert run.wait(lambda: bool(run.failed), 10 * bound / WARP), "no FAILED reached the topside"
    failed_at, status = run.failed[0]
    assert status.state == HealthStatus.FAILED
    assert failed_at - killed_at <= bound, f"FAILED {failed_at - killed_at:.0f} s sim after the kill (bound {bound})"

    # killed, goby-launch respawns usv-manager; the next complete answer is GOOD again
    run.good.clear()
    os.kill(victim, signal.SIGKILL)
    assert run.wait(lambda: bool(run.good), 60), "GOOD never came back after the respawn"
    assert _pid_of("usv-manager", launcher.pid) != victim
    print(f"silent -> FAILED at the topside after {failed_at - killed_at:.0f} s sim (bound {bound:.0f} s); "
          f"killed and respawned -> GOOD {run.good[0][0] - killed_at:.0f} s sim after it fell silent")


def test_summary_health_timeline_from_the_logs(run: Run) -> None:
    """The demo's summary section, read from the topside's and the USV's goby-logger logs after the run."""
    result = run.mission.stop()
    events = health_events(result.logs, WARP)
    states = [e.state for e in events]
    assert "GOOD" in states and "FAILED" in states, states
    # the FAILED of the kill names usv-manager and why (the USV's coroner report of the same second), GOOD follows
    killed = [i for i, e in enumerate(events) if e.state == "FAILED" and e.reason == "usv-manager: Process usv-manager "
              "has died"]
    assert killed and "GOOD" in states[killed[-1]:], [(e.state, e.reason) for e in events]
    lines = health_timeline_lines(result.logs, WARP, result.t0)
    assert lines[0].startswith(f"health the topside received over the satellite link ({len(events)} reports")
    assert any(" FAILED" in line and line.endswith(": usv-manager: Process usv-manager has died") for line in lines), lines
