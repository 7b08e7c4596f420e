"""The node reporter: pNodeReporter's NODE_REPORT_LOCAL from NAV_*, as a library and as the ``node-reporter`` app."""

from __future__ import annotations

import sys
from pathlib import Path

from behaviors.node_reporter import NodeReporter, NodeReporterConfig
from gateway.moos import MoosClock
from gateway.moos.testing import connected_comms, running_moosdb
from translators.node_report_codec import parse_node_report
from util.process import ChildProcess, wait_until

NODE_REPORTER = Path(sys.executable).parent / "node-reporter"


def reporter(*pairs: tuple[str, str]) -> NodeReporter:
    return NodeReporter("auv0", NodeReporterConfig.from_pairs(list(pairs), "test.moos: ProcessConfig = pNodeReporter"))


def feed(rep: NodeReporter, now: float, **nav: float) -> None:
    for var, value in nav.items():
        rep.handle_mail(var, value, now)


def test_nothing_is_reported_until_the_record_is_valid_then_every_tick():
    rep = reporter(("platform_type", "auv"), ("platform_color", "yellow"), ("platform_length", "2"))
    assert rep.iterate(10.0) == []
    feed(rep, 10.0, NAV_X=1.0, NAV_Y=-2.0, NAV_SPEED=1.5)
    assert rep.iterate(10.5) == []  # no heading yet
    feed(rep, 11.0, NAV_HEADING=-90.0, NAV_DEPTH=10.0)
    first = rep.iterate(11.25)
    report = "NAME=auv0,X=1,Y=-2,SPD=1.5,HDG=270,DEP=10,TYPE=auv,COLOR=yellow,MODE=NOHELM-EVER,ALLSTOP=unknown," \
             "TIME=11.25,LENGTH=2"
    assert first == [("NODE_REPORT_LOCAL_FIRST", report), ("NODE_REPORT_LOCAL", report)]
    second = rep.iterate(11.5)
    assert [var for var, _ in second] == ["NODE_REPORT_LOCAL"]
    assert ",INDEX=1," in second[0][1] and ",TIME=11.5," in second[0][1]


def test_mode_and_allstop_follow_the_helm():
    rep = reporter(("platform_type", "usv"))
    feed(rep, 0.0, NAV_X=0.0, NAV_Y=0.0, NAV_SPEED=0.0, NAV_HEADING=0.0, NAV_LAT=43.8, NAV_LONG=-70.3, NAV_YAW=0.0)
    rep.handle_mail("IVPHELM_STATE", "DRIVE", 1.0)
    rep.handle_mail("IVPHELM_ALLSTOP", "clear", 1.0)
    fields = parse_node_report(rep.iterate(2.0)[-1][1])
    assert (fields.mode, fields.allstop, fields.length) == ("DRIVE", "clear", 6.0)  # usv: pNodeReporter's 6 m guess
    assert (fields.lat, fields.lon, fields.yaw) == (43.8, -70.3, 1.5707963)
    rep.handle_mail("IVPHELM_SUMMARY", "iter=3,var=speed:1,modes=MODE@ACTIVE:LOITERING,active_bhvs=x", 3.0)
    assert parse_node_report(rep.iterate(3.0)[-1][1]).mode == "MODE@ACTIVE:LOITERING"
    assert parse_node_report(rep.iterate(10.4)[-1][1]).mode == "NOHELM-7"
    rep.handle_mail("IVPHELM_STATE", "MALCONFIG", 11.0)
    fields = parse_node_report(rep.iterate(11.0)[-1][1])
    assert (fields.mode, fields.allstop) == ("MALCONFIG", "n/a")
    rep.handle_mail("PNR_PAUSE", "true", 12.0)
    assert rep.iterate(12.0) == []


def test_config_names_and_problems():
    cfg = NodeReporterConfig.from_pairs([("vessel_type", "glider"), ("node_report_output", "MY_REPORT"),
                                         ("terse_reports", "true"), ("group", "blue"), ("AppTick", "2"),
                                         ("blackout_interval", "5"), ("platform_length", "long")], "f.moos: B")
    assert (cfg.platform_type, cfg.output, cfg.terse, cfg.group, cfg.app_tick) == ("glider", "MY_REPORT", True,
                                                                                   "blue", 2.0)
    assert cfg.platform_length == 3.0  # the glider guess, since "long" is refused
    assert cfg.problems == ["f.moos: B: unhandled or bad parameter 'blackout_interval = 5'",
                            "f.moos: B: unhandled or bad parameter 'platform_length = long'"]
    assert NodeReporterConfig.from_pairs([("platform_type", "blimp")], "f").problems == [
        "f: unrecognized platform type 'blimp'"]


MISSION = """\
ServerHost = 127.0.0.1
ServerPort = {port}
Community  = trail_usv
MOOSTimeWarp = {warp}
LatOrigin  = 43.8253
LongOrigin = -70.3304

ProcessConfig = pNodeReporter
{{
  AppTick        = 10
  CommsTick      = 10
  platform_type   = usv
  platform_color  = green
  platform_length = 4
}}
"""


def test_the_app_reports_a_vehicle_from_its_moosdb(tmp_path):
    warp = 10.0
    clock = MoosClock(warp)
    with running_moosdb("trail_usv", warp=warp) as db:
        mission = tmp_path / "usv.moos"
        mission.write_text(MISSION.format(port=db.port, warp=warp))
        with ChildProcess([str(NODE_REPORTER), str(mission), "-v"], tmp_path / "reporter.log"), \
                connected_comms(db.port, "uSim", register=["NODE_REPORT_LOCAL", "NODE_REPORT_LOCAL_FIRST"]) as sim:
            reports: list[str] = []

            def two_reports() -> bool:
                for var, value in (("NAV_X", 12.345), ("NAV_Y", -6.0), ("NAV_HEADING", 370.0),
                                   ("NAV_SPEED", 1.5), ("NAV_DEPTH", 0.0)):
                    sim.notify(var, value)
                reports.extend(m.string() for m in sim.fetch() if m.key() == "NODE_REPORT_LOCAL")
                return len(reports) >= 2

            wait_until(two_reports, 20, "two NODE_REPORT_LOCAL")
    fields = parse_node_report(reports[-1])
    assert reports[-1].startswith("NAME=trail_usv,X=12.35,Y=-6,SPD=1.5,HDG=10,DEP=0,TYPE=usv,COLOR=green,")
    assert fields.index >= 1 and fields.length == 4
    assert abs(fields.time - clock.time()) < 30 * warp  # MOOS (warped) time
