"""NODE_REPORT as the course's AUVs use it: the real pHelmIvP (when on PATH) trails a contact it only knows
from our NODE_REPORT lines, so the format is checked by the parser that matters."""

from __future__ import annotations

import shutil
import time

import pytest
from translator_procs import ORIGIN, start_child

from behaviors.testing import write_helm_mission
from frontseat import groups
from frontseat.protobuf.frontseat_data_pb2 import USV, NodeStatus
from gateway.goby.portal.testing import PortalClient, broker_process
from gateway.moos.testing import connected_comms, running_moosdb
from translators.node_report import NodeReportTranslation
from translators.testing import gateway_config, hosted_translators
from util.geodesy import UTMGeodesy

TIMEOUT_S = 60.0

BHV = """
initialize MOOS_MANUAL_OVERRIDE = false

Behavior = BHV_Trail
{
  name             = trail_usv
  pwt              = 100
  contact          = USV
  trail_range      = 50
  trail_angle      = 180
  trail_angle_type = relative
  radius           = 5
  nm_radius        = 20
  on_no_contact_ok = true
}
"""

def usv_status(geodesy: UTMGeodesy, x: float, y: float, heading: float) -> NodeStatus:
    status = NodeStatus(time=time.time(), name="USV", type=USV)
    status.global_fix.lat, status.global_fix.lon = geodesy.to_geo(x, y)
    status.pose.heading = heading
    status.speed.over_ground = 1.5
    return status


def test_real_phelmivp_trails_a_contact_known_only_from_our_node_report(tmp_path):
    if shutil.which("pHelmIvP") is None:
        pytest.skip("the real pHelmIvP is not on PATH")
    geodesy = UTMGeodesy(*ORIGIN)
    bhv = tmp_path / "auv.bhv"
    bhv.write_text(BHV)
    with running_moosdb(community="auv0") as db, broker_process(tmp_path, platform="auv0") as broker:
        cfg = gateway_config(db.port, broker.interprocess_config())
        cfg.app.geodesy.lat_origin, cfg.app.geodesy.lon_origin = ORIGIN
        mission = write_helm_mission(tmp_path, db.port, bhv, community="auv0", max_speed="4", origin=ORIGIN,
                                     name="auv.moos")
        helm = start_child("pHelmIvP", ["pHelmIvP", str(mission)], tmp_path)
        try:
            with hosted_translators(cfg, NodeReportTranslation), \
                    connected_comms(db.port, "auv_nav", register=["DESIRED_HEADING", "DESIRED_SPEED",
                                                                   "NODE_REPORT"]) as nav, \
                    PortalClient(broker.interprocess_config(), name="usv_source") as client:
                assert client.wait_subscribed()
                latest: dict[str, object] = {}
                deadline = time.monotonic() + TIMEOUT_S
                # Ownship at the origin heading north; the USV 200 m east heading east: the trail point (50 m
                # behind it) is due east, so a helm that parsed the contact steers about 90 degrees.
                while not (latest.get("DESIRED_SPEED", 0) > 0 and "NODE_REPORT" in latest):
                    assert helm.running, helm.output()
                    assert time.monotonic() < deadline, f"pHelmIvP never trailed the contact: {latest}\n" \
                        f"{helm.output()[-3000:]}"
                    for name, value in (("NAV_X", 0.0), ("NAV_Y", 0.0), ("NAV_HEADING", 0.0), ("NAV_SPEED", 0.0),
                                        ("NAV_DEPTH", 0.0)):
                        nav.notify(name, value)
                    client.publish(groups.node_status, usv_status(geodesy, 200.0, 0.0, 90.0))
                    client.poll(0.25)
                    for msg in nav.fetch():
                        latest[msg.key()] = msg.double() if msg.is_double() else msg.string()
        finally:
            helm.stop(10)
    assert str(latest["NODE_REPORT"]).startswith("NAME=USV,TYPE=USV,TIME=")
    assert abs(float(latest["DESIRED_HEADING"]) - 90.0) <= 15.0, latest
