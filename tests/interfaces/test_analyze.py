"""Static analysis of publish/subscribe calls: what it finds, and the errors that keep it honest."""

from __future__ import annotations

import sys
import textwrap
import uuid
from pathlib import Path

import pytest

from launch.interfaces.analyze import AnalysisError, analyze_modules

PREAMBLE = """
from __future__ import annotations
from frontseat import groups
from frontseat.protobuf.frontseat_pb2 import InterfaceData, HelmStateReport
from frontseat.protobuf.frontseat_data_pb2 import DesiredCourse, NodeStatus
from gateway.goby.portal import Group, SimpleThread

custom = Group("test::custom", 3)

def make_course() -> DesiredCourse:
    return DesiredCourse(speed=1.0)

def course_and_notes() -> tuple[DesiredCourse, list[str]]:
    return DesiredCourse(), []

class Plan:
    def to_message(self, now: float) -> HelmStateReport:
        return HelmStateReport()
"""


@pytest.fixture
def write_module(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    created: list[str] = []

    def write(body: str) -> str:
        name = f"app_{uuid.uuid4().hex[:8]}"
        (tmp_path / f"{name}.py").write_text(PREAMBLE + textwrap.dedent(body))
        created.append(name)
        return name

    yield write
    for name in created:
        sys.modules.pop(name, None)


def _entries(module: str) -> set[tuple[str, str, str, str, str]]:
    interface = analyze_modules("app", [module])
    return {(e.layer, e.direction, e.group, e.scheme, e.type) for e in interface.entries if not e.inner}


def test_finds_calls_and_resolves_types_every_supported_way(write_module) -> None:
    module = write_module("""
    class Helm(SimpleThread):
        def __init__(self, cfg) -> None:
            super().__init__(cfg)
            self.interprocess().subscribe(groups.node_status, NodeStatus, self.on_status)
            portal = self.interprocess()
            portal.subscribe(custom, HelmStateReport, self.on_status)
            self.interthread().subscribe(groups.status, InterfaceData, self.on_status)

        def on_status(self, data: InterfaceData) -> None:
            self.interprocess().publish(groups.node_status, data.node_status)   # field of an annotated arg
            course = DesiredCourse(heading=90)
            self.interprocess().publish(groups.desired_course, course)          # constructor
            self.interprocess().publish(custom, make_course())                  # return annotation
            chosen, _notes = course_and_notes()
            self.interthread().publish(groups.desired_course, chosen)           # tuple element
            self.interprocess().publish(groups.raw_in, "text")                  # CSTR
            plan: Plan = self.plans.pop(0)
            self.interprocess().publish(groups.helm_state, plan.to_message(0.0))  # method of an annotated local
    """)
    ns = "goby::middleware::frontseat::"
    pb = "goby::middleware::frontseat::protobuf::"
    assert _entries(module) == {
        ("interprocess", "subscribes", ns + "node_status", "PROTOBUF", pb + "NodeStatus"),
        ("interprocess", "subscribes", "test::custom;3", "PROTOBUF", pb + "HelmStateReport"),
        ("interthread", "subscribes", ns + "status", "CXX_OBJECT", pb + "InterfaceData"),
        ("interprocess", "publishes", ns + "node_status", "PROTOBUF", pb + "NodeStatus"),
        ("interprocess", "publishes", ns + "desired_course", "PROTOBUF", pb + "DesiredCourse"),
        ("interprocess", "publishes", "test::custom;3", "PROTOBUF", pb + "DesiredCourse"),
        ("interthread", "publishes", ns + "desired_course", "CXX_OBJECT", pb + "DesiredCourse"),
        ("interprocess", "publishes", ns + "raw_in", "CSTR", "std::string"),
        ("interprocess", "publishes", ns + "helm_state", "PROTOBUF", pb + "HelmStateReport"),
    }
    interface = analyze_modules("app", [module])
    thread = f"{module}.Helm"
    assert interface.threads[thread].bases[0] == "gateway.goby.portal.thread.SimpleThread"


def test_regex_subscription_records_its_patterns(write_module) -> None:
    module = write_module("""
    class Scope(SimpleThread):
        def start(self) -> None:
            self.interprocess().subscribe_regex(self.on_any, group_regex="goby::.*", type_regex=".*Status")

        def on_any(self, *args) -> None:
            pass
    """)
    interface = analyze_modules("app", [module])
    (entry,) = interface.entries
    assert (entry.group, entry.type, entry.scheme, entry.is_regex) == ("goby::.*", ".*Status", "ALL_SCHEMES", True)


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("def f(self, msg):\n    self.interprocess().publish(groups.status, msg)", "cannot tell the type of published `msg`"),
        ("def f(self):\n    self.interprocess().publish(nowhere.group, DesiredCourse())", "cannot resolve the group"),
        ("def f(self):\n    self.interprocess().subscribe(groups.status, 42, print)", "not a protobuf message class"),
        ("def f(self):\n    self.interprocess().subscribe(groups.status)", "without a message type"),
    ],
)
def test_unresolvable_calls_are_errors_naming_file_and_line(write_module, body: str, message: str) -> None:
    module = write_module("class T(SimpleThread):\n" + textwrap.indent(body, "    ") + "\n")
    with pytest.raises(AnalysisError, match=message) as info:
        analyze_modules("app", [module])
    assert f"{module}.py:" in str(info.value)


def test_calls_on_other_objects_are_not_portal_calls(write_module) -> None:
    module = write_module("""
    class Bus:
        def publish(self, a, b) -> None:
            pass

    def use(bus: Bus) -> None:
        bus.publish(1, 2)
    """)
    assert analyze_modules("app", [module]).entries == set()
