"""Judging a mission from a hand-made record (and from hand-made logger files read back): polygons, command grouping,
loiter phases, the waypoint turn."""

from __future__ import annotations

import csv
import math

import pytest

from frontseat.protobuf.frontseat_pb2 import InterfaceState, InterfaceStatus
from gateway.goby.log import LogWriter
from gateway.goby.portal import Scheme
from gateway.moos.alog import AlogWriter
from launch.record import MissionRecord, shifted
from launch.usv.analysis import (
    bhv_waypoints,
    command_effects,
    link_acks,
    loiter_phases,
    normalized_heading,
    waypoint_approach,
)
from launch.usv.config import data_log_dir
from launch.usv.geometry import parse_points, parse_polygon, radial_polygon
from launch.usv.mission import MissionResult, read_mission_logs
from launch.usv.plot import write_track_png
from launch.usv.settings import UsvSettings
from launch.usv.summary import progress_line, summary_text
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck


def test_radial_polygon_matches_moos_ivp_vertex_order():
    ring = radial_polygon(0, 0, 200, 6)
    expected = [(100, 173.2), (200, 0), (100, -173.2), (-100, -173.2), (-200, 0), (-100, 173.2)]
    for (x, y), (ex, ey) in zip(ring.vertices, expected, strict=True):
        assert x == pytest.approx(ex, abs=0.1) and y == pytest.approx(ey, abs=0.1)
    assert ring.center == pytest.approx((0, 0), abs=1e-9)
    assert ring.distance((0, 0)) == pytest.approx(173.2, abs=0.1)  # the apothem
    assert ring.distance((200, 0)) == pytest.approx(0, abs=1e-9)


def test_polygon_strings():
    assert len(parse_polygon("polygon=radial::x=0,y=0,radius=400,pts=8").vertices) == 8
    assert len(parse_polygon("radial:: x=10, y=5, radius=50, pts=5").vertices) == 5
    view = parse_polygon("pts={0,0:100,0:100,100:0,100},label=usv_polygon,edge_color=white")
    assert view.label == "usv_polygon" and view.center == (50, 50)
    assert parse_polygon("pts={0,0:100,0:100,100},active=false") is None
    assert parse_polygon("radial::x=0,y=0,radius=0,pts=6") is None
    assert parse_polygon("nonsense") is None
    assert parse_points("pts={1,2:3,4},label=x") == [(1, 2), (3, 4)]


def test_waypoints_are_read_from_the_usv_behaviour_file():
    points = bhv_waypoints(UsvSettings().bhv_file)
    assert points[0] == (134, 33) and len(points) > 50


def _circle(record: MissionRecord, t0: float, t1: float, cx: float, cy: float, r: float) -> None:
    for t in range(int(t0), int(t1)):
        a = t / 50.0
        record.add_nav(t, "NAV_X", cx + r * math.sin(a))
        record.add_nav(t, "NAV_Y", cy + r * math.cos(a))
        record.add_nav(t, "NAV_HEADING", 90.0)


def _mission_record() -> MissionRecord:
    record = MissionRecord()
    record.add_event(0, "moos", "DEPLOY_STATE", "POLYGON", "pHelmIvP")  # the helm's initialize: not a command
    _circle(record, 0, 100, 0, 0, 190)
    record.add_event(100, "moos", "POLYGON_UPDATES", "polygon=radial::x=0,y=0,radius=200,pts=6", "gw")
    record.add_event(100, "moos", "DEPLOY_STATE", "POLYGON", "gw")
    _circle(record, 100, 300, 0, 0, 190)
    record.add_event(300, "moos", "DEPLOY_STATE", "WAYPOINTS", "gw")
    for i, t in enumerate(range(300, 400)):  # head straight for (134, 33) from (0, 190)
        frac = i / 100
        record.add_nav(t, "NAV_X", 134 * frac)
        record.add_nav(t, "NAV_Y", 190 + (33 - 190) * frac)
        record.add_nav(t, "NAV_HEADING", math.degrees(math.atan2(134, 33 - 190)) % 360)
    record.add_event(400, "moos", "POLYGON_UPDATES", "polygon=radial::x=0,y=0,radius=400,pts=8", "gw")
    record.add_event(400, "moos", "DEPLOY_STATE", "POLYGON", "gw")
    record.add_nav(400, "NAV_X", 134)
    record.add_nav(400, "NAV_Y", 33)
    _circle(record, 401, 600, 134, 33, 380)
    return record


def test_commands_are_grouped_and_helm_initialisation_is_not_a_command():
    effects = command_effects(_mission_record())
    assert [e.state for e in effects] == ["POLYGON", "WAYPOINTS", "POLYGON"]
    assert effects[0].polygon_before_state and effects[2].polygon_before_state
    assert not effects[1].polygon_before_state
    assert effects[2].t == 400


def test_loiter_phases_use_the_commanded_ring_recentred_on_activation():
    first, second = loiter_phases(_mission_record())
    assert (first.start, first.end) == (0, 300)
    assert first.ring.mean_radius == pytest.approx(200, abs=1)
    assert first.mean_distance is not None and first.mean_distance < 15
    assert second.start == 400
    assert len(second.ring.vertices) == 8
    assert second.ring.center == pytest.approx((134, 33), abs=1)  # where the vehicle was at t=400
    assert second.final_center_distance == pytest.approx(380, abs=1)


def test_waypoint_approach_measures_the_turn_and_the_closing_range():
    approach = waypoint_approach(_mission_record(), [(134, 33)])
    assert approach.waypoint == (134, 33)
    assert approach.min_heading_error < 1
    assert approach.min_range < approach.start_range - 100
    assert (approach.t_command, approach.t_end, approach.duration) == (300, 400, 100)
    assert approach.ended_by_command


def _short_waypoints_phase() -> MissionRecord:
    """WAYPOINTS for only 50 s, halfway to (134, 33), then POLYGON; the vehicle passes over the waypoint later."""
    record = MissionRecord()
    record.add_event(0, "moos", "DEPLOY_STATE", "WAYPOINTS", "gw")
    for t in range(0, 50):  # from (0, 190) halfway to the waypoint
        frac = t / 100
        record.add_nav(t, "NAV_X", 134 * frac)
        record.add_nav(t, "NAV_Y", 190 + (33 - 190) * frac)
        record.add_nav(t, "NAV_HEADING", 140.0)
    record.add_event(50, "moos", "POLYGON_UPDATES", "polygon=radial::x=0,y=0,radius=200,pts=6", "gw")
    record.add_event(50, "moos", "DEPLOY_STATE", "POLYGON", "gw")
    for t in range(50, 250):  # drifts on over the waypoint and past it, under the polygon command
        frac = t / 100
        record.add_nav(t, "NAV_X", 134 * frac)
        record.add_nav(t, "NAV_Y", 190 + (33 - 190) * frac)
        record.add_nav(t, "NAV_HEADING", 140.0)
    return record


def test_waypoint_approach_is_limited_to_the_waypoints_phase():
    record = _short_waypoints_phase()
    approach = waypoint_approach(record, [(134, 33)])
    assert (approach.t_command, approach.t_end, approach.duration) == (0, 50, 50)
    assert approach.ended_by_command
    start = math.hypot(134, 190 - 33)
    assert approach.start_range == pytest.approx(start)
    # Only the phase counts: halfway there at its end, although the vehicle passed over the waypoint at t=100.
    assert approach.min_range == pytest.approx(start * 0.5, abs=2)
    text = summary_text(MissionResult(record, 0.0), [(134, 33)])
    assert "waypoints phase t=0..50 s (50 s, until the next command)" in text, text
    assert "in 200 s" not in text and f"range {start:.0f} -> min {start * 0.5:.0f} m" in text, text
    # A last phase runs to the end of the record.
    only = MissionRecord()
    only.add_event(10, "moos", "DEPLOY_STATE", "WAYPOINTS", "gw")
    for t in range(10, 80):
        only.add_nav(t, "NAV_X", 0.0)
        only.add_nav(t, "NAV_Y", float(t))
    approach = waypoint_approach(only, [(0, 100)])
    assert (approach.t_end, approach.ended_by_command) == (79, False)
    assert "(69 s, until the end of the run)" in summary_text(MissionResult(only, 0.0), [(0, 100)])


def test_headings_are_shown_normalised_and_kept_raw_in_track_csv(tmp_path):
    assert [normalized_heading(h) for h in (0, 359.5, 360, 540, 765, -90, -1e-15)] == [0, 359.5, 0, 180, 45, 270, 0]
    record = MissionRecord()
    record.add_event(0, "moos", "DEPLOY_STATE", "WAYPOINTS", "gw")
    for t, heading in ((0, 400.0), (1, 540.0)):  # the basic simulator never wraps NAV_HEADING
        record.add_nav(t, "NAV_X", float(t))
        record.add_nav(t, "NAV_Y", 0.0)
        record.add_nav(t, "NAV_HEADING", heading)
    line = progress_line(record, 1.0, None)
    assert "hdg=180.0" in line and "540" not in line, line
    text = summary_text(MissionResult(record, 0.0), [(100, 0)])
    assert "last fix (1,0) heading 180 deg" in text and "540" not in text, text
    record.write_csv(tmp_path / "track.csv")
    assert [r["heading"] for r in csv.DictReader(open(tmp_path / "track.csv"))] == ["400.00", "540.00"]


def test_outputs_csv_and_png(tmp_path):
    record = shifted(_mission_record(), 100)
    record.write_csv(tmp_path / "track.csv", tmp_path / "events.csv")
    rows = list(csv.DictReader(open(tmp_path / "track.csv")))
    assert rows[0]["t"] == "-100.00" and rows[-1]["deploy_state"] == "POLYGON"
    assert any(r["deploy_state"] == "WAYPOINTS" for r in rows)
    write_track_png(tmp_path / "track.png", record.nav, [(e.t, e.value) for e in record.events], loiter_phases(record),
                    [(134, 33)], command_effects(record), "test")
    assert (tmp_path / "track.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# -- the record read from the loggers' files --------------------------------------------------------------------

WARP = 20
LOGSTART = 1_795_000_000.0 * WARP  # MOOS time (Unix time times the warp) when the alog was opened


def _write_logs(settings: UsvSettings) -> None:
    """What moos-logger and the two goby-loggers would have written for ``_mission_record()``'s mission, 50 s of
    interface start-up before it: the alog with every fix's NAV_* a millisecond apart (each posting has its own
    MOOS time) and the helm's repeated postings; the USV's .goby with the interface's states; the topside's with
    the satellite link's ack."""

    t0 = LOGSTART + 50.0  # the interface reaches COMMAND here: t=0 of the record
    record = _mission_record()
    session = data_log_dir(settings, "usv") / "usv_1_1_2027_____00_00_00"
    session.mkdir(parents=True)
    rows: list[tuple[float, str, str, float | str]] = []
    for s in record.nav:
        for i, (var, value) in enumerate((("NAV_X", s.x), ("NAV_Y", s.y), ("NAV_HEADING", s.heading),
                                          ("NAV_SPEED", 1.5))):
            if value is not None:
                rows.append((t0 + s.t + 0.001 * i, var, "moos-gateway", value))
    for e in record.events:
        rows.append((t0 + e.t, e.name, e.origin, e.value))
    for t in range(0, 600, 10):  # the helm's state, posted every iteration: one change only
        rows.append((t0 + t + 0.5, "IVPHELM_STATE", "pHelmIvP", "DRIVE"))
        rows.append((t0 + t + 0.5, "DESIRED_SPEED", "pHelmIvP", 1.5))  # not recorded
    with AlogWriter(session / "usv_1_1_2027_____00_00_00.alog", LOGSTART) as alog:
        for when, var, source, value in sorted(rows, key=lambda row: row[0]):
            alog.write(when, var, source, value)

    def goby(platform: str, entries: list[tuple[float, str, object]]) -> None:
        out = data_log_dir(settings, platform) / f"{platform}_20270101T000000.goby"
        out.parent.mkdir(parents=True, exist_ok=True)
        with open(out, "wb") as f:
            writer = LogWriter(f.write, lambda: 0)
            for when, group, message in entries:
                writer.write(message.SerializeToString(), Scheme.PROTOBUF, message.DESCRIPTOR.full_name, group,
                             round(when / WARP * 1e6))  # goby-logger runs on real time

    status = "goby::middleware::frontseat::status"
    goby("usv", [(LOGSTART + t, status, InterfaceStatus(state=state)) for t, state in
                 ((1, InterfaceState.INTERFACE_STANDBY), (20, InterfaceState.INTERFACE_STANDBY),
                  (50, InterfaceState.INTERFACE_COMMAND), (60, InterfaceState.INTERFACE_COMMAND))])
    ack = USVCommandAck(stage=USVCommandAck.LINK_ACKED, responder="satellite modem 2", slot_wait=2.5,
                        link_latency=3.25)
    goby("topside", [(t0 + 97.0, "goby3_course::usv_command_ack", ack)])


def test_the_record_is_read_from_the_loggers_files(tmp_path):
    settings = UsvSettings(run_dir=tmp_path / "run", warp=WARP)
    _write_logs(settings)
    record, paths = read_mission_logs(settings)
    assert sorted(p.suffix for p in paths) == [".alog", ".goby", ".goby"]
    command = next(e.t for e in record.events_named("interface_state") if e.value == "INTERFACE_COMMAND")
    assert command == pytest.approx(LOGSTART + 50.0, abs=1e-3)
    record = shifted(record, command)
    # one state event per change of the interface and the helm
    assert [(round(e.t), e.value) for e in record.events_named("interface_state")] == [
        (-49, "INTERFACE_STANDBY"), (0, "INTERFACE_COMMAND")]
    assert [e.value for e in record.events_named("IVPHELM_STATE")] == ["DRIVE"]
    assert record.events_named("DESIRED_SPEED") == []
    # one fix per NAV_* batch, as many as the hand-made record's, at the same places
    expected = _mission_record()
    assert len(record.nav) == len(expected.nav)
    assert [(round(s.x, 2), round(s.y, 2)) for s in record.nav] == [(round(s.x, 2), round(s.y, 2))
                                                                     for s in expected.nav]
    assert all(s.speed == 1.5 for s in record.nav)
    # and the same judgement as from the hand-made record
    effects = command_effects(record)
    assert [e.state for e in effects] == ["POLYGON", "WAYPOINTS", "POLYGON"]
    assert [round(e.t) for e in effects] == [100, 300, 400]
    first, second = loiter_phases(record)
    assert (round(first.start), round(first.end)) == (0, 300) and first.mean_distance < 15
    assert second.ring.center == pytest.approx((134, 33), abs=1)
    (link,) = link_acks(record)
    assert (round(link.t), link.acked, link.slot_wait, link.latency) == (97, True, 2.5, 3.25)
    text = summary_text(MissionResult(record, 0.0), [(134, 33)])
    assert "over the satellite link (5 s / 64 B slots): t=97 s acked: slot wait 2.5 s, ack after 3.2 s" in text, text
