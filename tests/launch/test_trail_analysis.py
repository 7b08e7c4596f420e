"""Trail analyses on hand-made records (and on hand-made logger files read back): relative geometry, trail errors, commands and their latency, RECOVER,
link counting from real ModemTransmission datagrams, the schedule and the picture."""

from __future__ import annotations

import math

import pytest
from google.protobuf import text_format

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission
from gateway.goby.log import LogWriter
from gateway.goby.portal import Scheme
from gateway.moos.alog import AlogWriter
from launch.errors import MissionConfigError
from launch.record import MissionRecord, NavSample
from launch.recorder import read_platform
from launch.trail.analysis import (
    angle_difference,
    command_outcomes,
    recover_outcome,
    relative_position,
    state_timeline,
    trail_performance,
    trail_point,
)
from launch.trail.links import LinkStats, _count
from launch.trail.mission import TrailResult
from launch.trail.operator import parse_trail_schedule
from launch.trail.plot import write_trail_png
from launch.trail.settings import Vehicle, acomms_mac_slots
from launch.trail.summary import summary_text


def _usv_east(record: MissionRecord, seconds: int = 300) -> None:
    for t in range(seconds):
        record.add_nav(float(t), "NAV_HEADING", 90.0)
        record.add_nav(float(t), "NAV_X", 1.5 * t)
        record.add_nav(float(t), "NAV_Y", 0.0)


def test_relative_geometry_follows_bhv_trail_conventions():
    usv = NavSample(0, 0, 0, heading=90.0)  # heading east
    rng, angle = relative_position(usv, NavSample(0, 0, -50))  # south of it: the starboard beam
    assert rng == pytest.approx(50) and angle == pytest.approx(90)
    x, y = trail_point(usv, 270)
    assert (x, y) == pytest.approx((0, 50))
    assert angle_difference(350, 10) == pytest.approx(20)


def test_trail_errors_settling_and_recover():
    usv, auv = MissionRecord(), MissionRecord()
    _usv_east(usv)
    vehicle = Vehicle("auv", 2, 0)  # angle 90 (starboard), depth 10
    for t in range(300):
        off = 100.0 if t < 50 else 55.0  # far at first, then 5 m outside the trail range
        auv.add_nav(float(t), "NAV_DEPTH", 10.0 if t >= 50 else 2.0)
        auv.add_nav(float(t), "NAV_X", 1.5 * t)
        auv.add_nav(float(t), "NAV_Y", -off)
    auv.add_event(250.0, "moos", "DEPLOY_DEPTH_UPDATES", "depth=0")
    auv.add_event(250.0, "moos", "AUV_DEPLOY_STATE", "RECOVER")
    perf = trail_performance(vehicle, auv, usv)
    assert perf.settled_at == pytest.approx(50)
    assert perf.range_error.mean == pytest.approx(5) and perf.angle_error.max == pytest.approx(0, abs=1e-6)
    assert perf.depth_error.max == pytest.approx(0) and perf.end == pytest.approx(250)
    outcome = recover_outcome("auv0", auv)
    assert outcome.commanded_at == 250 and outcome.depth_updates_first
    assert outcome.final_distance_to_station == pytest.approx(math.hypot(1.5 * 299 - 100, -55 + 100))


def test_commands_acks_and_latency():
    operator, usv, auv0 = MissionRecord(), MissionRecord(), MissionRecord()
    operator.add_event(10, "command", "sent", "polygon --sides 6 --radius 200", "topside")
    operator.add_event(18, "command", "ack", "polygon --sides 6 --radius 200", "modem 2")
    operator.add_event(100, "command", "sent", "waypoints", "topside")
    operator.add_event(200, "command", "sent", "recover", "usv")
    operator.add_event(260, "command", "expire", "recover", "EXPIRED_TIME_TO_LIVE_EXCEEDED")
    usv.add_event(15, "moos", "POLYGON_UPDATES", "polygon=radial::x=0,y=0,radius=200,pts=6")
    usv.add_event(15, "moos", "DEPLOY_STATE", "POLYGON")
    usv.add_event(130, "moos", "DEPLOY_STATE", "WAYPOINTS")
    auv0.add_event(240, "moos", "AUV_DEPLOY_STATE", "RECOVER")
    usv.add_event(0, "interface", "interface_state", "INTERFACE_STANDBY")
    usv.add_event(5, "interface", "interface_state", "INTERFACE_COMMAND")
    outcomes = command_outcomes(operator, {"usv": usv, "auv0": auv0, "auv1": MissionRecord()})
    assert [(c.acked_at, c.expired, c.arrived_at) for c in outcomes] == [
        (18, None, {"usv": 15}), (None, None, {"usv": 130}), (None, "EXPIRED_TIME_TO_LIVE_EXCEEDED", {"auv0": 240})]
    assert outcomes[1].latencies == [30]
    assert [(t, v) for t, w, v in state_timeline(usv) if w == "interface"] == [(0, "STANDBY"), (5, "COMMAND")]
    result = TrailResult(records={"usv": usv, "auv0": auv0}, command_times={"usv": 5, "auv0": None}, t0=0)
    text = summary_text(result, [], outcomes, [], None, 300, topside_view={"USV": 3})
    assert "3. recover: sent t=200, EXPIRED (EXPIRED_TIME_TO_LIVE_EXCEEDED); in MOOS: auv0 t=240 (+40 s)" in text
    assert "1. polygon --sides 6 --radius 200: sent t=10, acked t=18 (modem 2)" in text
    assert "mean 25.0 s, max 40.0 s over 3 arrivals" in text and "USV x3" in text


def test_link_counting_from_modem_transmissions():
    stats = LinkStats("acomms", acomms_mac_slots(2))
    data = ModemTransmission(src=2, dest=0, type=ModemTransmission.DATA, frame=[b"x" * 13, b"y" * 20])
    _count(stats, data.SerializeToString())
    _count(stats, ModemTransmission(src=3, dest=2, type=ModemTransmission.ACK, acked_frame=[0]).SerializeToString())
    _count(stats, ModemTransmission(src=3, type=ModemTransmission.DATA).SerializeToString())
    _count(stats, b"\xff\xff garbage")
    assert (stats.data_transmissions, stats.frames, stats.frame_bytes, stats.acks, stats.empty) == (1, 2, 33, 1, 1)
    assert stats.undecodable == 1
    assert stats.capacity_bytes(40) == pytest.approx(4 * 128)  # one 40 s cycle of four 128 B slots
    assert stats.saturation(40) == pytest.approx(33 / 512)


def test_schedule_parsing():
    plan = parse_trail_schedule("500:waypoints, 0:polygon:6:200, 900:recover")
    assert [(p.at, p.describe()) for p in plan] == [(0, "polygon --sides 6 --radius 200"), (500, "waypoints"),
                                                    (900, "recover")]
    assert parse_trail_schedule("none") == []
    with pytest.raises(MissionConfigError):
        parse_trail_schedule("x:recover")
    with pytest.raises(MissionConfigError):
        parse_trail_schedule("0:polygon:2:200")  # fewer sides than the DCCL minimum


def test_picture_is_written(tmp_path):
    usv, auv = MissionRecord(), MissionRecord()
    _usv_east(usv, 50)
    for t in range(50):
        auv.add_nav(float(t), "NAV_X", 1.5 * t)
        auv.add_nav(float(t), "NAV_Y", -50.0)
    perf = trail_performance(Vehicle("auv", 1, 0), auv, usv)
    path = tmp_path / "trail.png"
    write_trail_png(path, {"usv": usv, "auv0": auv}, [], [recover_outcome("auv0", auv)], [perf], "test")
    assert path.stat().st_size > 10_000


def test_trail_errors_and_topside_view_from_the_loggers_files(tmp_path):
    """The same judgement from the files the loggers write: the USV's and the AUV's alogs (moos-logger, MOOS times
    = Unix time x warp), the topside's .goby with the NodeStatus it republishes (goby-logger, real time)."""
    warp, logstart = 10, 1_795_000_000.0 * 10
    usv, auv = MissionRecord(), MissionRecord()
    _usv_east(usv)
    for t in range(300):
        off = 100.0 if t < 50 else 55.0
        auv.add_nav(float(t), "NAV_DEPTH", 10.0 if t >= 50 else 2.0)
        auv.add_nav(float(t), "NAV_X", 1.5 * t)
        auv.add_nav(float(t), "NAV_Y", -off)
    for name, record, depth in (("usv", usv, False), ("auv0", auv, True)):
        session = tmp_path / name / f"{name.upper()}_1_1_2027_____00_00_00"
        session.mkdir(parents=True)
        with AlogWriter(session / f"{session.name}.alog", logstart) as alog:
            for s in record.nav:
                for i, (var, value) in enumerate((("NAV_X", s.x), ("NAV_Y", s.y), ("NAV_HEADING", s.heading),
                                                  ("NAV_DEPTH", s.depth if depth else None))):
                    if value is not None:
                        alog.write(logstart + s.t + 0.002 * i, var, "goby::moos::Translator", value)
            if depth:
                alog.write(logstart + 250.0, "DEPLOY_DEPTH_UPDATES", "goby::moos::Translator", "depth=0")
                alog.write(logstart + 250.0, "AUV_DEPLOY_STATE", "goby::moos::Translator", "RECOVER")
    (tmp_path / "topside").mkdir()
    with open(tmp_path / "topside" / "topside_20270101T000000.goby", "wb") as f:
        writer = LogWriter(f.write, lambda: 0)
        for t in range(0, 300, 10):
            for name in ("USV", "AUV_0"):
                status = text_format.Parse(f'time: {t} name: "{name}" global_fix {{ lat: 0 lon: 0 }} pose {{ }} '
                                           f'local_fix {{ x: {1.5 * t} y: 0 }} speed {{ over_ground: 1.5 }}', NodeStatus())
                writer.write(status.SerializeToString(), Scheme.PROTOBUF, status.DESCRIPTOR.full_name,
                             "goby::middleware::frontseat::node_status", round((logstart + t) / warp * 1e6))
    read = {name: read_platform(tmp_path / name, name, warp, origin=logstart).record for name in ("usv", "auv0")}
    topside = read_platform(tmp_path / "topside", "topside", warp, moos=False, node_status=True, origin=logstart)
    assert [(e.t, e.value, e.origin) for e in topside.record.events[:2]] == [(0.0, "USV", "0,0"), (0.0, "AUV_0", "0,0")]
    assert len(topside.record.events_named("node_status", "topside")) == 60
    assert len(read["auv0"].nav) == 300 and len(read["usv"].nav) == 300  # one fix per NAV_* batch
    perf = trail_performance(Vehicle("auv", 2, 0), read["auv0"], read["usv"])
    assert perf.settled_at == pytest.approx(50, abs=0.01)
    assert perf.range_error.mean == pytest.approx(5, abs=0.01) and perf.depth_error.max == pytest.approx(0)
    assert perf.end == pytest.approx(250, abs=0.01)
    outcome = recover_outcome("auv0", read["auv0"])
    assert outcome.commanded_at == pytest.approx(250, abs=0.01) and outcome.depth_updates_first
