"""The basic simulator driver against the real simulator (and a scripted TCP peer for lines the sim never sends).

The driver does its I/O on a reactor, as in the interface; here the test's thread is the host: ``tick_until`` runs
the reactor (lines arrive) and ``do_work`` (the tick) in turn."""

from __future__ import annotations

import socket
import threading
import time

import pytest

from frontseat.basic_simulator_driver import BasicSimulatorDriver, frontseat_driver_load
from frontseat.errors import DriverConfigError
from frontseat.line_client import LineConnection
from frontseat.protobuf import basic_simulator_config_pb2 as sim_pb
from frontseat.protobuf import basic_simulator_tuning_pb2 as tuning_pb
from frontseat.protobuf import frontseat_config_pb2 as config_pb
from frontseat.protobuf import frontseat_pb2 as fs
from frontseat.simulator.server import SimulatorServer
from util.geodesy import UTMGeodesy
from util.process import wait_until
from util.reactor import Reactor

ORIGIN = (41.592344, -70.711260)


class AdjustableClock:
    """Wall-clock seconds plus an offset the test can add (to cross the data timeout quickly)."""

    def __init__(self) -> None:
        self.offset = 0.0

    def now(self) -> float:
        return time.time() + self.offset


def make_cfg(port: int, warp: int = 10, **tuning_fields: float) -> config_pb.Config:
    cfg = config_pb.Config(name="usv", type=20, sim_warp_factor=warp)
    cfg.origin.lat, cfg.origin.lon = ORIGIN
    ext = cfg.Extensions[sim_pb.basic_simulator_config]
    ext.tcp_address, ext.tcp_port = "127.0.0.1", port
    ext.start.lat, ext.start.lon = 41.592344, -70.71126
    tuning = cfg.Extensions[tuning_pb.basic_simulator_tuning]
    tuning.reconnect_interval = 0.1
    for name, value in tuning_fields.items():
        setattr(tuning, name, value)
    return cfg


class Recorder:
    def __init__(self, driver: BasicSimulatorDriver) -> None:
        self.raw_in: list[str] = []
        self.raw_out: list[str] = []
        self.data: list[fs.InterfaceData] = []
        self.responses: list[fs.CommandResponse] = []
        driver.signal_raw_from_frontseat.connect(lambda r: self.raw_in.append(r.raw.decode()))
        driver.signal_raw_to_frontseat.connect(lambda r: self.raw_out.append(r.raw.decode()))
        driver.signal_data_from_frontseat.connect(self.data.append)
        driver.signal_command_response.connect(self.responses.append)


@pytest.fixture()
def reactor():
    host = Reactor("test-host")
    yield host
    host.close()


def tick_until(driver: BasicSimulatorDriver, condition, timeout: float = 20.0, what: str = ""):
    def step():
        driver.reactor.run_once(0.01)
        driver.do_work()
        return condition()

    return wait_until(step, timeout=timeout, interval=0.0, what=what)


def run_until(reactor: Reactor, condition, timeout: float = 20.0, what: str = ""):
    return wait_until(lambda: reactor.run_once(0.01) >= 0 and condition(), timeout=timeout, interval=0.0, what=what)


def test_missing_extension_is_a_clear_config_error() -> None:
    with pytest.raises(DriverConfigError, match="basic_simulator_config"):
        frontseat_driver_load(config_pb.Config())


def test_a_driver_without_a_host_reactor_is_a_clear_config_error() -> None:
    with pytest.raises(DriverConfigError, match="hosted_on"):
        BasicSimulatorDriver(make_cfg(1), clock=AdjustableClock())


def test_start_nav_command_and_responses_against_the_real_simulator(reactor: Reactor) -> None:
    clock = AdjustableClock()
    with SimulatorServer() as server, \
            BasicSimulatorDriver(make_cfg(server.port), clock=clock, reactor=reactor) as driver:
        rec = Recorder(driver)
        assert driver.frontseat_state() == fs.FRONTSEAT_NOT_CONNECTED
        tick_until(driver, lambda: driver.frontseat_state() == fs.FRONTSEAT_ACCEPTING_COMMANDS, what="PAYLOAD")
        assert rec.raw_out[0] == (
            "START,LAT:41.5923,LON:-70.7113,DURATION:0,FREQ:10,ACCEL:0.5,HDG_RATE:45,Z_RATE:2,WARP:10"
        )
        assert rec.raw_in[0] == "CTRL,STATE:PAYLOAD"
        tick_until(driver, lambda: rec.data, what="NAV")
        assert driver.frontseat_providing_data()
        status = rec.data[0].node_status
        first_nav = next(line for line in rec.raw_in if line.startswith("NAV"))
        assert first_nav.endswith("DEPTH:-0,HEADING:0,SPEED:0")
        assert (status.name, status.type) == ("usv", 20)
        assert status.global_fix.depth == 0 and status.local_fix.z == 0
        x, y = UTMGeodesy(*ORIGIN).to_local(status.global_fix.lat, status.global_fix.lon)
        assert (status.local_fix.x, status.local_fix.y) == pytest.approx((x, y), abs=1e-6)
        assert abs(status.time - clock.now()) < 5

        # a command asking for a response gets one, matched to the last request
        request = fs.CommandRequest(response_requested=True, request_id=7)
        request.desired_course.time = clock.now()
        request.desired_course.heading, request.desired_course.speed = 90, 2
        driver.send_command_to_frontseat(request)
        assert rec.raw_out[-1] == "CMD,HEADING:90,SPEED:2,DEPTH:0"
        tick_until(driver, lambda: rec.responses, what="command response")
        assert (rec.responses[0].request_successful, rec.responses[0].request_id) == (True, 7)
        # a plain desired course (as the interface builds it) gets none
        plain = fs.CommandRequest()
        plain.desired_course.time, plain.desired_course.heading = clock.now(), 45
        driver.send_command_to_frontseat(plain)
        tick_until(driver, lambda: "CMD,RESULT:OK" in rec.raw_in[rec.raw_in.index("CMD,RESULT:OK") + 1 :])
        assert len(rec.responses) == 1
        # the vehicle answers the command: heading rises toward 90
        tick_until(driver, lambda: rec.data[-1].node_status.pose.heading > 10, what="the vehicle to turn")

        # raw send passes the text through; no data -> providing_data false after data_timeout
        driver.send_raw_to_frontseat(fs.Raw(raw=b"CMD,HEADING:0,SPEED:0,DEPTH:0\r\n"))
        assert rec.raw_out[-1] == "CMD,HEADING:0,SPEED:0,DEPTH:0"
        clock.offset = -1e6  # data looks fresh forever... until the clock jumps ahead of it
        driver.do_work()
        clock.offset = 1e6
        server.stop()
        tick_until(driver, lambda: not driver.frontseat_providing_data(), what="data timeout")


def test_reconnects_and_restarts_after_the_simulator_comes_back(reactor: Reactor) -> None:
    server = SimulatorServer().start()
    port = server.port
    try:
        with BasicSimulatorDriver(make_cfg(port), clock=AdjustableClock(), reactor=reactor) as driver:
            rec = Recorder(driver)
            tick_until(driver, driver.frontseat_providing_data, what="first NAV")
            server.stop()
            tick_until(driver, lambda: driver.frontseat_state() == fs.FRONTSEAT_NOT_CONNECTED, what="link lost")
            assert not driver.frontseat_providing_data()
            server = wait_until(lambda: _try_server(port), what="port reuse")
            tick_until(driver, driver.frontseat_providing_data, what="NAV from the restarted simulator")
            assert driver.frontseat_state() == fs.FRONTSEAT_ACCEPTING_COMMANDS
            assert sum(line.startswith("START") for line in rec.raw_out) == 2
    finally:
        server.stop()


def _try_server(port: int) -> SimulatorServer | None:
    try:
        return SimulatorServer(port=port).start()
    except OSError:
        return None


class ScriptedPeer:
    """A one-shot TCP peer that plays lines the simulator never sends (test peer, real socket)."""

    def __init__(self, batches: list[bytes]) -> None:
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.received = bytearray()
        self.thread = threading.Thread(target=self._serve, args=(batches,), name="scripted-peer")
        self.thread.start()

    def _serve(self, batches: list[bytes]) -> None:
        """Send each batch after receiving one more line from the driver (START first, then NEXT)."""
        conn, _ = self.listener.accept()
        with conn:
            conn.settimeout(10)
            for batch in batches:
                while self.received.count(b"\r\n") <= batches.index(batch):
                    self.received += conn.recv(4096)
                conn.sendall(batch)
            try:
                while chunk := conn.recv(4096):
                    self.received += chunk
            except OSError:
                pass

    def close(self) -> None:
        self.listener.close()
        self.thread.join(timeout=10)


def test_ctrl_states_garbage_and_missing_nav_values(reactor: Reactor) -> None:
    peer = ScriptedPeer(
        [b"CTRL,STATE:AUV\r\n", b"garbage,line\r\nNAV,LAT:41.6,LON:-70.7\r\nWHAT,X:1\r\nCTRL\r\n"]
    )
    try:
        with BasicSimulatorDriver(make_cfg(peer.port), clock=AdjustableClock(), reactor=reactor) as driver:
            rec = Recorder(driver)
            tick_until(driver, lambda: driver.frontseat_state() == fs.FRONTSEAT_IN_CONTROL, what="CTRL,STATE:AUV")
            driver.send_raw_to_frontseat(fs.Raw(raw=b"NEXT"))
            tick_until(driver, lambda: len(rec.raw_in) == 5, what="the rest of the script")
            assert driver.frontseat_state() == fs.FRONTSEAT_IDLE  # a CTRL without STATE reads as idle
            assert rec.raw_in[1] == "garbage,line"  # raw_in carries even unparsable lines
            assert len(rec.data) == 1
            nav = rec.data[0].node_status
            assert nav.global_fix.lat == 41.6
            assert nav.pose.heading != nav.pose.heading and nav.speed.over_ground != nav.speed.over_ground  # NaN
            assert peer.received.startswith(b"START,LAT:41.5923")
    finally:
        peer.close()


def test_link_refuses_a_line_over_its_bound_and_reconnects_when_the_peer_stops_reading(reactor: Reactor) -> None:
    listener = socket.create_server(("127.0.0.1", 0))  # accepts (kernel backlog) but never reads
    connects: list[float] = []
    try:
        with LineConnection(reactor, "127.0.0.1", listener.getsockname()[1], on_line=lambda _line: None,
                            on_connect=lambda: connects.append(time.monotonic()), io_timeout=0.5,
                            reconnect_interval=0.05, max_pending=256 * 1024) as link:
            run_until(reactor, lambda: link.connected, what="connection")
            assert link.write_line("X" * (1024 * 1024)) is False  # one line over the bound: refused, link kept
            assert link.connected and link.pending == 0
            # the peer never reads: the kernel buffers fill, then the queue; writes stall and the link is renewed
            written = 0
            while link.connected and link.write_line("Y" * 1000):
                written += 1
                reactor.run_once(0)
            assert written > 10  # what the kernel and the queue took before the bound
            run_until(reactor, lambda: len(connects) >= 2 and link.connected, what="a fresh connection")
            assert link.pending == 0  # the stalled bytes went with the old connection (and were logged)
            assert link.write_line("Z") is True
            # a queue that stops draining (without filling up) is also a stall: the io_timeout renews the link
            while link.pending == 0:
                link.write_line("W" * 60000)
                reactor.run_once(0)
            stalled = time.monotonic()
            run_until(reactor, lambda: len(connects) >= 3, what="the stall to be noticed")
            assert time.monotonic() - stalled >= 0.4
    finally:
        listener.close()


def test_duration_expiry_leads_command_to_listen_then_not_providing_data(reactor: Reactor) -> None:
    """§6.5 step 10 with real parts: CTRL,STATE:IDLE ends COMMAND; silence then trips the data timeout."""
    with SimulatorServer() as server:
        cfg = make_cfg(server.port, warp=10, data_timeout=0.5)
        cfg.Extensions[sim_pb.basic_simulator_config].start.duration = 5  # 5 s simulated = 0.5 s real at warp 10
        with BasicSimulatorDriver(cfg, clock=AdjustableClock(), reactor=reactor) as driver:
            states: list[int] = []
            driver.signal_state_change.connect(states.append)
            driver.set_helm_state(fs.HELM_DRIVE)
            tick_until(driver, lambda: driver.state() == fs.INTERFACE_FS_ERROR, what="FS_ERROR")
            assert states == [fs.INTERFACE_LISTEN, fs.INTERFACE_COMMAND, fs.INTERFACE_LISTEN, fs.INTERFACE_FS_ERROR]
            assert driver.last_frontseat_error() == fs.ERROR_FRONTSEAT_NOT_PROVIDING_DATA
            assert driver.frontseat_state() == fs.FRONTSEAT_IDLE
