"""The basic simulator's NAV heading is not wrapped to [0, 360), as Goby's ``goby_basic_frontseat_simulator``:
its ``compute_state`` moves only the *desired* heading by ±360 toward the vehicle's, and prints ``vehicle_.hdg``
as it is (issue 29's ``raw_in`` showing ``HEADING:381``: explained in docs/launch.md, not changed)."""

from __future__ import annotations

from collections.abc import Callable

from frontseat.simulator import protocol
from frontseat.simulator.server import SimulatorServer
from frontseat.testing import SimClient

LAT, LON = 21.590491, -159.534166


def heading(line: str) -> str:
    return dict(field.split(":", 1) for field in line.split(",")[1:])["HEADING"]


def reaches(wanted: str) -> Callable[[str], bool]:
    return lambda line: line.startswith("NAV,") and heading(line) == wanted


def test_turning_clockwise_past_north_reads_381_over_tcp() -> None:
    with SimulatorServer() as server, SimClient(server.port) as client:
        client.send(f"START,LAT:{LAT},LON:{LON},WARP:10")
        client.read_until(lambda line: line == protocol.CTRL_PAYLOAD)
        for wanted in ("90", "180", "270"):  # each a quarter turn clockwise (the shorter way)
            client.send(f"CMD,HEADING:{wanted},SPEED:1,DEPTH:0")
            client.read_until(reaches(wanted))
        client.send("CMD,HEADING:21,SPEED:1,DEPTH:0")  # 111 degrees further clockwise: through 360, not back
        turn = client.read_until(reaches("381"))
    headings = [float(heading(line)) for line in turn if line.startswith("NAV,")]
    assert headings == sorted(headings) and 360 < headings[-1] == 381  # clockwise all the way, never wrapped
    assert any(360 < h < 381 for h in headings)
