"""The interface files we ship: derived from the code, identical to what is committed, faithful to Goby."""

from __future__ import annotations

from pathlib import Path

import pytest

from launch.interfaces.analyze import analyze_modules
from launch.interfaces.catalog import SHIPPED_APPLICATIONS, generate_text, interface_file_name
from launch.interfaces.deployment import DEFAULT_INTERFACES_DIR, load_deployment
from launch.interfaces.visualize import VizOptions, build_graph

FS = "goby::middleware::frontseat::"
PB = "goby::middleware::frontseat::protobuf::"


def _frontseat(direction: str, *names: str) -> set[tuple[str, str, str]]:
    """``(direction, group, type)`` for frontseat groups, each name ``group:Type`` (type in the protobuf package)."""
    return {(direction, FS + group, PB + type_name) for group, type_name in (n.split(":") for n in names)}


# goby_frontseat_interface's interprocess interface (goby_frontseat.md §4.3): (direction, group, type), all PROTOBUF.
ORIGINAL_FRONTSEAT_INTERFACE = (
    _frontseat("subscribes", "helm_state:HelmStateReport", "command_request:CommandRequest",
               "desired_course:DesiredCourse", "data_to_frontseat:InterfaceData", "raw_send_request:Raw")
    | {("subscribes", "goby::datum_update", "goby::middleware::protobuf::DatumUpdate")}
    | _frontseat("publishes", "command_response:CommandResponse", "data_from_frontseat:InterfaceData",
                 "node_status:NodeStatus", "raw_in:Raw", "raw_out:Raw", "status:InterfaceStatus")
    # Goby's application base class announces the configuration at start, and answers health and terminate requests
    | {("publishes", "goby::configuration", "goby::apps::zeromq::protobuf::FrontSeatInterfaceConfig")}
    | {("subscribes", "goby::health::request", "goby::middleware::protobuf::HealthRequest"),
       ("publishes", "goby::health::response", "goby::middleware::protobuf::ProcessHealth"),
       ("subscribes", "goby::terminate::request", "goby::middleware::protobuf::TerminateRequest"),
       ("publishes", "goby::terminate::response", "goby::middleware::protobuf::TerminateResponse")}
)
# The embedded FrontSeatTranslation (the moos_helm block; Goby's interface file lists it in goby_frontseat_interface
# too): Goby3's frontseat_gateway_plugin.h/.cpp subscribe node_status and publish helm_state and desired_course;
# ours also follows datum updates (docs/translators.md).
ORIGINAL_FRONTSEAT_TRANSLATION = _frontseat("subscribes", "node_status:NodeStatus") | _frontseat(
    "publishes", "helm_state:HelmStateReport", "desired_course:DesiredCourse")


def test_frontseat_interface_matches_the_original() -> None:
    interface = analyze_modules("frontseat-interface", SHIPPED_APPLICATIONS["frontseat-interface"])
    interprocess = [e for e in interface.entries if e.layer == "interprocess"]
    assert {e.scheme for e in interprocess} == {"PROTOBUF"}
    by_thread: dict[str, set[tuple[str, str, str]]] = {}
    for e in interprocess:
        by_thread.setdefault(e.thread.rsplit(".", 1)[-1], set()).add((e.direction, e.group, e.type))
    assert by_thread["FrontSeatInterface"] == ORIGINAL_FRONTSEAT_INTERFACE
    extra = {("subscribes", "goby::datum_update", "goby::middleware::protobuf::DatumUpdate")}
    assert by_thread["FrontSeatTranslation"] == ORIGINAL_FRONTSEAT_TRANSLATION | extra
    assert set(by_thread) == {"FrontSeatInterface", "FrontSeatTranslation"}


@pytest.mark.parametrize("app", sorted(SHIPPED_APPLICATIONS))
def test_committed_interface_file_is_up_to_date(app: str) -> None:
    committed = DEFAULT_INTERFACES_DIR / interface_file_name(app)
    assert committed.exists(), f"missing {committed}: run `make interfaces`"
    assert generate_text(app) == committed.read_text(), f"{committed.name} is stale: run `make interfaces`"


def _edge_set(path: Path) -> set[tuple[str, str, str]]:
    graph = build_graph(load_deployment(path), VizOptions(no_disconnected=True))
    return {(e.publisher.application, e.subscriber.application, e.group) for e in graph.edges
            if e.layer == "interprocess"}


def test_usv_deployment_has_the_edges_the_mission_needs() -> None:
    edges = _edge_set(DEFAULT_INTERFACES_DIR / "usv_deployment.yml")
    # the embedded FrontSeatTranslation and the interface talk over interprocess inside one process
    assert ("frontseat-interface", "frontseat-interface", FS + "desired_course") in edges
    assert ("frontseat-interface", "frontseat-interface", FS + "helm_state") in edges
    assert ("frontseat-interface", "frontseat-interface", FS + "node_status") in edges
    assert ("usv-manager", "moos-gateway", "goby3_course::usv_command;0") in edges
    assert ("usv-command", "usv-manager", "goby3_course::shore::usv_command;0") in edges
    assert ("moos-gateway", "usv-command", "goby3_course::usv_command_ack") in edges
    # the health chain: goby-coroner's report to usv-health-monitor (docs/health.md)
    assert ("goby-coroner", "usv-health-monitor", "goby::health::report") in edges
