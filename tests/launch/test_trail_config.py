"""Trail mission config generation and launch files: every config parses into its real message, ids and ports
are the course's, bad input fails the course's way, MOOS files come and go with moos_gen."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from google.protobuf import text_format

import frontseat.protobuf.basic_simulator_config_pb2  # noqa: F401 - registers the extensions the configs use
import frontseat.protobuf.moos_helm_frontseat_interface_config_pb2  # noqa: F401
import launch.liaison.protobuf.liaison_web_pb2  # noqa: F401
from behaviors.protobuf.goby_helm_example_config_pb2 import Helm
from frontseat.protobuf.frontseat_interface_config_pb2 import FrontSeatInterfaceConfig
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.moos.mission_file import MissionFile
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from launch.config import INVALID_BANNER
from launch.errors import MissionConfigError
from launch.launchfile import parse_file
from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig
from launch.trail.config import ALIASES, GENERATORS, broker_hosts_intervehicle, generate
from launch.trail.generate_all_launch import all_launch_text
from launch.trail.settings import (
    TRAIL_DIR,
    TrailSettings,
    Vehicle,
    acomms_mac_slots,
    auv_modem_ids,
    vehicle_from_env,
)
from translators.usv.protobuf.usv_config_pb2 import CommandTool, USVManager

N = 4


@pytest.fixture
def settings(tmp_path):
    return TrailSettings(run_dir=tmp_path, warp=7, moos_port_base=19000)


def _vehicles(n: int = N) -> list[Vehicle]:
    return [Vehicle("topside", n), Vehicle("usv", n), *(Vehicle("auv", n, i) for i in range(n))]


def test_ids_and_ports_follow_the_course_table(settings):
    course = TrailSettings()
    table = {(v.name, v.vehicle_id, v.satellite_modem_id if "satellite" in v.links else None,
              v.acomms_modem_id if "acomms" in v.links else None, v.moos_port(course), v.sim_port(course),
              v.liaison_port(course), v.community) for v in _vehicles()}
    topside = Vehicle("topside", N)
    assert (topside.vehicle_id, topside.satellite_modem_id, topside.liaison_port(course)) == (0, 1, 50000)
    assert ("usv", 1, 2, 258, 9001, 55001, 50001, "trail_usv") in table
    for i in range(N):
        assert (f"auv{i}", i + 2, None, 259 + i, 9002 + i, 55002 + i, 50002 + i, f"AUV{i}") in table
    assert [Vehicle("auv", N, i).trail_angle for i in range(N)] == [90, 150, 210, 270]
    assert [Vehicle("auv", N, i).deploy_depth for i in range(N)] == [10, 20, 30, 40]
    assert Vehicle("auv", 1, 0).trail_angle == 180  # the course divides by zero here
    assert auv_modem_ids(N) == [259, 260, 261, 262]
    assert acomms_mac_slots(2) == [(258, 10, 128), (259, 10, 128), (258, 10, 128), (260, 10, 128)]
    assert acomms_mac_slots(0) == []


@pytest.mark.parametrize("vehicle", _vehicles(), ids=lambda v: v.name)
def test_every_goby_config_parses_into_its_message(settings, vehicle):
    apps = {"gobyd": GobyDaemonConfig, "liaison": LiaisonConfig}
    if vehicle.kind != "topside":
        apps |= {"frontseat_interface": FrontSeatInterfaceConfig, "moos_gateway": GobyMOOSGatewayConfig}
    if vehicle.kind == "usv":
        apps |= {"usv_manager": USVManager, "helm": Helm}
    if vehicle.kind == "topside":
        apps |= {"commander": CommandTool}
    for app, message_type in apps.items():
        text = generate(vehicle.kind, app, settings, vehicle)
        msg = text_format.Parse(text, message_type())
        assert msg.app.simulation.time.warp_factor == 7, app
        assert msg.interprocess.platform == vehicle.name, app
        assert msg.interprocess.socket_name == vehicle.ipc_base(settings), app


def test_gobyd_carries_the_links_of_its_platform(settings):
    usv = generate("usv", "gobyd", settings, Vehicle("usv", N))
    auv = generate("auv", "gobyd", settings, Vehicle("auv", N, 3))
    topside = generate("topside", "gobyd", settings, Vehicle("topside", N))
    assert "multicast_port: 54500" in usv and "multicast_port: 54501" in usv
    assert "modem_id: 2\n" in usv and "modem_id: 258\n" in usv
    assert "modem_id: 262\n" in auv and "54500" not in auv
    assert "modem_id: 1\n" in topside and "54501" not in topside
    assert topside.count("slot {") == 2 and "slot_seconds: 5 max_frame_bytes: 64" in topside
    assert auv.count("slot {") == 2 * N and "slot { src: 258 slot_seconds: 10 max_frame_bytes: 128 }" in auv
    assert ("\n# intervehicle {" in usv) != broker_hosts_intervehicle()
    # loopback unless asked: no datagram leaves the machine; TRAIL_LINK_ADDRESS=0.0.0.0 is Goby's default interface
    assert usv.count('listen_address: "127.0.0.1"') == 2
    wide = generate("usv", "gobyd", settings.replace(link_address="0.0.0.0"), Vehicle("usv", N))
    assert wide.count('listen_address: "0.0.0.0"') == 2
    with pytest.raises(MissionConfigError, match="TRAIL_LINK_ADDRESS must be an IPv4 address"):
        settings.replace(link_address="eth0")


def test_manager_blocks_name_the_peer_modems(settings):
    usv = text_format.Parse(generate("usv", "usv_manager", settings, Vehicle("usv", N)), USVManager())
    assert list(usv.auv_modem_id) == [259, 260, 261, 262] and usv.vehicle_id == 1
    assert "usv_modem_id: 258" in generate("auv", "auv_manager", settings, Vehicle("auv", N, 1))
    assert "vehicle_id: 3" in generate("auv", "auv_manager", settings, Vehicle("auv", N, 1))
    assert "usv_modem_id: 2" in generate("topside", "topside_manager", settings, Vehicle("topside", N))
    with pytest.raises(MissionConfigError, match="not defined for platform usv"):
        generate("usv", "auv_manager", settings, Vehicle("usv", N))


def test_moos_and_bhv_files_agree_with_the_goby_side(settings):
    vehicle = Vehicle("auv", N, 2)
    path = generate("auv", "moos", settings, vehicle)
    mission = MissionFile(path)
    assert mission.server_port == 19004 and mission.community == "AUV2" and mission.time_warp == 7
    helm = dict(mission.process_config("pHelmIvP"))
    assert helm["behaviors"] == str(vehicle.bhv_file(settings))
    bhv = vehicle.bhv_file(settings).read_text()
    assert re.search(r"trail_angle = 210\b", bhv) and re.search(r"depth = 30\b", bhv) and "$" not in bhv
    interface = text_format.Parse(generate("auv", "frontseat_interface", settings, vehicle), FrontSeatInterfaceConfig())
    assert interface.frontseat_cfg.DESCRIPTOR.fields_by_name["type"].enum_type.values_by_number[
        interface.frontseat_cfg.type].name == "AUV"
    assert generate("auv", "frontseat_sim", settings, vehicle) == str(settings.sim_port_base + 4)
    usv_moos = MissionFile(generate("usv", "moos", settings, Vehicle("usv", N)))
    assert usv_moos.community == "trail_usv" and usv_moos.server_port == 19001


def test_usv_helm_choice(settings):
    usv = Vehicle("usv", 0)
    assert generate("usv", "helm_command", settings, usv).startswith("ivp-helm ")
    goby = generate("usv", "helm_command", settings.replace(usv_helm="goby", east_duration=30), usv)
    program, path = goby.split()
    assert program == "goby-helm-example" and text_format.Parse(open(path).read(), Helm()).east_duration == 30
    real = generate("usv", "helm_command", settings.replace(helm="pHelmIvP"), usv)
    assert real.startswith("pHelmIvP ")
    with pytest.raises(MissionConfigError, match="ivp or goby"):
        settings.replace(usv_helm="alpha")


def test_course_app_names_are_accepted(settings):
    for course_name, ours in ALIASES.items():
        assert ours in GENERATORS, course_name
    text = generate("usv", "goby3_course_usv_manager", settings, Vehicle("usv", N))
    assert "auv_modem_id: 262" in text


def _config_cli(*args: str, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "launch.trail.config", *args], capture_output=True, text=True,
                          env=env, timeout=60)


def test_cli_failures_are_the_courses(tmp_path):
    base = {"PATH": "/usr/bin:/bin", "TRAIL_RUN_DIR": str(tmp_path)}
    unknown = _config_cli("usv", "pMarineViewer", env=base | {"goby3_course_n_auvs": "1"})
    assert unknown.returncode == 1 and "App: pMarineViewer not defined" in unknown.stderr
    assert INVALID_BANNER in unknown.stdout
    missing = _config_cli("auv", "gobyd", env=base | {"goby3_course_n_auvs": "2"})
    assert missing.returncode == 1 and INVALID_BANNER in missing.stdout
    assert "goby3_course_auv_index must be set" in missing.stderr
    no_n = _config_cli("usv", "moos", env=base)
    assert no_n.returncode == 1 and "goby3_course_n_auvs must be set" in no_n.stderr
    bad_index = _config_cli("auv", "gobyd", env=base | {"goby3_course_n_auvs": "2", "goby3_course_auv_index": "2"})
    assert bad_index.returncode == 1 and "not below goby3_course_n_auvs=2" in bad_index.stderr
    bad_warp = _config_cli("topside", "gobyd", env=base | {"TRAIL_WARP": "fast"})
    assert bad_warp.returncode == 1 and "TRAIL_WARP='fast' is not a valid int" in bad_warp.stderr
    ok = _config_cli("auv", "frontseat_sim", env=base | {"goby3_course_n_auvs": "2", "goby3_course_auv_index": "1"})
    assert ok.returncode == 0 and ok.stdout.strip() == "55003"


def test_vehicle_from_env():
    assert vehicle_from_env("auv", {"goby3_course_n_auvs": "4", "goby3_course_auv_index": "3"}).name == "auv3"
    assert vehicle_from_env("topside", {}).name == "topside"
    with pytest.raises(MissionConfigError, match="is not a whole number"):
        vehicle_from_env("usv", {"goby3_course_n_auvs": "four"})


def test_moos_gen_writes_the_files_and_removes_them_on_sigterm(tmp_path):
    env = {"PATH": "/usr/bin:/bin", "TRAIL_RUN_DIR": str(tmp_path), "goby3_course_n_auvs": "2",
           "goby3_course_auv_index": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "launch.trail.moos_gen", "auv"], env=env,
                            stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().startswith("wrote ")
        assert (tmp_path / "auv1.moos").is_file() and (tmp_path / "auv1.bhv").is_file()
        # it waits as the course's script does, in a shell, not in a Python interpreter for the whole mission
        assert os.path.basename(os.path.realpath(f"/proc/{proc.pid}/exe")) in ("dash", "bash", "sh")
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=30) == 0
        assert proc.stdout.readline().startswith("removed ")
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        proc.stdout.close()
    assert not (tmp_path / "auv1.moos").exists() and not (tmp_path / "auv1.bhv").exists()


def test_launch_files_parse_and_name_only_known_apps():
    assert (TRAIL_DIR / "all.launch").read_text() == all_launch_text(4)
    for name in ("all", "topside", "usv", "auv"):
        entries = parse_file(TRAIL_DIR / f"{name}.launch").entries
        for entry in entries:
            for platform, app in re.findall(r"launch\.trail\.config (\w+) (\w+)", entry.command):
                assert platform == name, entry.command
                assert app in GENERATORS, entry.command
    text = all_launch_text(2, launch_dir="/x")
    assert "-p auv1 /x/auv.launch" in text and "goby3_course_auv_index=1" in text and "auv2" not in text


def test_nested_goby_launch_stops_inner_processes_first_and_logs_beneath_the_parent(tmp_path):
    inner = tmp_path / "inner.launch"
    child = f"{sys.executable} -c \"import signal,sys,time; signal.signal(signal.SIGTERM, lambda *a: (print('inner " \
            f"stopped', time.monotonic(), flush=True), sys.exit(0))); print('up', flush=True); time.sleep(600)\""
    inner.write_text(f"[name=${{GOBY_LAUNCH_PLATFORM}}.worker] {child}\n")
    outer = tmp_path / "outer.launch"
    outer.write_text("[name=first] goby-launch -P -d 10 -p one ${GOBY_LAUNCH_DIR}/inner.launch\n"
                     "[name=second] goby-launch -P -d 10 -p two ${GOBY_LAUNCH_DIR}/inner.launch\n")
    logs = tmp_path / "logs"
    proc = subprocess.Popen([sys.executable, "-m", "launch.apps.goby_launch", "-P", "-d", "50", "-L", str(logs), str(outer)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd="/")
    try:
        deadline = time.monotonic() + 90
        while not all((logs / p / f"{p}.worker.log").is_file() and "up" in (logs / p / f"{p}.worker.log").read_text()
                      for p in ("one", "two")):
            assert time.monotonic() < deadline and proc.poll() is None, "inner launches did not come up"
            time.sleep(0.1)
        proc.send_signal(signal.SIGINT)
        output, _ = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, output
    for platform in ("one", "two"):
        assert "inner stopped" in (logs / platform / f"{platform}.worker.log").read_text()
        assert "Cleaning up" in (logs / ("first" if platform == "one" else "second")).with_suffix(".log").read_text()


def test_trail_deployment_is_generated_from_the_code():
    from launch.interfaces.deployment import DEFAULT_INTERFACES_DIR, load_deployment
    from launch.trail.deployment import deployment_text

    path = DEFAULT_INTERFACES_DIR / "trail_deployment.yml"
    assert path.read_text() == deployment_text(4), "stale: run `python -m launch.trail.deployment 4`"
    deployment = load_deployment(path)
    assert list(deployment.platforms) == ["topside", "usv", "auv0", "auv1", "auv2", "auv3"]
    usv_apps = set(deployment.platforms["usv"].modules["nomodule"].applications)
    assert {"usv-manager", "frontseat-interface", "moos-gateway"} <= usv_apps


def test_a_death_inside_a_nested_launch_is_named_by_both_launchers_and_everything_stops(tmp_path):
    inner = tmp_path / "inner.launch"
    inner.write_text(f"[name=${{GOBY_LAUNCH_PLATFORM}}.sleeper] {sys.executable} -c \"import time; time.sleep(600)\"\n"
                     f"[name=${{GOBY_LAUNCH_PLATFORM}}.crasher] bash -c 'sleep 2; echo boom; exit 3'\n")
    outer = tmp_path / "outer.launch"
    outer.write_text("[name=vehicle] goby-launch -P -d 10 --startup-check 0.2 -p one ${GOBY_LAUNCH_DIR}/inner.launch\n"
                     "[name=other] goby-launch -P -d 10 -p two ${GOBY_LAUNCH_DIR}/inner.launch\n")
    logs = tmp_path / "logs"
    run = subprocess.run([sys.executable, "-m", "launch.apps.goby_launch", "-P", "-d", "10", "--startup-check", "0.2",
                          "-L", str(logs), str(outer)], capture_output=True, text=True, timeout=120, cwd="/")
    output = run.stdout + run.stderr
    assert run.returncode == 1, output
    # the outer launcher names the platform and shows the inner one's report: the process, its status, its log tail
    assert re.search(r"\] \d\d:\d\d:\d\d: (vehicle|other) died unexpectedly \(exit status 1\)", output), output
    assert re.search(r"(one|two)\.crasher died unexpectedly \(exit status 3\)", output) and "boom" in output, output
    sleepers = [int(pid) for path in logs.rglob("*.log")
                for pid in re.findall(r"^Launched \((\d+)\) \w+\.sleeper", path.read_text(), flags=re.M)]
    assert sleepers and not any(Path(f"/proc/{pid}").exists() for pid in sleepers), sleepers
