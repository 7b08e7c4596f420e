"""The basic simulator: codec, the documented dynamics (§5.6) step by step, DURATION, bad input."""

from __future__ import annotations

import math
import socket
import time

import pytest

from frontseat.errors import SimulatorLineError
from frontseat.simulator import protocol
from frontseat.simulator.model import Simulation
from frontseat.simulator.server import SimulatorServer
from frontseat.testing import SimClient, running_simulator
from util.geodesy import UTMGeodesy
from util.process import wait_until

LAT, LON = 41.592344, -70.71126


# ----- a transcription of the documented model, independent of frontseat.simulator.model -----------------
class ReferenceVehicle:
    """§5.6 written out: z up, heading unwrapped toward desired, speed limited by accel, then position."""

    def __init__(self, accel: float = 0.5, hdg_rate: float = 45.0, z_rate: float = 2.0, freq: int = 10) -> None:
        self.a, self.hr, self.zr, self.dt = accel, hdg_rate, z_rate, 1.0 / freq
        self.x = self.y = self.z = self.v = self.hdg = 0.0
        self.zd = self.vd = self.hd = 0.0

    def command(self, heading: float, speed: float, depth: float) -> None:
        self.hd, self.vd, self.zd = heading, speed, -depth

    def step(self) -> None:
        dt = self.dt
        if abs(self.z - self.zd) > self.zr * dt:
            self.z += self.zr * dt if self.z < self.zd else -self.zr * dt
        else:
            self.z = self.zd
        if self.hdg - self.hd >= 180:
            self.hd += 360
        if self.hdg - self.hd < -180:
            self.hd -= 360
        if abs(self.hdg - self.hd) > self.hr * dt:
            self.hdg += self.hr * dt if self.hdg < self.hd else -self.hr * dt
        else:
            self.hdg = self.hd
        if abs(self.v - self.vd) > self.a * dt:
            self.v += self.a * dt if self.v < self.vd else -self.a * dt
        else:
            self.v = self.vd
        theta = (90 - self.hdg) * math.pi / 180
        self.x += self.v * math.cos(theta) * dt
        self.y += self.v * math.sin(theta) * dt


def nav_fields(line: str) -> dict[str, str]:
    key, fields = protocol.parse_line(line)
    assert key == "NAV", line
    return fields


# ----- codec ----------------------------------------------------------------------------------------------
def test_parse_line_first_duplicate_wins_and_extra_colon_parts_are_ignored() -> None:
    assert protocol.parse_line("CMD,HEADING:1,HEADING:2,SPEED:3:9") == ("CMD", {"HEADING": "1", "SPEED": "3"})


@pytest.mark.parametrize("line", ["CMD,HEADING:1,", "CMD,,HEADING:1", "CMD,HEADING"])
def test_parse_line_rejects_a_field_without_colon(line: str) -> None:
    with pytest.raises(SimulatorLineError):
        protocol.parse_line(line)


def test_numbers_fall_back_like_goby() -> None:
    assert math.isnan(protocol.as_double("abc")) and math.isnan(protocol.as_double(None))
    assert protocol.as_double("-1.5e2") == -150.0
    assert protocol.as_int("10.5") == protocol.INT_MAX and protocol.as_int("") == protocol.INT_MAX
    assert protocol.as_int("-7") == -7


def test_start_line_uses_six_significant_digits() -> None:
    line = protocol.start_line(41.592344, -70.71126, 0, 10, 0.5, 45, 2, 10)
    assert line == "START,LAT:41.5923,LON:-70.7113,DURATION:0,FREQ:10,ACCEL:0.5,HDG_RATE:45,Z_RATE:2,WARP:10"


# ----- the model against the spec's golden vector ----------------------------------------------------------
def test_model_matches_the_documented_worked_example() -> None:
    sim = Simulation()
    assert sim.handle_line(f"START,LAT:{LAT},LON:{LON}") == [protocol.CTRL_PAYLOAD]
    assert sim.handle_line("CMD,HEADING:270,SPEED:1.5,DEPTH:10") == [protocol.CMD_OK]
    navs = [nav_fields(sim.tick()[0]) for _ in range(40)]

    def brief(i: int) -> tuple[str, str, str]:
        return navs[i - 1]["DEPTH"], navs[i - 1]["HEADING"], navs[i - 1]["SPEED"]

    assert brief(1) == ("0.2", "-4.5", "0.05")
    assert brief(2) == ("0.4", "-9", "0.1")
    assert brief(10) == ("2", "-45", "0.5")
    assert brief(20) == ("4", "-90", "1")
    assert brief(30) == ("6", "-90", "1.5")
    assert brief(40) == ("8", "-90", "1.5")
    assert sim.vehicle.x == pytest.approx(-3.635986264, abs=1e-9)
    assert sim.vehicle.y == pytest.approx(0.4615987146, abs=1e-9)


def test_first_nav_of_a_fresh_simulator_has_minus_zero_depth() -> None:
    sim = Simulation()
    sim.handle_line(f"START,LAT:{LAT},LON:{LON}")
    nav = nav_fields(sim.tick()[0])
    assert (nav["DEPTH"], nav["HEADING"], nav["SPEED"]) == ("-0", "0", "0")
    assert float(nav["LAT"]) == pytest.approx(LAT, abs=1e-9)


def test_restart_keeps_vehicle_state_and_resets_parameters() -> None:
    sim = Simulation()
    sim.handle_line(f"START,LAT:{LAT},LON:{LON},FREQ:20,ACCEL:2")
    sim.handle_line("CMD,HEADING:0,SPEED:1,DEPTH:0")
    for _ in range(5):
        sim.tick()
    v = sim.vehicle.v
    assert v == pytest.approx(0.5)  # 5 steps of 2 m/s² at 20 Hz
    sim.handle_line(f"START,LAT:{LAT},LON:{LON}")
    assert sim.period == pytest.approx(0.1)  # FREQ back to 10
    nav = nav_fields(sim.tick()[0])
    assert float(nav["SPEED"]) == pytest.approx(v + 0.05)  # default accel again, speed kept


def test_duration_gives_exactly_d_plus_one_times_f_minus_one_navs_then_idle() -> None:
    sim = Simulation()
    sim.handle_line(f"START,LAT:{LAT},LON:{LON},DURATION:2,FREQ:5")
    out = [line for _ in range(40) for line in sim.tick()]
    assert sum(line.startswith("NAV") for line in out) == (2 + 1) * 5 - 1
    assert out[(2 + 1) * 5 - 1] == protocol.CTRL_IDLE and len(out) == (2 + 1) * 5
    assert sim.handle_line("CMD,HEADING:1,SPEED:1,DEPTH:1") == [protocol.CMD_ERROR]


# ----- the real server over TCP ----------------------------------------------------------------------------
@pytest.mark.parametrize("warp", [1, 10])
def test_server_dynamics_step_by_step_after_cmd_heading_90(warp: int) -> None:
    steps = 30
    geodesy = UTMGeodesy(LAT, LON)
    with SimulatorServer() as server, SimClient(server.port) as client:
        sent = time.monotonic()
        client.send(f"START,LAT:{LAT},LON:{LON},WARP:{warp}", "CMD,HEADING:90,SPEED:2,DEPTH:0")
        client.read_until(lambda line: line == protocol.CTRL_PAYLOAD)
        # NAVs before the CMD reply (if the CMD arrived a tick late) leave the vehicle at rest
        before = client.read_until(lambda line: line == protocol.CMD_OK)
        for line in before[:-1]:
            nav = nav_fields(line)
            assert (float(nav["SPEED"]), float(nav["HEADING"])) == (0.0, 0.0)
        ref = ReferenceVehicle()
        ref.command(90, 2, 0)
        for step in range(1, steps + 1):
            nav = nav_fields(client.read_line())
            ref.step()
            assert nav["SPEED"] == format(ref.v, ".10g"), f"step {step}"
            assert nav["HEADING"] == format(ref.hdg, ".10g"), f"step {step}"
            assert nav["DEPTH"] == format(-ref.z, ".10g"), f"step {step}"
            lat, lon = geodesy.to_geo(ref.x, ref.y)
            assert float(nav["LAT"]) == pytest.approx(lat, abs=1e-8), f"step {step}"
            assert float(nav["LON"]) == pytest.approx(lon, abs=1e-8), f"step {step}"
        elapsed = time.monotonic() - sent
        period = server.simulation.period
    # the steps covered both regimes: heading settled at 90 after 20 steps, speed still ramping by 0.05
    assert ref.hdg == 90 and ref.v == pytest.approx(1.5)
    assert ref.x > 0 and abs(ref.y) < ref.x
    assert period == pytest.approx(0.1 / warp)  # one step per 1/(FREQ*WARP) real seconds
    if warp == 1:
        # never ahead of schedule (it may catch up after a stall by at most MAX_LAG = 1 s)
        assert elapsed >= steps * 0.1 - 1.0 - 0.1


def test_bad_input_leaves_the_server_serving_other_clients() -> None:
    with SimulatorServer() as server, SimClient(server.port) as good:
        with SimClient(server.port) as bad:
            bad.send("CMD,HEADING:1,SPEED:1,DEPTH:1")  # before START: our reply is an error
            assert good.read_line() == protocol.CMD_ERROR  # replies go to every client
            good.send(f"START,LAT:{LAT},LON:{LON},WARP:10")
            good.read_until(lambda line: line == protocol.CTRL_PAYLOAD)
            bad.send(
                "garbage",
                "\x00\x01\xff binary",
                "START,LON:1",  # missing LAT: logged, no reply
                "START,LAT:95,LON:1",  # not a position
                "START,LAT:1,LON:1,FREQ:0",  # would divide by zero in the original
                "CMD,HEADING:1,SPEED:1",  # missing DEPTH
                "CMD,HEADING:x,SPEED:1,DEPTH:1",  # not a number
                "CMD,HEADING:1,SPEED:1,DEPTH:1,",  # trailing comma
                "",
            )
            bad.send_bytes(b"X" * (1024 * 1024) + b"\r\n")  # a 1 MB line
            bad.send_bytes(b"CMD,HEADING:1,SPE")  # then leave mid-line: FIN after the data, so none of it is lost
            bad.sock.shutdown(socket.SHUT_WR)
            # the three malformed CMDs are answered with errors, nothing else is answered, NAV keeps flowing
            seen: list[str] = []
            wait_until(lambda: seen.append(good.read_line()) or seen.count(protocol.CMD_ERROR) == 3, timeout=30)
        seen += [good.read_line() for _ in range(30)]
        assert seen.count(protocol.CMD_ERROR) == 3
        assert protocol.CTRL_PAYLOAD not in seen
        assert sum(line.startswith("NAV") for line in seen) >= 20
        wait_until(lambda: server.client_count == 1, what="the departed client to be dropped")
        with SimClient(server.port) as late:
            late.send("CMD,HEADING:180,SPEED:1,DEPTH:2")
            late.read_until(lambda line: line == protocol.CMD_OK)
        assert server.running
        # the state from the good client's START survived the bad client
        assert nav_fields(good.read_until(lambda line: line.startswith("NAV"))[-1])["LAT"]


def test_frontseat_sim_process_usage_and_run() -> None:
    from frontseat.apps.frontseat_sim import main

    assert main([]) == 1
    assert main(["notaport"]) == 1
    with running_simulator() as sim, SimClient(sim.port) as client:
        client.send(f"START,LAT:{LAT},LON:{LON},WARP:10")
        lines = client.read_until(lambda line: line.startswith("NAV"))
        assert lines[0] == protocol.CTRL_PAYLOAD
    assert sim.process.returncode == 0  # SIGTERM is a clean shutdown


@pytest.mark.parametrize("fields", ["HEADING:0,SPEED:-5,DEPTH:0", "HEADING:0,SPEED:1e308,DEPTH:0",
                                    "HEADING:1e20,SPEED:1,DEPTH:0", "HEADING:0,SPEED:1,DEPTH:-1",
                                    "HEADING:0,SPEED:inf,DEPTH:0", "HEADING:nan,SPEED:1,DEPTH:0",
                                    "HEADING:0,SPEED:1,DEPTH:11001"])
def test_out_of_range_or_non_finite_commands_are_refused_and_change_nothing(fields: str) -> None:
    sim = Simulation()
    sim.handle_line(f"START,LAT:{LAT},LON:{LON}")
    assert sim.handle_line("CMD,HEADING:-360,SPEED:100,DEPTH:11000") == [protocol.CMD_OK]  # the bounds are in
    before = (sim.desired.hdg, sim.desired.v, sim.desired.z)
    assert sim.handle_line(f"CMD,{fields}") == [protocol.CMD_ERROR]
    assert (sim.desired.hdg, sim.desired.v, sim.desired.z) == before
