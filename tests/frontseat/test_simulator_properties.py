"""Properties of the simulator model: no input makes it raise, and every step respects the rate limits."""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from frontseat.simulator import protocol
from frontseat.simulator.model import Simulation

KEYS = st.sampled_from(["START", "CMD", "NAV", "CTRL", "", "start", "CMD "])
FIELD_NAMES = st.sampled_from(["LAT", "LON", "HEADING", "SPEED", "DEPTH", "FREQ", "WARP", "DURATION", "ACCEL", "X"])
VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(2**40), 2**40).map(str),
    st.text(max_size=8),
)
FIELDS = st.lists(st.tuples(FIELD_NAMES, VALUES).map(lambda kv: f"{kv[0]}:{kv[1]}"), max_size=8)
LINES = st.one_of(
    st.text(max_size=200),
    st.builds(lambda key, fields: ",".join([key, *fields]), KEYS, FIELDS),
)


@settings(max_examples=150, deadline=None)
@given(st.lists(LINES, max_size=12))
def test_no_line_makes_the_model_raise(lines: list[str]) -> None:
    sim = Simulation()
    sim.handle_line("START,LAT:41.5,LON:-70.7")
    for line in lines:
        replies = sim.handle_line(line)
        assert set(replies) <= {protocol.CTRL_PAYLOAD, protocol.CMD_OK, protocol.CMD_ERROR, protocol.START_ERROR}
        for out in sim.tick():
            assert out == protocol.CTRL_IDLE or out.startswith("NAV,")
        assert sim.period > 0


@settings(max_examples=100, deadline=None)
@given(
    heading=st.floats(-360, 360),  # the whole range a CMD may ask (model.COMMAND_RANGES); beyond it is refused
    speed=st.floats(0, 5),
    depth=st.floats(0, 50),
    steps=st.integers(1, 60),
)
def test_each_step_respects_the_rate_limits(heading: float, speed: float, depth: float, steps: int) -> None:
    sim = Simulation()
    sim.handle_line("START,LAT:41.5,LON:-70.7,ACCEL:0.5,HDG_RATE:45,Z_RATE:2,FREQ:10")
    assert sim.handle_line(f"CMD,HEADING:{heading!r},SPEED:{speed!r},DEPTH:{depth!r}") == [protocol.CMD_OK]
    dt = 0.1
    for _ in range(steps):
        before = (sim.vehicle.hdg, sim.vehicle.v, sim.vehicle.z, sim.vehicle.x, sim.vehicle.y)
        sim.tick()
        v = sim.vehicle
        assert abs(v.hdg - before[0]) <= 45 * dt + 1e-9
        assert abs(v.v - before[1]) <= 0.5 * dt + 1e-9
        assert abs(v.z - before[2]) <= 2 * dt + 1e-9
        assert math.hypot(v.x - before[3], v.y - before[4]) <= abs(v.v) * dt + 1e-9


@settings(max_examples=100, deadline=None)
@given(st.lists(st.text(alphabet=st.characters(blacklist_categories=("Cs",), blacklist_characters="\r\n"), max_size=20), max_size=10),
       st.lists(st.integers(min_value=1, max_value=7), min_size=1, max_size=5))
def test_the_line_splitter_returns_the_same_lines_however_the_bytes_are_cut(lines: list[str], cuts: list[int]) -> None:
    wire = protocol.encode_lines(lines)
    splitter, got, at, i = protocol.LineSplitter(), [], 0, 0
    while at < len(wire):
        size = cuts[i % len(cuts)]
        got += splitter.feed(wire[at:at + size])
        at, i = at + size, i + 1
    assert got == lines and splitter.partial == 0


def test_the_line_splitter_drops_an_over_long_line_once_and_keeps_the_next() -> None:
    splitter = protocol.LineSplitter(max_line=8)
    assert splitter.feed(b"0123456789abc") == [] and splitter.overflowed
    assert splitter.feed(b"def\r") == [] and not splitter.overflowed
    assert splitter.feed(b"\nNAV,X:1\r\n") == ["NAV,X:1"]
