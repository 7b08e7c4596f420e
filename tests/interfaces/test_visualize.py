"""Deployment graphs: which edges exist, Goby's node ids and styles, and DOT that Graphviz accepts."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from launch.apps.goby_interfaces import main as cli_main
from launch.interfaces.deployment import DeploymentError, load_deployment
from launch.interfaces.interface_yaml import dumps
from launch.interfaces.model import ApplicationInterface, PubSubEntry
from launch.interfaces.visualize import VizOptions, build_graph, escape_id, to_dot

FS = "goby::middleware::frontseat::"
PB = "goby::middleware::frontseat::protobuf::"


def _write(path: Path, app: str, entries: list[PubSubEntry]) -> str:
    interface = ApplicationInterface(app)
    for entry in entries:
        interface.add(entry)
    path.write_text(dumps(interface))
    return path.name


@pytest.fixture
def deployment(tmp_path: Path) -> Path:
    helm = "helm.Thread"
    iface = "iface.Main"
    _write(tmp_path / "helm_interface.yml", "helm", [
        PubSubEntry("interprocess", helm, FS + "desired_course", "PROTOBUF", PB + "DesiredCourse", "publishes"),
        PubSubEntry("interprocess", helm, FS + "node_status", "PROTOBUF", PB + "NodeStatus", "subscribes", "required"),
        PubSubEntry("interprocess", helm, "lonely", "PROTOBUF", "x::Lonely", "subscribes", "required"),
        PubSubEntry("intervehicle", helm, "nav;1", "DCCL", "x::Nav", "publishes"),
    ])
    _write(tmp_path / "iface_interface.yml", "iface", [
        PubSubEntry("interprocess", iface, FS + "node_status", "PROTOBUF", PB + "NodeStatus", "publishes"),
        PubSubEntry("interprocess", iface, FS + "desired_course", "PROTOBUF", PB + "DesiredCourse", "subscribes"),
        PubSubEntry("interprocess", iface, FS + "status", "PROTOBUF", PB + "InterfaceStatus", "publishes"),
    ])
    _write(tmp_path / "shore_interface.yml", "shore", [
        PubSubEntry("intervehicle", "shore.Main", "nav;1", "DCCL", "x::Nav", "subscribes", "recommended"),
    ])
    path = tmp_path / "deploy.yml"
    path.write_text(
        "deployment: test_deployment\nplatforms:\n"
        "  - name: usv\n    interfaces:\n      - helm_interface.yml\n      - file: iface_interface.yml\n"
        "  - name: topside\n    interfaces:\n      - shore_interface.yml\n"
        "  - name: other\n    interfaces:\n      - iface_interface.yml\n"
    )
    return path


def _edges(path: Path, **options) -> set[tuple[str, str, str, str, str]]:
    graph = build_graph(load_deployment(path), VizOptions(**options))
    return {(e.publisher.platform, e.publisher.application, e.subscriber.platform, e.subscriber.application, e.group)
            for e in graph.edges}


def test_interprocess_edges_stay_on_their_platform(deployment: Path) -> None:
    edges = _edges(deployment)
    assert ("usv", "helm", "usv", "iface", FS + "desired_course") in edges
    assert ("usv", "iface", "usv", "helm", FS + "node_status") in edges
    assert not any(e[0] == "other" and e[2] == "usv" for e in edges)


def test_intervehicle_edges_only_between_platforms(deployment: Path) -> None:
    edges = _edges(deployment)
    assert ("usv", "helm", "topside", "shore", "nav;1") in edges
    assert not any(e[4] == "nav;1" and e[0] == e[2] for e in edges)


def test_dot_has_goby_styles_and_ids(deployment: Path) -> None:
    text = to_dot(build_graph(load_deployment(deployment)))
    helm_id = "usv_nomodule_helm_" + escape_id("helm.Thread")
    assert helm_id == "usv_nomodule_helm_helm_46_Thread"
    assert "digraph test_deployment {" in text and "splines=ortho" in text
    assert 'fontcolor="#006400"' in text and 'fontcolor="#104e8b"' in text
    # required subscription fed by the interface: bold; recommended intervehicle: tapered
    assert any(line.startswith(f"\t\tusv_nomodule_iface_iface_46_Main->{helm_id}") and "style=bold" in line
               for line in text.splitlines())
    assert "style=tapered" in text
    # the required subscription nobody publishes is drawn in red even with --no-disconnected
    compact = to_dot(build_graph(load_deployment(deployment), VizOptions(no_disconnected=True)),
                     VizOptions(no_disconnected=True))
    assert 'color="red"' in compact
    assert "_no_subscribers_" in text and "_no_subscribers_" not in compact


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz `dot` is not installed")
def test_graphviz_accepts_the_dot(deployment: Path, tmp_path: Path) -> None:
    assert cli_main(["visualize", str(deployment), "--outdir", str(tmp_path), "--format", "svg"]) == 0
    svg = (tmp_path / "test_deployment.svg").read_text()
    assert "<svg" in svg and "desired_course" in svg
    subprocess.run(["dot", "-Tcanon", str(tmp_path / "test_deployment.dot")], check=True, capture_output=True)


def test_bad_deployments_are_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.yml"
    bad.write_text("deployment: x\nplatforms: {usv: a.yml}\n")
    with pytest.raises(DeploymentError, match="platforms: as a sequence"):
        load_deployment(bad)
    assert cli_main(["visualize", str(bad), "--outdir", str(tmp_path)]) == 1
    assert "bad.yml" in capsys.readouterr().err


def test_unreadable_interface_file_is_reported_and_skipped(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    (tmp_path / "broken.yml").write_text("application: [unterminated")
    (tmp_path / "d.yml").write_text("deployment: d\nplatforms:\n  - name: p\n    interfaces: [broken.yml, missing.yml]\n")
    deployment = load_deployment(tmp_path / "d.yml")
    assert deployment.platforms["p"].modules["nomodule"].applications == {}
    assert "Failed to parse broken.yml" in caplog.text and "Failed to parse missing.yml" in caplog.text


def test_unquoted_interfaces_dir_token_as_in_the_course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    iface_dir = tmp_path / "share"
    iface_dir.mkdir()
    _write(iface_dir / "a_interface.yml", "a", [
        PubSubEntry("interprocess", "A", FS + "status", "PROTOBUF", PB + "InterfaceStatus", "publishes")])
    (tmp_path / "d.yml").write_text(
        "deployment: d\nplatforms:\n  - name: p\n    interfaces:\n      - @GOBY_INTERFACES_DIR@/a_interface.yml\n")
    monkeypatch.setenv("GOBY_INTERFACES_DIR", str(iface_dir))
    deployment = load_deployment(tmp_path / "d.yml")
    assert list(deployment.platforms["p"].modules["nomodule"].applications) == ["a"]
