"""The real path on loopback: frontseat-sim <-> driver <-> frontseat-interface <-> goby-broker <-> a scripted helm.

Every part is a real process except the helm, which is this test publishing on the portal (the role the
course's goby3_course_helm plays). Simulated time runs at warp 10, so 10 s timeouts take 1 s.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import pytest

from frontseat import groups
from frontseat.protobuf import frontseat_data_pb2 as data_pb
from frontseat.protobuf import frontseat_pb2 as fs
from frontseat.testing import SimulatorProcess, basic_simulator_frontseat_cfg, start_simulator
from gateway.goby.portal.testing import PortalClient, app_process, broker_process
from util.process import ChildProcess, free_port

WARP = 10
HELM_TIMEOUT = 60.0  # simulated seconds: 6 s real at warp 10 (counted from start: room for a slow start)
ORIGIN = (41.592344, -70.711260)


def write_config(path: Path, port: int, **frontseat: object) -> Path:
    path.write_text(
        "app {\n"
        f"  geodesy {{ lat_origin: {ORIGIN[0]} lon_origin: {ORIGIN[1]} }}\n"
        f"  simulation {{ time {{ use_sim_time: true warp_factor: {WARP} }} }}\n"
        "}\n"
        + basic_simulator_frontseat_cfg(port, **frontseat)  # type: ignore[arg-type]
    )
    return path


def start_interface(tmp_path: Path, broker, cfg: Path, name: str = "iface", driver: str = "basic_simulator",
                    flags: tuple[str, ...] = ("-vv",)) -> ChildProcess:
    env = broker.env()
    env["FRONTSEAT_DRIVER_LIBRARY"] = driver
    return app_process(
        [sys.executable, "-m", "frontseat.apps.frontseat_interface", str(cfg), *flags],
        env=env,
        log_path=tmp_path / f"{name}.log",
    )


def exit_code(iface: ChildProcess, timeout: float = 60) -> int:
    """The exit status of an interface expected to quit by itself; it is stopped whatever happens."""
    try:
        return iface.wait(timeout)
    finally:
        iface.stop()


class ScriptedHelm:
    """The test's helm: a portal client that records what the interface publishes and can drive it."""

    def __init__(self, client: PortalClient) -> None:
        self.client = client
        self.status = client.collect(groups.status, fs.InterfaceStatus)
        self.raw_out = client.collect(groups.raw_out, fs.Raw)
        self.raw_in = client.collect(groups.raw_in, fs.Raw)
        self.node_status = client.collect(groups.node_status, data_pb.NodeStatus)
        self.data = client.collect(groups.data_from_frontseat, fs.InterfaceData)
        self.responses = client.collect(groups.command_response, fs.CommandResponse)
        self.driving = False
        self.send_course = True
        self.course = (90.0, 2.0, 0.0)
        self._last_drive = 0.0

    def state(self) -> int | None:
        return self.status[-1].state if self.status else None

    def out_lines(self) -> list[str]:
        return [raw.raw.decode() for raw in self.raw_out]

    def pump(self) -> None:
        """Poll once; while driving, publish DRIVE and the desired course every 0.1 s real (1 s simulated)."""
        now = time.monotonic()
        if self.driving and now - self._last_drive > 0.1:
            self._last_drive = now
            self.client.publish(groups.helm_state, fs.HelmStateReport(state=fs.HELM_DRIVE))
            heading, speed, depth = self.course
            if self.send_course:
                self.client.publish(
                    groups.desired_course,
                    data_pb.DesiredCourse(time=time.time(), heading=heading, speed=speed, depth=depth),
                )
        self.client.poll(0.02)

    def until(self, predicate, timeout: float = 30.0, what: str = "") -> None:
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline:
                states = [fs.InterfaceState.Name(s.state) for s in self.status[-5:]]
                raise AssertionError(f"timed out waiting for {what}; last status states {states}")
            self.pump()

    def until_state(self, state: int, timeout: float = 30.0) -> fs.InterfaceStatus:
        start = len(self.status)
        self.until(lambda: any(s.state == state for s in self.status[start:]), timeout, fs.InterfaceState.Name(state))
        return next(s for s in self.status[start:] if s.state == state)


def test_standby_listen_command_helm_error_fs_error_and_recovery(tmp_path: Path) -> None:
    port = free_port()
    sims: list[SimulatorProcess] = []
    with broker_process(tmp_path, platform="usv") as broker:
        cfg = write_config(
            tmp_path / "frontseat.pb.cfg",
            port,
            status_period=1,
            helm_running_timeout=HELM_TIMEOUT,
            frontseat_connected_timeout=100,
            reconnect_interval=0.2,
        )
        iface = start_interface(tmp_path, broker, cfg)
        try:
            with PortalClient(broker.interprocess_config(), name="scripted_helm") as client:
                helm = ScriptedHelm(client)
                assert client.wait_subscribed()
                # no simulator yet: STANDBY, waiting for the frontseat (within frontseat_connected_timeout)
                standby = helm.until_state(fs.INTERFACE_STANDBY)
                assert standby.frontseat_state == fs.FRONTSEAT_NOT_CONNECTED
                assert not standby.HasField("frontseat_error") and not standby.HasField("helm_error")
                assert helm.out_lines() == []

                # the simulator comes up: START, CTRL,STATE:PAYLOAD and NAV take the interface to LISTEN
                sims.append(start_simulator(port))
                listen = helm.until_state(fs.INTERFACE_LISTEN)
                assert listen.frontseat_state == fs.FRONTSEAT_ACCEPTING_COMMANDS
                assert listen.helm_state == fs.HELM_NOT_RUNNING
                assert helm.out_lines()[0].startswith("START,LAT:41.5923,LON:-70.7113")
                assert helm.out_lines()[0].endswith(f"WARP:{WARP}")

                # gating in LISTEN: a desired course is not forwarded, a raw send request is
                client.publish(groups.desired_course, data_pb.DesiredCourse(time=time.time(), heading=45, speed=1))
                client.publish(groups.raw_send_request, fs.Raw(raw=b"CMD,HEADING:10,SPEED:0,DEPTH:0"))
                helm.until(lambda: "CMD,HEADING:10,SPEED:0,DEPTH:0" in helm.out_lines(), what="raw send")
                assert not any(line.startswith("CMD,HEADING:45") for line in helm.out_lines())

                # the helm drives: LISTEN -> COMMAND, and desired courses become CMD lines
                helm.driving = True
                command = helm.until_state(fs.INTERFACE_COMMAND)
                assert (command.helm_state, command.frontseat_state) == (fs.HELM_DRIVE, fs.FRONTSEAT_ACCEPTING_COMMANDS)
                assert not command.HasField("helm_error") and not command.HasField("frontseat_error")
                helm.until(lambda: "CMD,HEADING:90,SPEED:2,DEPTH:0" in helm.out_lines(), what="CMD on raw_out")
                helm.until(lambda: "CMD,RESULT:OK" in [r.raw.decode() for r in helm.raw_in], what="CMD,RESULT:OK")

                # NAV arrives as node_status (and data_from_frontseat) and shows the vehicle obeying
                helm.until(lambda: helm.node_status and helm.node_status[-1].pose.heading > 45, what="turning NAV")
                nav = helm.node_status[-1]
                assert (nav.name, nav.type) == ("usv", data_pb.USV)
                # heading east: x grows (the START datum is the origin at %g precision, so x0 is not 0)
                assert nav.local_fix.x > helm.node_status[0].local_fix.x
                assert helm.data and helm.data[-1].HasField("node_status")

                # a command request asking for a response gets one. The driver matches a CMD reply to the last
                # command sent (as Goby's does), so the helm's desired courses pause meanwhile.
                helm.send_course = False
                request = fs.CommandRequest(response_requested=True, request_id=42)
                request.desired_course.time, request.desired_course.heading = time.time(), 90
                request.desired_course.speed = 2
                client.publish(groups.command_request, request)
                helm.until(lambda: any(r.request_id == 42 for r in helm.responses), what="command response")
                assert next(r for r in helm.responses if r.request_id == 42).request_successful
                helm.send_course = True

                # the helm stops: HELM_ERROR(NOT_RUNNING) once its last report is helm_running_timeout old
                helm.driving = False
                stopped = time.monotonic()
                error = helm.until_state(fs.INTERFACE_HELM_ERROR)
                assert error.helm_error == fs.ERROR_HELM_NOT_RUNNING
                assert time.monotonic() - stopped >= 0.8 * HELM_TIMEOUT / WARP

                # the helm comes back: HELM_ERROR -> STANDBY -> LISTEN -> COMMAND
                helm.driving = True
                helm.until_state(fs.INTERFACE_COMMAND)

                # the simulator dies: FS_ERROR(NOT_CONNECTED)
                sims[0].stop(kill=True)
                fs_error = helm.until_state(fs.INTERFACE_FS_ERROR)
                assert fs_error.frontseat_error == fs.ERROR_FRONTSEAT_NOT_CONNECTED
                assert fs_error.frontseat_state == fs.FRONTSEAT_NOT_CONNECTED
                starts = sum(line.startswith("START") for line in helm.out_lines())

                # ... and comes back on the same port: START again, then STANDBY, LISTEN, COMMAND
                deadline = time.monotonic() + 30
                while len(sims) < 2:
                    try:
                        sims.append(start_simulator(port))
                    except RuntimeError:
                        if time.monotonic() > deadline:
                            raise
                        time.sleep(0.2)
                helm.until_state(fs.INTERFACE_COMMAND)
                assert sum(line.startswith("START") for line in helm.out_lines()) == starts + 1
                states = [s.state for s in helm.status]
                assert fs.INTERFACE_FS_ERROR in states and states[-1] == fs.INTERFACE_COMMAND
        finally:
            code = iface.stop()
            for sim in sims:
                sim.stop()
        assert code == 0, iface.stderr_text()[-3000:]


def test_exit_on_error_quits_with_code_zero(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="usv") as broker:
        cfg = write_config(tmp_path / "fs.pb.cfg", free_port(), helm_running_timeout=2,
                           frontseat_connected_timeout=2)
        cfg.write_text(cfg.read_text().replace("frontseat_cfg {", "frontseat_cfg {\n  exit_on_error: true"))
        iface = start_interface(tmp_path, broker, cfg)
        assert exit_code(iface) == 0
        assert "exit_on_error" in iface.stderr_text()


def test_driver_library_failures_exit_1_naming_the_library_and_cause(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from frontseat.apps.frontseat_interface import main

    monkeypatch.delenv("FRONTSEAT_DRIVER_LIBRARY", raising=False)
    assert main([]) == 1
    assert "FRONTSEAT_DRIVER_LIBRARY" in capsys.readouterr().err

    monkeypatch.setenv("FRONTSEAT_DRIVER_LIBRARY", "no_such_driver_module")
    assert main(["x.cfg"]) == 1
    err = capsys.readouterr().err
    assert "no_such_driver_module" in err and "ModuleNotFoundError" in err

    broken = tmp_path / "broken_driver.py"
    broken.write_text("raise RuntimeError('driver import exploded')\n")
    monkeypatch.setenv("FRONTSEAT_DRIVER_LIBRARY", str(broken))
    assert main(["x.cfg"]) == 1
    err = capsys.readouterr().err
    assert str(broken) in err and "driver import exploded" in err

    no_factory = tmp_path / "no_factory.py"
    no_factory.write_text("X = 1\n")
    monkeypatch.setenv("FRONTSEAT_DRIVER_LIBRARY", str(no_factory))
    assert main(["x.cfg"]) == 1
    assert "frontseat_driver_load" in capsys.readouterr().err


def test_example_config_includes_the_driver_extension_and_parses(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from google.protobuf import text_format

    from frontseat.apps.frontseat_interface import main
    from frontseat.protobuf import frontseat_interface_config_pb2 as app_pb

    monkeypatch.setenv("FRONTSEAT_DRIVER_LIBRARY", "libgoby_frontseat_basic_simulator.so.30")
    assert main(["--example_config"]) == 0
    text = capsys.readouterr().out
    assert "[goby.middleware.frontseat.protobuf.basic_simulator_config]" in text
    cfg = text_format.Parse(text, app_pb.FrontSeatInterfaceConfig())
    assert cfg.frontseat_cfg.require_helm and cfg.frontseat_cfg.status_period == 5
    assert os.environ["FRONTSEAT_DRIVER_LIBRARY"].endswith(".so.30")


def test_a_driver_factory_that_raises_exits_1_promptly(tmp_path: Path) -> None:
    driver = tmp_path / "failing_driver.py"
    driver.write_text("def frontseat_driver_load(cfg):\n    raise RuntimeError('no vehicle attached')\n")
    with broker_process(tmp_path, platform="usv") as broker:
        cfg = tmp_path / "fs.pb.cfg"
        cfg.write_text("frontseat_cfg { require_helm: false }\n")  # this driver has no config extension
        iface = start_interface(tmp_path, broker, cfg, driver=str(driver), flags=())
        assert exit_code(iface) == 1
        assert "no vehicle attached" in iface.stderr_text()
