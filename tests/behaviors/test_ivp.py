"""ZAIC_PEAK utilities, coupling, and the per-variable grid solver (spec §6)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from behaviors.helm.errors import ParamError
from behaviors.helm.ivp import IvPDomain, ObjectiveFunction, Piece, ZaicPiece, solve, zaic_peak


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


_summits = st.one_of(st.floats(-400, 800), st.integers(-10, 370).map(float), st.integers(-10, 370).map(lambda k: k + 0.5))
_widths = st.one_of(st.just(0.0), st.floats(0, 200))
_utils = st.sampled_from([(0.0, 100.0), (0.0, 20.0), (10.0, 100.0), (-50.0, 250.0)])


@given(kind=st.sampled_from(["coupled", "single course", "single speed"]), course_summit=_summits,
       speed_summit=st.one_of(st.floats(-1, 5), st.integers(0, 40).map(lambda k: k * 0.1)),
       course_widths=st.tuples(_widths, _widths), speed_widths=st.tuples(st.floats(0, 2), st.floats(0, 3)),
       summitdelta=st.one_of(st.just(0.0), st.floats(0, 100)), utils=_utils,
       pwt=st.floats(0.001, 500), weights=st.tuples(st.floats(0, 100), st.floats(0, 100)).filter(lambda w: sum(w) > 0))
@settings(max_examples=400, deadline=None)
def test_an_unbuilt_zaic_piece_gives_the_decision_of_the_whole_list(
        kind: str, course_summit: float, speed_summit: float, course_widths: tuple[float, float],
        speed_widths: tuple[float, float], summitdelta: float, utils: tuple[float, float], pwt: float,
        weights: tuple[float, float]) -> None:
    """ZaicPiece's shortcut (the best of a handful of points) decides exactly as scoring every grid point does."""
    d = dom()
    course, speed = d.vars["course"], d.vars["speed"]

    def functions(unbuilt: bool) -> list[ObjectiveFunction]:
        crs: Piece = ZaicPiece(course, course_summit, *course_widths, summitdelta, *utils, wrap=True)
        spd: Piece = ZaicPiece(speed, speed_summit, *speed_widths, summitdelta, *utils)
        if not unbuilt:
            crs, spd = zaic_peak(course, course_summit, *course_widths, summitdelta, *utils, wrap=True), \
                zaic_peak(speed, speed_summit, *speed_widths, summitdelta, *utils)
        if kind == "coupled":
            return [ObjectiveFunction.coupled(pwt, "course", crs, weights[0], "speed", spd, weights[1])]
        return [ObjectiveFunction.single(pwt, kind.split()[1], crs if kind == "single course" else spd)]

    assert solve(d, functions(True)) == solve(d, functions(False))


def test_a_zaic_piece_alone_is_decided_without_building_its_list() -> None:
    d = dom()
    crs = ZaicPiece(d.vars["course"], 123.4, 0, 180, 0, wrap=True)
    spd = ZaicPiece(d.vars["speed"], 1.23, 0, 0.3, 0)
    decision = solve(d, [ObjectiveFunction.coupled(100, "course", crs, 50, "speed", spd, 50)])
    assert decision == {"course": 123.0, "speed": pytest.approx(1.2)}
    assert crs._values is None and spd._values is None  # neither list was built
