"""Issue #23 item 6: a START asking for more than ``MAX_TICK_RATE`` ticks per real second (FREQ x WARP) is refused
with ``START,RESULT:ERROR``, and a well-behaved client of the same simulator keeps its rate and its answers."""

from __future__ import annotations

import time

import pytest

from frontseat.simulator import protocol
from frontseat.simulator.model import MAX_TICK_RATE, Simulation
from frontseat.testing import SimClient, running_simulator

LAT, LON = 41.592344, -70.71126


@pytest.mark.parametrize("freq, warp", [(10_000, 10_000), (10, 101), (1001, 1)])
def test_a_tick_rate_over_the_bound_is_refused_and_changes_nothing(freq: int, warp: int) -> None:
    sim = Simulation()
    assert sim.handle_line(f"START,LAT:{LAT},LON:{LON},FREQ:10,WARP:10") == [protocol.CTRL_PAYLOAD]
    assert sim.handle_line(f"START,LAT:{LAT},LON:{LON},FREQ:{freq},WARP:{warp}") == [protocol.START_ERROR]
    assert sim.period == pytest.approx(0.01)
    assert sim.params is not None and (sim.params.freq, sim.params.warp) == (10, 10)


def test_the_bound_itself_is_accepted() -> None:
    sim = Simulation()
    assert sim.handle_line(f"START,LAT:{LAT},LON:{LON},FREQ:10,WARP:{MAX_TICK_RATE // 10}") == [protocol.CTRL_PAYLOAD]
    assert sim.period == pytest.approx(1.0 / MAX_TICK_RATE)


def test_other_invalid_starts_are_answered_with_the_error_too() -> None:
    sim = Simulation()
    for line in ("START,LON:1", "START,LAT:95,LON:1", "START,LAT:1,LON:1,FREQ:0", "START,LAT:1,LON:1,WARP:x"):
        assert sim.handle_line(line) == [protocol.START_ERROR], line
    assert not sim.started


def _nav_rate(client: SimClient, seconds: float) -> float:
    """NAV lines per second the client reads over ``seconds``."""
    count, start = 0, time.monotonic()
    while time.monotonic() - start < seconds:
        if client.read_line(5.0).startswith("NAV"):
            count += 1
    return count / (time.monotonic() - start)


def test_a_huge_tick_rate_from_one_client_does_not_starve_a_well_behaved_one() -> None:
    with running_simulator() as sim, SimClient(sim.port) as good:
        good.send(f"START,LAT:{LAT},LON:{LON},FREQ:10,WARP:10")
        good.read_until(lambda line: line == protocol.CTRL_PAYLOAD, timeout=10)
        with SimClient(sim.port) as attacker:
            attacker.send(f"START,LAT:{LAT},LON:{LON},FREQ:10000,WARP:10000")
            good.read_until(lambda line: line == protocol.START_ERROR, timeout=10)  # replies go to every client
        rate = _nav_rate(good, 1.5)
        assert 40 <= rate <= 200, f"{rate:.0f} NAV/s; the good client's START asked for 100"
        sent = time.monotonic()
        good.send("CMD,HEADING:90,SPEED:1,DEPTH:0")
        good.read_until(lambda line: line == protocol.CMD_OK, timeout=5)
        assert time.monotonic() - sent < 2.0
        assert sim.process.running
