"""ZAIC_PEAK utilities, coupling, and the per-variable grid solver (spec §6)."""

from __future__ import annotations

import pytest

from behaviors.helm.errors import ParamError
from behaviors.helm.ivp import IvPDomain, ObjectiveFunction, solve, zaic_peak


def dom() -> IvPDomain:
    d = IvPDomain()
    d.add("course:0:359:360")
    d.add("speed:0:4:41")
    return d


def test_domain_forms_and_summary() -> None:
    d = IvPDomain()
    d.add("course,0,359,360")
    d.add("speed:0:4:delta=0.1")
    d.add("depth:0:100:101:optional")
    assert d.vars["speed"].points == 41 and d.vars["depth"].optional
    assert d.summary() == "course,0,359,360:speed,0,4,41:depth,0,100,101"
    assert d.vars["speed"].grid()[12] == pytest.approx(1.2)


@pytest.mark.parametrize("spec", ["speed:0:4", "speed:a:4:41", "speed:0:4:4.5", "speed:0:0:5", "speed:0:4:41:maybe"])
def test_bad_domains_are_rejected(spec: str) -> None:
    with pytest.raises(ParamError, match=spec.split(":")[0]):
        IvPDomain().add(spec)


def test_zaic_peak_shape_and_wrap() -> None:
    course = dom().vars["course"]
    u = zaic_peak(course, 10, 0, 180, 0, 0, 100, wrap=True)
    assert u[10] == 100 and u[100] == pytest.approx(50) and u[190] == 0 and u[280] == pytest.approx(50)
    u = zaic_peak(course, 180, 30, 180, 5, 0, 20, wrap=True)
    assert u[180] == 20 and u[210] == pytest.approx(15) and u[0] == pytest.approx(2.5)


def test_narrow_zaic_between_grid_points_keeps_a_peak() -> None:
    speed = dom().vars["speed"]
    u = zaic_peak(speed, 1.23, 0, 0.0, 0, 0, 100)
    assert max(u) == 100 and u.index(100) == 12


def test_waypoint_worked_example_picks_109_not_108() -> None:
    """Spec §6: vehicle at (0,-20) heading 180, bearing to the track point 108.43 deg → 109."""
    d = dom()
    c, s = d.vars["course"], d.vars["speed"]
    crs = [a + b for a, b in zip(zaic_peak(c, 108.43, 0, 180, 0, 0, 100, True),
                                 zaic_peak(c, 180, 30, 180, 5, 0, 20, True), strict=True)]
    fn = ObjectiveFunction.coupled(100, "course", crs, 50, "speed", zaic_peak(s, 1.2, 0.6, 1.6, 20), 50)
    decision = solve(d, [fn])
    assert decision["course"] == 109 and decision["speed"] == pytest.approx(1.2)


def test_priority_weights_decide_between_behaviours() -> None:
    d = dom()
    s = d.vars["speed"]
    survey = ObjectiveFunction.single(100, "speed", zaic_peak(s, 1.2, 0.6, 1.6, 20))
    slow = ObjectiveFunction.single(200, "speed", zaic_peak(s, 0.5, 0, 0.2, 0))
    assert solve(d, [survey, slow])["speed"] == pytest.approx(0.5)
    assert solve(d, [survey])["speed"] == pytest.approx(1.2)
    assert "course" not in solve(d, [survey])
    zero = ObjectiveFunction.single(0, "speed", zaic_peak(s, 3, 0, 0.2, 0))
    assert solve(d, [zero]) == {}
