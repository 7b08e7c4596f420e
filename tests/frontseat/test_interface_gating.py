"""The interface's portal side in-process (real broker, real portal): state gating of §4.3, the status period,
signal publications, datum updates and the helm report expiry, with a scripted driver double for the vehicle."""

from __future__ import annotations

from functools import partial
from pathlib import Path

from frontseat import groups
from frontseat.driver import FrontSeatDriver
from frontseat.interface import FrontSeatInterface
from frontseat.protobuf import frontseat_config_pb2 as config_pb
from frontseat.protobuf import frontseat_data_pb2 as data_pb
from frontseat.protobuf import frontseat_interface_config_pb2 as app_pb
from frontseat.protobuf import frontseat_pb2 as fs
from frontseat.protobuf import navigation_pb2 as nav_pb
from gateway.goby.portal.testing import PortalClient, broker_process, running_app
from util.process import wait_until

STATUS_PERIOD = 5
HELM_TIMEOUT = 30.0


class FakeClock:
    def __init__(self) -> None:
        self.t = 1_000_000.0

    def now(self) -> float:
        return self.t


class ScriptedDriverDouble(FrontSeatDriver):
    """Test double for a vehicle: the test sets its answers; it records what the interface forwards."""

    clock = FakeClock()

    def __init__(self, cfg: config_pb.Config) -> None:
        super().__init__(cfg, clock=self.clock)
        self.fs_state = fs.FRONTSEAT_NOT_CONNECTED
        self.providing = False
        self.commands: list[fs.CommandRequest] = []
        self.data_sent: list[fs.InterfaceData] = []
        self.raw_sent: list[bytes] = []
        self.helm_reports = 0
        self.emit_nav = False
        self.received_cfg = cfg

    def set_helm_state(self, helm_state: int) -> None:
        super().set_helm_state(helm_state)
        self.helm_reports += 1

    def send_command_to_frontseat(self, command: fs.CommandRequest) -> None:
        self.commands.append(command)

    def send_data_to_frontseat(self, data: fs.InterfaceData) -> None:
        self.data_sent.append(data)

    def send_raw_to_frontseat(self, raw: fs.Raw) -> None:
        self.raw_sent.append(raw.raw)

    def frontseat_state(self) -> int:
        return self.fs_state

    def frontseat_providing_data(self) -> bool:
        return self.providing

    def loop(self) -> None:
        if self.emit_nav:
            self.emit_nav = False
            data = fs.InterfaceData()
            data.node_status.global_fix.lat, data.node_status.global_fix.lon = 41.6, -70.7
            data.node_status.pose.heading, data.node_status.speed.over_ground = 12.0, 1.0
            self.compute_missing(data.node_status)
            self.signal_data_from_frontseat.emit(data)
            self.signal_raw_from_frontseat.emit(fs.Raw(raw=b"NAV,..."))
            self.signal_command_response.emit(fs.CommandResponse(request_successful=True, request_id=3))


def test_gating_status_period_publications_datum_and_helm_expiry(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="auv") as broker:
        cfg = app_pb.FrontSeatInterfaceConfig()
        cfg.app.name = "frontseat_interface"
        cfg.app.geodesy.lat_origin, cfg.app.geodesy.lon_origin = 41.5, -70.6
        cfg.interprocess.CopyFrom(broker.interprocess_config())
        cfg.frontseat_cfg.status_period = STATUS_PERIOD
        cfg.frontseat_cfg.helm_running_timeout = HELM_TIMEOUT
        cfg.frontseat_cfg.frontseat_connected_timeout = 1e9
        with (
            PortalClient(broker.interprocess_config(), name="payload") as client,
            running_app(partial(FrontSeatInterface, driver_factory=ScriptedDriverDouble), cfg) as app,
        ):
            driver: ScriptedDriverDouble = app.driver  # type: ignore[assignment]
            assert (driver.received_cfg.name, driver.received_cfg.origin.lat) == ("auv", 41.5)
            status = client.collect(groups.status, fs.InterfaceStatus)
            order: list[str] = []
            client.subscribe(groups.data_from_frontseat, fs.InterfaceData, lambda _m: order.append("data"))
            client.subscribe(groups.node_status, data_pb.NodeStatus, lambda _m: order.append("node_status"))
            raw_in = client.collect(groups.raw_in, fs.Raw)
            responses = client.collect(groups.command_response, fs.CommandResponse)
            assert client.wait_subscribed()
            # the first-tick status may or may not predate our subscription; one period later there is surely one
            # (a loaded machine may still deliver the first one late, so later checks look at states, not counts)
            ScriptedDriverDouble.clock.t += STATUS_PERIOD
            wait_until(lambda: app._next_status == ScriptedDriverDouble.clock.t + STATUS_PERIOD, what="2nd status")
            assert client.poll_until(lambda: len(status) >= 1)
            assert status[-1].state == fs.INTERFACE_STANDBY

            def send_all(tag: float) -> None:
                """One of each payload-to-frontseat message, then a helm report as an in-order barrier."""
                before = driver.helm_reports
                request = fs.CommandRequest(request_id=int(tag))
                request.desired_course.time = tag
                client.publish(groups.command_request, request)
                client.publish(groups.desired_course, data_pb.DesiredCourse(time=tag, heading=tag))
                client.publish(groups.data_to_frontseat, fs.InterfaceData(dccl_message=str(tag).encode()))
                client.publish(groups.raw_send_request, fs.Raw(raw=str(tag).encode()))
                client.publish(groups.helm_state, fs.HelmStateReport(state=fs.HELM_DRIVE))
                assert client.poll_until(lambda: driver.helm_reports > before)

            # STANDBY: nothing reaches the frontseat
            send_all(1)
            assert driver.state() == fs.INTERFACE_STANDBY
            assert (driver.commands, driver.data_sent, driver.raw_sent) == ([], [], [])

            # LISTEN (frontseat in control): data and raw pass, commands do not
            driver.fs_state, driver.providing = fs.FRONTSEAT_IN_CONTROL, True
            wait_until(lambda: driver.state() == fs.INTERFACE_LISTEN, what="LISTEN")
            send_all(2)
            assert driver.commands == []
            assert [d.dccl_message for d in driver.data_sent] == [b"2"] and driver.raw_sent == [b"2"]

            # COMMAND: everything passes; a desired course becomes a bare CommandRequest
            driver.fs_state = fs.FRONTSEAT_ACCEPTING_COMMANDS
            wait_until(lambda: driver.state() == fs.INTERFACE_COMMAND, what="COMMAND")
            send_all(3)
            assert [c.request_id for c in driver.commands] == [3, 0]
            course_command = driver.commands[1]
            assert [f.name for f, _ in course_command.ListFields()] == ["desired_course"]
            assert course_command.desired_course.heading == 3 and not course_command.response_requested
            assert driver.raw_sent == [b"2", b"3"]

            # status goes out every status_period on the driver's clock, not on state changes
            client.poll(0.3)
            assert {s.state for s in status} == {fs.INTERFACE_STANDBY}, "a state change published a status"
            ScriptedDriverDouble.clock.t += STATUS_PERIOD
            assert client.poll_until(lambda: status[-1].state != fs.INTERFACE_STANDBY)
            client.poll(0.3)
            assert [s.state for s in status if s.state != fs.INTERFACE_STANDBY] == [fs.INTERFACE_COMMAND]
            assert status[-1].helm_state == fs.HELM_DRIVE

            # driver signals: data_from_frontseat then node_status; raw_in; command_response
            driver.emit_nav = True
            assert client.poll_until(lambda: len(order) == 2 and raw_in and responses)
            assert order == ["data", "node_status"]
            assert raw_in[0].raw == b"NAV,..." and responses[0].request_id == 3

            # datum_update moves the driver's grid
            update = nav_pb.DatumUpdate()
            update.datum.lat, update.datum.lon = 42.0, -71.0
            client.publish(groups.datum_update, update)
            wait_until(lambda: driver.geodesy.lat_origin == 42.0, what="datum update")

            # a helm that stops reporting counts as not running after helm_running_timeout: HELM_ERROR in COMMAND
            ScriptedDriverDouble.clock.t += HELM_TIMEOUT + 1
            wait_until(lambda: driver.state() == fs.INTERFACE_HELM_ERROR, what="HELM_ERROR")
            assert driver.last_helm_error() == fs.ERROR_HELM_NOT_RUNNING


def test_moos_helm_block_without_the_translator_fails_clearly(tmp_path: Path, monkeypatch) -> None:
    import sys

    import pytest

    from frontseat.protobuf import moos_helm_frontseat_interface_config_pb2 as helm_pb
    from util.extensions import ExtensionError

    monkeypatch.setitem(sys.modules, "translators.frontseat.translation", None)  # import now raises ImportError
    built: list[ScriptedDriverDouble] = []

    def factory(cfg: config_pb.Config) -> ScriptedDriverDouble:
        built.append(ScriptedDriverDouble(cfg))
        return built[-1]

    with broker_process(tmp_path, platform="auv") as broker:
        cfg = app_pb.FrontSeatInterfaceConfig()
        cfg.interprocess.CopyFrom(broker.interprocess_config())
        cfg.frontseat_cfg.SetInParent()
        cfg.Extensions[helm_pb.moos_helm].port = 9000
        with pytest.raises(ExtensionError, match=r"^Failed to open helm interface: moos_helm, reason: entry point "
                                                 r"moos_helm = translators.frontseat.translation:FrontSeatTranslation: "
                                                 r"ModuleNotFoundError"):
            with running_app(partial(FrontSeatInterface, driver_factory=factory), cfg):
                pass
    assert len(built) == 1
