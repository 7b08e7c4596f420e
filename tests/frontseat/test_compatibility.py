"""Wire compatibility with Goby3: group strings, full message names, field numbers, defaults, extensions."""

from __future__ import annotations

import math

from google.protobuf import text_format

from frontseat import groups
from frontseat.protobuf import basic_simulator_config_pb2 as sim_pb
from frontseat.protobuf import frontseat_config_pb2 as config_pb
from frontseat.protobuf import frontseat_data_pb2 as data_pb
from frontseat.protobuf import frontseat_interface_config_pb2 as app_pb
from frontseat.protobuf import frontseat_pb2 as fs
from frontseat.protobuf import moos_helm_frontseat_interface_config_pb2 as helm_pb
from gateway.goby.protobuf import geographic_pb2 as geo_pb

GOBY_GROUPS = {
    "node_status", "desired_course", "raw_in", "raw_out", "raw_send_request", "command_request",
    "command_response", "data_from_frontseat", "data_to_frontseat", "helm_state", "status",
}


def test_group_strings_are_gobys() -> None:
    for name in GOBY_GROUPS:
        assert str(getattr(groups, name)) == f"goby::middleware::frontseat::{name}"
    assert {str(g) for g in groups.ALL} == {f"goby::middleware::frontseat::{n}" for n in GOBY_GROUPS}
    assert str(groups.datum_update) == "goby::datum_update"


def numbers(message: type) -> dict[str, int]:
    return {f.name: f.number for f in message.DESCRIPTOR.fields}


def test_full_names_and_field_numbers() -> None:
    assert fs.InterfaceStatus.DESCRIPTOR.full_name == "goby.middleware.frontseat.protobuf.InterfaceStatus"
    assert data_pb.NodeStatus.DESCRIPTOR.full_name == "goby.middleware.frontseat.protobuf.NodeStatus"
    assert geo_pb.LatLonPoint.DESCRIPTOR.full_name == "goby.middleware.protobuf.LatLonPoint"
    assert app_pb.FrontSeatInterfaceConfig.DESCRIPTOR.full_name == "goby.apps.zeromq.protobuf.FrontSeatInterfaceConfig"
    assert numbers(data_pb.NodeStatus) == {
        "time": 1, "name": 2, "type": 3, "global_fix": 10, "local_fix": 11, "pose": 20, "speed": 30, "source": 40
    }
    assert numbers(fs.CommandRequest) == {
        "desired_course": 1, "response_requested": 10, "request_id": 11, "cancel_request_id": 20
    }
    assert numbers(fs.CommandResponse) == {"request_successful": 10, "request_id": 11, "error_code": 20,
                                           "error_string": 21}
    assert numbers(data_pb.CTDSample)["time"] == 2
    assert numbers(config_pb.Config) == {
        "name": 1, "origin": 2, "type": 3, "require_helm": 10, "helm_running_timeout": 11,
        "frontseat_connected_timeout": 12, "status_period": 13, "exit_on_error": 21, "sim_warp_factor": 30,
    }
    assert numbers(app_pb.FrontSeatInterfaceConfig) == {"app": 1, "interprocess": 2, "frontseat_cfg": 10}
    assert sim_pb.basic_simulator_config.number == 1001
    assert helm_pb.moos_helm.number == 1000
    assert data_pb.OTHER == -1 and data_pb.USV == 20


def test_defaults() -> None:
    course = data_pb.DesiredCourse()
    assert (course.altitude, course.heading, course.depth) == (10, 0, 0)
    assert math.isnan(geo_pb.LatLonPoint().altitude)
    cfg = config_pb.Config()
    assert (cfg.type, cfg.require_helm, cfg.helm_running_timeout, cfg.frontseat_connected_timeout) == (
        data_pb.AUV, True, 10, 10
    )
    assert (cfg.status_period, cfg.exit_on_error, cfg.sim_warp_factor) == (5, False, 1)
    assert fs.Raw().type == fs.Raw.RAW_ASCII
    start = sim_pb.BasicSimulatorFrontSeatConfig.StartParams()
    assert (start.duration, start.control_freq) == (0, 10)
    assert (start.vehicle.accel, start.vehicle.hdg_rate, start.vehicle.z_rate) == (0.5, 45, 2)
    assert sim_pb.BasicSimulatorFrontSeatConfig().tcp_port == 54321


def test_the_courses_frontseat_config_parses() -> None:
    text = """
    app { geodesy { lat_origin: 41.592344 lon_origin: -70.711260 }
          simulation { time { use_sim_time: true warp_factor: 10 reference_microtime: 0 } } }
    interprocess { platform: "usv" }
    frontseat_cfg { require_helm: true helm_running_timeout: 10 frontseat_connected_timeout: 10
      status_period: 5 exit_on_error: false type: USV
      [goby.middleware.frontseat.protobuf.basic_simulator_config] {
        tcp_address: "127.0.0.1" tcp_port: 54321
        start { lat: 41.59 lon: -70.71 duration: 0 control_freq: 10
                vehicle { accel: 1.0 hdg_rate: 80 z_rate: 2 } } } }
    [goby.moos.protobuf.moos_helm] { server: "localhost" port: 9000 use_binary_protobuf: false
      moos_parser_technique: TECHNIQUE_PREFIXED_PROTOBUF_TEXT_FORMAT }
    """
    cfg = text_format.Parse(text, app_pb.FrontSeatInterfaceConfig())
    sim = cfg.frontseat_cfg.Extensions[sim_pb.basic_simulator_config]
    assert (sim.tcp_port, sim.start.vehicle.hdg_rate) == (54321, 80)
    assert cfg.Extensions[helm_pb.moos_helm].port == 9000
