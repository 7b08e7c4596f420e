"""The map's model: the helm's objective drawn from what the helm posts, the topside's model of it, the page's
lat/lon polynomial against the project's UTM, the AUVs from their acoustic reports, and every bound on input."""

from __future__ import annotations

import math

import pytest

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus, VehicleType
from launch.liaison import map_model
from launch.liaison.map_model import MAX_HELM_VIEWS, MapModel, geo_polynomial, parse_helm_view
from launch.usv.geometry import radial_polygon
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from util.geodesy import UTMGeodesy

SQUARE = [(-100.0, -100.0), (100.0, -100.0), (100.0, 100.0), (-100.0, 100.0)]


def status(name: str, x: float, y: float, kind: int = VehicleType.USV, geodesy: UTMGeodesy | None = None) -> bytes:
    msg = NodeStatus(name=name, type=kind, time=1.0)
    msg.local_fix.x, msg.local_fix.y = x, y
    msg.global_fix.lat, msg.global_fix.lon = (geodesy or UTMGeodesy(41.5, -70.6)).to_geo(x, y)
    msg.pose.heading, msg.speed.over_ground = 90.0, 1.5
    return msg.SerializeToString()


def polygon_command(t: float, sides: int = 6, radius: int = 300) -> bytes:
    return USVCommand(time=t, desired_state=USVCommand.POLYGON, polygon_sides=sides,
                      polygon_radius=radius).SerializeToString()


def ring(x: float, y: float, radius: float, sides: int) -> list[list[float]]:
    return [[round(a, 1), round(b, 1)] for a, b in radial_polygon(x, y, radius, sides).vertices]


@pytest.mark.parametrize(("lat", "lon", "within_m", "error_m"), [
    (41.5, -70.6, 5_000, 0.002), (41.5, -70.6, 10_000, 0.02), (70.0, 20.0, 10_000, 0.08), (-33.9, 151.2, 10_000, 0.02)])
def test_the_pages_lat_lon_follows_the_projects_utm(lat, lon, within_m, error_m) -> None:
    geo = geo_polynomial(lat, lon)
    utm = UTMGeodesy(lat, lon)
    worst = 0.0
    for k in range(24):
        angle = k * math.pi / 12
        x, y = within_m * math.cos(angle), within_m * math.sin(angle)
        terms = (1, x, y, x * x, x * y, y * y)
        page = (sum(c * t for c, t in zip(geo["lat_terms"], terms, strict=True)),
                sum(c * t for c, t in zip(geo["lon_terms"], terms, strict=True)))
        back = utm.to_local(*page)
        worst = max(worst, math.hypot(back[0] - x, back[1] - y))
    assert worst < error_m, worst


def test_the_datum_is_derived_from_a_fix_with_both_positions() -> None:
    utm = UTMGeodesy(41.52, -70.68)
    model = MapModel([], [])
    model.ingest_node_status("usv", status("usv", 1234.0, -567.0, geodesy=utm))
    update = model.tick()
    assert update is not None and update["geo"] is not None
    assert update["geo"]["lat"] == pytest.approx(41.52, abs=1e-9)
    assert update["geo"]["lon"] == pytest.approx(-70.68, abs=1e-9)


def test_the_helms_polygon_is_drawn_not_the_command() -> None:
    """With the MOOSDB read, the ring is the helm's VIEW_POLYGON and the mode its DEPLOY_STATE; a command alone
    changes nothing drawn."""
    model = MapModel([], SQUARE, center_activate=True, helm_views=True, initial_mode="POLYGON")
    model.ingest_node_status("usv", status("usv", 500.0, 500.0))
    model.ingest_moos("DEPLOY_STATE", "POLYGON")
    model.ingest_moos("VIEW_POLYGON", "pts={0,200:173.2,100:173.2,-100:0,-200:-173.2,-100:-173.2,100},label=usv_polygon")
    update = model.tick()
    assert update is not None and update["polygon_source"] == "helm" and update["mode_source"] == "helm"
    assert update["polygon"][0] == [0.0, 200.0] and len(update["polygon"]) == 6
    model.ingest_command(polygon_command(10.0, sides=8, radius=400))
    model.tick()
    assert model.snapshot()["polygon"][0] == [0.0, 200.0]  # not what was sent
    model.ingest_moos("VIEW_POLYGON", "radial:: x=0,y=0,radius=400,pts=8,label=usv_polygon")
    assert model.tick()["polygon"] == ring(0, 0, 400, 8)
    model.ingest_moos("VIEW_POINT", "x=12.5,y=-3,active=true,label=usv_wpt")
    assert model.tick()["views"] == [{"kind": "point", "label": "usv_wpt", "points": [[12.5, -3.0]]}]
    model.ingest_moos("VIEW_POINT", "x=12.5,y=-3,active=false,label=usv_wpt")
    assert model.tick()["views"] == []  # erased


def test_without_the_helm_a_polygon_while_in_polygon_keeps_the_commands_centre() -> None:
    """The topside's model of BHV_Loiter (issue 29's defect): re-centred on the vehicle only when the loiter
    becomes active (center_activate); a POLYGON while in POLYGON is where the translator put it (x=0,y=0)."""
    model = MapModel([], SQUARE, center_activate=True, initial_mode="POLYGON")
    assert model.snapshot()["mode"] == "polygon"  # "Mode: unknown" no more
    model.ingest_node_status("usv", status("usv", 500.0, 500.0))
    model.tick()
    model.ingest_command(polygon_command(10.0))
    update = model.tick()
    assert update["polygon"] == ring(0, 0, 300, 6) and update["polygon_source"] == "command"
    model.ingest_command(USVCommand(time=20.0, desired_state=USVCommand.WAYPOINTS).SerializeToString())
    assert model.tick()["mode"] == "waypoints"
    model.ingest_command(polygon_command(30.0, sides=4, radius=200))  # activates the loiter: centred on the boat
    assert model.tick()["polygon"] == ring(500, 500, 200, 4)


@pytest.mark.parametrize(("variable", "text", "why"), [
    ("VIEW_POLYGON", "radial:: x=0,y=0,radius=10,pts=3000000,label=a", "pts in [3, 360]"),
    ("VIEW_POLYGON", "pts={" + ":".join(["1,1"] * 5000) + "},label=a", "characters"),
    ("VIEW_POLYGON", "pts={0,0:1e300,0:0,1e300},label=a", "out-of-range"),
    ("VIEW_SEGLIST", "pts={nan,0:1,1},label=a", "out-of-range"),
    ("VIEW_POINT", "x=abc,y=1,label=a", "x= and y="),
])
def test_bad_helm_views_are_refused_with_a_reason(variable, text, why) -> None:
    reason = parse_helm_view(variable, text)
    assert isinstance(reason, str) and why in reason, reason
    model = MapModel([], [], helm_views=True)
    model.ingest_moos(variable, text)
    model.tick()
    assert model.refused["helm-view"] == 1 and model.snapshot()["views"] == []


def test_helm_views_are_capped() -> None:
    model = MapModel([], [], helm_views=True)
    for i in range(MAX_HELM_VIEWS + 10):
        model.ingest_moos("VIEW_POINT", f"x={i},y=0,label=p{i}")
    model.tick()
    assert len(model.snapshot()["views"]) == MAX_HELM_VIEWS and model.refused["too-many-views"] == 10
    model.ingest_moos("DEPLOY_STATE", "SURVEY")
    model.tick()
    assert model.refused["deploy-state"] == 1


def test_the_auvs_come_from_their_acoustic_reports(monkeypatch) -> None:
    model = MapModel([], [])
    auv = NavigationReport(vehicle=3, time=1.0, x=-40.0, y=25.0, z=-5.0, speed_over_ground=1.2, heading=270.0,
                           type=NavigationReport.AUV)
    usv = NavigationReport(vehicle=1, time=1.0, x=1.0, y=1.0, z=0.0, speed_over_ground=1.0, heading=0.0,
                           type=NavigationReport.USV)
    model.ingest_nav_report("goby3_course::auv_nav", auv.SerializeToString())
    model.ingest_nav_report("goby3_course::usv_nav", usv.SerializeToString())
    update = model.tick()
    assert [(v["name"], v["type"], v["x"], v["y"]) for v in update["vehicles"]] == [("AUV_1", "AUV", -40.0, 25.0)]
    model.ingest_nav_report("goby3_course::auv_nav", b"\xff\xff")
    model.tick()
    assert model.refused["unparsable"] == 1
    monkeypatch.setattr(map_model, "MAX_COORDINATE_M", 10.0)
    model.ingest_nav_report("goby3_course::auv_nav", auv.SerializeToString())
    model.tick()
    assert model.refused["non-finite"] == 1


@pytest.mark.parametrize(("map_text", "named"), [
    ('initial_mode: "SURVEY"', "map.initial_mode"),
    ("datum_lat: 41.5", "datum_lat and datum_lon go together"),
    ("datum_lat: 89 datum_lon: 0", "outside UTM's range"),
    ("moos { port: 70000 }", "map.moos.port"),
    ('background { image: "/nonexistent.png" lat_north: 1 lat_south: 0 lon_east: 1 lon_west: 0 }',
     "map.background.image"),
    ('replay_dir: "/etc/hostname"', "map.replay_dir[0]"),
    ("replay_max_samples: 10", "map.replay_max_samples"),
])
def test_bad_map_settings_are_named(map_text, named) -> None:
    from google.protobuf import text_format

    from launch.liaison.errors import LiaisonConfigError
    from launch.liaison.protobuf import liaison_web_pb2  # noqa: F401 - the [..web] extension
    from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig
    from launch.liaison.settings import load_settings

    cfg = text_format.Parse(f"[goby_moos_py.liaison.protobuf.web] {{ map {{ {map_text} }} }}", LiaisonConfig())
    with pytest.raises(LiaisonConfigError, match=named.replace("[", r"\[").replace("]", r"\]")):
        load_settings(cfg)
