"""Contacts in the helm: NODE_REPORT into pHelmIvP 19.8.1's <NAME>_NAV_* variables, and LinearExtrapolator."""

from __future__ import annotations

import logging
import math

import pytest

from behaviors.helm.contacts import ContactTable, LinearExtrapolator
from behaviors.helm.info_buffer import InfoBuffer
from behaviors.helm.testing import helm_from_text
from translators.node_report_codec import NodeReportError
from util.geodesy import UTMGeodesy

ORIGIN = (43.8253, -70.3304)  # moos-ivp's s1_alpha; (60, -40) is 43.82494863, -70.32964602 on its UTM grid


def test_a_report_writes_phelmivp_contact_variables():
    info = InfoBuffer()
    table = ContactTable(info, skews={"usv": 2.5})
    table.handle_report("name=usv,type=USV,TIME=1000.25,X=10,Y=-20.5,DEPTH=3,HDG=370,SPD=1.5,GROUP=blue")
    assert info.get("USV_NAV_X") == 10.0 and info.get("USV_NAV_Y") == -20.5
    assert info.get("USV_NAV_SPEED") == 1.5 and info.get("USV_NAV_HEADING") == 370.0  # as reported, as pHelmIvP
    assert info.get("USV_NAV_DEPTH") == 3.0
    assert info.get("USV_NAV_TYPE") == "USV" and info.get("USV_NAV_GROUP") == "blue"
    assert info.get("USV_NAV_UTC") == 1002.75  # TIME + node_skew (given for the name as reported)
    assert info.get("USV_NAV_LAT") == 0.0 and info.get("USV_NAV_LONG") == 0.0  # no grid to fill them from
    assert table.names() == ["USV"] and table.get("usv").x == 10.0


def test_lat_lon_reports_are_placed_on_the_missions_utm_grid():
    info = InfoBuffer()
    table = ContactTable(info, UTMGeodesy(*ORIGIN))
    table.handle_report("NAME=alpha,TIME=5,LAT=43.82494863,LON=-70.32964602,SPD=2,HDG=90")
    assert info.get("ALPHA_NAV_X") == pytest.approx(60.0, abs=0.01)
    assert info.get("ALPHA_NAV_Y") == pytest.approx(-40.0, abs=0.01)
    assert info.get("ALPHA_NAV_LAT") == 43.82494863
    table.handle_report("NAME=bravo,TIME=5,X=180,Y=-100")  # and the other way round
    assert info.get("BRAVO_NAV_LAT") == pytest.approx(43.82442590, abs=1e-7)
    assert info.get("BRAVO_NAV_LONG") == pytest.approx(-70.32814209, abs=1e-7)
    assert info.get("BRAVO_NAV_SPEED") == 0.0 and info.get("BRAVO_NAV_HEADING") == 0.0


@pytest.mark.parametrize(("line", "reason"), [
    ("TYPE=USV,TIME=1,X=1,Y=2", "no NAME"),
    ("NAME=USV,X=1,Y=2", "USV: no TIME"),
    ("NAME=USV,TIME=1,X=1", "USV: neither X and Y nor LAT and LON"),
    ("NAME=USV,TIME=1,LAT=43.8,LON=-70.3", "USV: a LAT/LON report needs the mission's LatOrigin/LongOrigin"),
    ("NAME=USV,TIME=1,X=1,Y=2.5e-3", "Y=2.5e-3 is not a number"),
])
def test_unusable_reports_are_refused_whole(line, reason):
    info = InfoBuffer()
    with pytest.raises(NodeReportError) as exc:
        ContactTable(info).handle_report(line)
    assert str(exc.value) == reason
    assert not any(info.is_known(f"USV_NAV_{s}") for s in ("X", "Y", "UTC"))


def test_the_helm_registers_node_reports_and_logs_a_bad_one_by_name(caplog):
    helm = helm_from_text("initialize A = 1\n")
    assert {"NODE_REPORT", "NODE_REPORT_LOCAL", "AIS_REPORT", "AIS_REPORT_LOCAL"} <= helm.registrations()
    with caplog.at_level(logging.WARNING, logger="behaviors.helm.helm"):
        helm.handle_mail("NODE_REPORT", "NAME=USV,TIME=10,X=1e-3,Y=0", 10.0, "gateway", 10.0)
        helm.handle_mail("NODE_REPORT", "NAME=USV,TIME=10,X=1e-3,Y=0", 11.0, "gateway", 11.0)  # the same fault
    warnings = [r.getMessage() for r in caplog.records]
    assert warnings == ["unhandled NODE_REPORT from gateway: X=1e-3 is not a number "
                        "(report 'NAME=USV,TIME=10,X=1e-3,Y=0')"]
    assert not helm.info.is_known("USV_NAV_X")
    assert helm.info.get("NODE_REPORT") == "NAME=USV,TIME=10,X=1e-3,Y=0"  # the raw string, as pHelmIvP keeps it
    helm.handle_mail("NODE_REPORT_LOCAL", "NAME=alpha,TIME=10,X=1,Y=2,SPD=1,HDG=5", 12.0, "pNodeReporter", 12.0)
    assert helm.info.get("ALPHA_NAV_X") == 1.0 and helm.contacts.get("ALPHA").heading == 5.0


def test_node_skew_is_read_from_the_helm_block():
    helm = helm_from_text("initialize A = 1\n", node_skew="usv,-3")
    helm.handle_mail("NODE_REPORT", "NAME=usv,TIME=10,X=1,Y=2", 10.0, "gateway", 10.0)
    assert helm.info.get("USV_NAV_UTC") == 7.0  # matched by the name as reported (or upper-cased), as pHelmIvP
    bad = helm_from_text("initialize A = 1\n", node_skew="usv")
    assert any("node_skew must be VNAME,SECONDS" in p for p in bad.problems)


# ---- LinearExtrapolator: the numbers of its formulas (decay 15..30 s, 2 m/s due east from (0, 0) at t=100) --
def extrapolator() -> LinearExtrapolator:
    ex = LinearExtrapolator(15, 30)
    ex.set_position(0.0, 0.0, 2.0, 90.0, 100.0)
    return ex


@pytest.mark.parametrize(("now", "distance", "maxed"), [
    (100.0, 0.0, False),  # dt = 0: the report itself
    (110.0, 20.0, False),  # dt <= decay_start: spd * dt
    (115.0, 30.0, False),
    (120.0, 30.0 + (2.0 + (2.0 - 2.0 / 15 * 5)) / 2 * 5, False),  # decaying: spd*ds + average speed * (dt - ds)
    (130.0, 30.0 + 1.0 * 15, False),
    (140.0, 45.0, True),  # past decay_end: spd*ds + spd/2*(de - ds), and maxed
    (99.95, -0.1, False),  # slightly negative dt (within 0.1 s) is still extrapolated, backwards
])
def test_extrapolation_follows_the_linear_extrapolator_formulas(now, distance, maxed):
    ex = extrapolator()
    x, y, ok = ex.position(now)
    assert ok and ex.failure_reason == ""
    assert (x, y) == pytest.approx((distance, 0.0), abs=1e-9)
    assert ex.decay_maxed is maxed


def test_negative_dt_returns_the_raw_position_and_keeps_the_maxed_flag():
    ex = extrapolator()
    ex.position(200.0)
    assert ex.decay_maxed
    x, y, ok = ex.position(99.8)
    assert not ok and (x, y) == (0.0, 0.0)
    assert ex.failure_reason == "negative delta time, possible clock skew, dtime=-0.20000"
    assert ex.decay_maxed  # not reset by a failure, as in MOOS-IvP


def test_instant_decay_and_no_position():
    ex = LinearExtrapolator(10, 10)
    assert ex.position(5.0) == (0.0, 0.0, False) and ex.failure_reason == "unknown contact position"
    ex.set_position(1.0, 1.0, 3.0, 45.0, 0.0)
    x, y, ok = ex.position(20.0)
    assert ok and ex.decay_maxed
    assert (x, y) == pytest.approx((1 + 30 * math.sin(math.radians(45)), 1 + 30 * math.cos(math.radians(45))))
