"""Config generation: every generated config parses into its real config message, and all agree."""

from __future__ import annotations

import subprocess
import sys

import pytest
from google.protobuf import text_format

import frontseat.protobuf.basic_simulator_config_pb2 as basic_sim_pb
import frontseat.protobuf.basic_simulator_tuning_pb2 as tuning_pb
import frontseat.protobuf.moos_helm_frontseat_interface_config_pb2 as moos_helm_pb
from frontseat.protobuf.frontseat_config_pb2 import Config
from frontseat.protobuf.frontseat_interface_config_pb2 import FrontSeatInterfaceConfig
from gateway.goby.acomms.protobuf import udp_multicast_driver_pb2 as udp_multicast_pb
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.moos.mission_file import MissionFile
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from launch.errors import MissionConfigError
from launch.launchfile import parse_file
from launch.usv.config import GENERATORS, generate, write_moos_file
from launch.usv.demo import command_env, command_lines
from launch.usv.mission import LAUNCH_FILE, choose_program
from launch.usv.settings import UsvSettings
from launch.usv.shore import parse_schedule
from translators.usv.protobuf.usv_config_pb2 import CommandTool, USVManager

PB_APPS = {
    "broker": GobyDaemonConfig,
    "frontseat_interface": FrontSeatInterfaceConfig,
    "moos_gateway": GobyMOOSGatewayConfig,
    "usv_manager": USVManager,
    "shore": CommandTool,
    "topside_broker": GobyDaemonConfig,
}
TOPSIDE_APPS = {"shore", "topside_broker"}  # on the shore's own broker


@pytest.fixture
def settings(tmp_path):
    return UsvSettings(run_dir=tmp_path, warp=17, lat_origin=41.5, lon_origin=-70.7, moos_port=9123,
                       sim_port=55123, socket_name=str(tmp_path / "goby_usv"))


def test_every_goby_config_parses_and_agrees_on_warp_origin_and_broker(settings):
    for app, config_type in PB_APPS.items():
        cfg = text_format.Parse(generate(app, settings), config_type())
        assert cfg.app.simulation.time.use_sim_time, app
        assert cfg.app.simulation.time.warp_factor == 17, app
        assert (cfg.app.geodesy.lat_origin, cfg.app.geodesy.lon_origin) == (41.5, -70.7), app
        if app in TOPSIDE_APPS:
            assert cfg.interprocess.platform == "topside", app
            assert cfg.interprocess.socket_name == settings.topside_ipc_base, app
        else:
            assert cfg.interprocess.platform == "usv", app
            assert cfg.interprocess.socket_name == settings.ipc_base, app


def test_topside_and_usv_share_the_course_satellite_link(settings):
    settings = settings.replace(sat_port=47123)
    links = {}
    for app in ("broker", "topside_broker"):
        cfg = text_format.Parse(generate(app, settings), GobyDaemonConfig())
        (link,) = cfg.intervehicle.link
        udp = link.driver.Extensions[udp_multicast_pb.config]
        assert (udp.multicast_address, udp.multicast_port) == ("239.142.0.2", 47123), app
        assert [(s.src, s.slot_seconds, s.max_frame_bytes) for s in link.mac.slot] == [(1, 5, 64), (2, 5, 64)]
        assert link.subnet_mask == 0xFF00
        links[app] = link.modem_id
    assert links == {"topside_broker": 1, "broker": 2}
    assert text_format.Parse(generate("shore", settings), CommandTool()).intervehicle
    vehicle = text_format.Parse(generate("vehicle_interprocess", settings), InterProcessPortalConfig())
    assert (vehicle.platform, vehicle.socket_name) == ("usv", settings.ipc_base)


def test_frontseat_and_gateway_point_at_the_same_moosdb_and_simulator(settings):
    fs = text_format.Parse(generate("frontseat_interface", settings), FrontSeatInterfaceConfig())
    helm = fs.Extensions[moos_helm_pb.moos_helm]
    sim = fs.frontseat_cfg.Extensions[basic_sim_pb.basic_simulator_config]
    gw = text_format.Parse(generate("moos_gateway", settings), GobyMOOSGatewayConfig())
    assert helm.port == gw.moos.port == 9123
    assert sim.tcp_port == int(generate("frontseat_sim", settings)) == 55123
    assert (sim.start.lat, sim.start.lon) == (41.5, -70.7)
    # the course's 10 s, stretched to three real seconds at this warp
    assert fs.frontseat_cfg.helm_running_timeout == fs.frontseat_cfg.frontseat_connected_timeout == 51
    # our driver's data timeout travels on the command line (the file holds Goby3's fields only)
    tuning = text_format.Parse(generate("frontseat_tuning", settings), Config())
    assert tuning.Extensions[tuning_pb.basic_simulator_tuning].data_timeout == 51


def test_moos_file_matches_the_goby_side(settings):
    mission = MissionFile(write_moos_file(settings))
    assert mission.server_port == 9123
    assert mission.time_warp == 17
    assert (float(mission.lat_origin), float(mission.long_origin)) == (41.5, -70.7)
    helm = dict((k.lower(), v) for k, v in mission.process_config("pHelmIvP"))
    assert helm["behaviors"] == str(settings.bhv_file)


def test_settings_round_trip_through_the_environment(settings):
    assert UsvSettings.from_env(settings.to_env()) == settings
    with pytest.raises(MissionConfigError, match="USV_WARP='fast' is not a valid int"):
        UsvSettings.from_env({"USV_WARP": "fast"})
    with pytest.raises(MissionConfigError, match="warp must be"):
        UsvSettings(warp=0)


def test_the_config_script_prints_configs_and_fails_loudly(settings):
    env = settings.to_env()
    ok = subprocess.run([sys.executable, "-m", "launch.usv.config", "moos_gateway"], capture_output=True, text=True,
                        env={**env, "PATH": "/usr/bin:/bin"}, timeout=60)
    assert ok.returncode == 0 and "port: 9123" in ok.stdout
    bad = subprocess.run([sys.executable, "-m", "launch.usv.config", "nope"], capture_output=True, text=True,
                         env=env, timeout=60)
    assert bad.returncode == 1
    assert "INVALID CONFIGURATION" in bad.stdout  # what a process-substituted app would read
    assert "App: nope not defined" in bad.stderr
    assert set(GENERATORS) >= {"broker", "moos", "frontseat_sim"}


def test_launch_file_has_every_component_in_order():
    entries = parse_file(LAUNCH_FILE).entries
    commands = " | ".join(e.command for e in entries)
    for piece in ("frontseat-sim", "goby-broker", "USV_MOOSDB", "USV_HELM", "frontseat-interface", "moos-gateway",
                  "usv-manager", "launch.usv.shore"):
        assert piece in commands
    env = {k: v for e in entries for k, v in e.env}
    assert env["FRONTSEAT_DRIVER_LIBRARY"] == "basic_simulator"
    assert env["GOBY_MOOS_GATEWAY_PLUGINS"] == "translators.usv.command_translation"


def test_schedule_parsing():
    plan = parse_schedule("500:waypoints, 0:polygon:6:200,800:POLYGON:8:400")
    assert [(c.at, c.args) for c in plan] == [
        (0.0, ("polygon", "--sides", "6", "--radius", "200")),
        (500.0, ("waypoints",)),
        (800.0, ("polygon", "--sides", "8", "--radius", "400")),
    ]
    for bad in ("x:waypoints", "10:polygon:6", "10:circle", "-5:waypoints", "10:loiter", "nan:waypoints",
                "0:polygon:2:200", "0:polygon:6:5000"):  # the last two are outside the USVCommand's DCCL bounds
        with pytest.raises(MissionConfigError, match="bad schedule entry"):
            parse_schedule(bad)


def test_an_explicitly_empty_schedule_is_none_and_blank_ones_are_refused():
    assert parse_schedule("none") == [] and parse_schedule(" None ") == []
    for blank in ("", " "):
        with pytest.raises(MissionConfigError, match="empty schedule .* none for no commands"):
            parse_schedule(blank)
    for gap in ("0:waypoints,,500:waypoints", "0:waypoints,"):
        with pytest.raises(MissionConfigError, match="empty entry"):
            parse_schedule(gap)


def test_the_shore_refuses_a_bad_schedule_and_runs_with_none(tmp_path):
    bad = subprocess.run([sys.executable, "-m", "launch.usv.shore", "--schedule", "10:loiter"],
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "bad schedule entry '10:loiter'" in bad.stderr, bad.stderr
    # USV_SHORE_SCHEDULE=none reaches the shore as none (an empty value would mean "unset": the default plan).
    env = UsvSettings(run_dir=tmp_path, schedule="none").to_env()
    assert UsvSettings.from_env(env).schedule == "none"
    assert parse_schedule(UsvSettings.from_env(env | {"USV_SHORE_SCHEDULE": ""}).schedule) != []


def test_choosing_real_or_our_programs(monkeypatch):
    monkeypatch.setenv("PATH", "/nonexistent")
    assert choose_program("auto", "MOOSDB", "moos-db") == "moos-db"
    assert choose_program("ours", "MOOSDB", "moos-db") == "moos-db"
    with pytest.raises(MissionConfigError, match="MOOSDB was asked for but is not on PATH"):
        choose_program("real", "MOOSDB", "moos-db")


@pytest.mark.parametrize("long_run_dir", [False, True], ids=["socket-in-run-dir", "socket-elsewhere"])
def test_the_printed_command_environment_reproduces_the_runs_usv_command_config(tmp_path, long_run_dir):
    run_dir = tmp_path / ("x" * 90 if long_run_dir else "") / "run"
    socket_name = str(tmp_path / "s" / "goby_usv") if long_run_dir else str(run_dir / "goby_usv")
    settings = UsvSettings(run_dir=run_dir, warp=37, lat_origin=41.5, lon_origin=-70.7, moos_port=9123,
                           sim_port=55123, socket_name=socket_name)
    env = command_env(settings)
    assert ("USV_SOCKET_NAME" in env) == long_run_dir
    # What a user's shell rebuilds from the exported variables alone (nothing else of the run's environment).
    assert generate("usv_command", UsvSettings.from_env(env)) == generate("usv_command", settings)
    export, waypoints, polygon = command_lines(settings)
    assert export.startswith("export USV_RUN_DIR=") and "USV_WARP=37" in export
    assert waypoints.split()[1:] == ["waypoints", "<(" + sys.executable, "-m", "launch.usv.config", "usv_command)"]
    assert "polygon --sides 8 --radius 400 <(" in polygon


def test_liaison_web_settings_travel_on_the_command_line(settings, tmp_path):
    # the file keeps Goby3's LiaisonConfig fields (the real goby_liaison accepts it); --web carries our extension
    from gateway.goby.portal.config import load_config
    from gateway.goby.portal.errors import AppConfigError
    from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig
    from launch.liaison.protobuf.liaison_web_pb2 import web

    path = tmp_path / "liaison.pb.cfg"
    path.write_text(generate("liaison", settings))
    assert not text_format.Parse(path.read_text(), LiaisonConfig()).HasExtension(web)
    cfg = load_config(LiaisonConfig, [str(path), "--web", generate("liaison_web", settings)], environ={}).cfg
    extra = cfg.Extensions[web]
    assert extra.map.center_activate and len(extra.map.waypoint) >= 1
    assert extra.interprocess_ack[0].command_type == "goby3_course.dccl.USVCommand"
    assert cfg.http_port == settings.liaison_port
    with pytest.raises(AppConfigError, match="--web"):
        load_config(LiaisonConfig, [str(path), "--web", "map { no_such_field: 1 }"], environ={})


def test_the_topside_liaison_commands_over_the_satellite_link(settings):
    """The course's topside page: on the topside's broker, USVCommand on intervehicle group 0 (checked by
    goby-liaison's own settings loader, as at start)."""
    from gateway.goby.protobuf.layer_pb2 import LAYER_INTERVEHICLE
    from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig
    from launch.liaison.settings import load_settings

    cfg = text_format.Parse(generate("topside_liaison", settings.replace(topside_liaison_port=50000)),
                            LiaisonConfig())
    assert cfg.interprocess.platform == "topside" and cfg.interprocess.socket_name == settings.topside_ipc_base
    assert cfg.http_port == 50000
    (kind,) = load_settings(cfg).command_types
    assert kind.name == "goby3_course.dccl.USVCommand"
    assert [(t.layer, t.label) for t in kind.targets] == [
        (LAYER_INTERVEHICLE, "goby3_course::usv_command/0 [intervehicle]")]
    assert "topside_liaison" in " ".join(e.command for e in parse_file(LAUNCH_FILE).entries)
