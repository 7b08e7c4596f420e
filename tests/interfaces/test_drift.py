"""The drift check itself: it must flag an undeclared call and a declared subscription never made."""

from __future__ import annotations

from gateway.goby.portal.interface_registry import InterfaceEntry
from launch.interfaces.drift import covered_threads, drift_problems
from launch.interfaces.model import ApplicationInterface, PubSubEntry

G = "goby::middleware::frontseat::node_status"
T = "goby.middleware.frontseat.protobuf.NodeStatus"


def _interface() -> ApplicationInterface:
    interface = ApplicationInterface("app")
    interface.add(PubSubEntry("interprocess", "pkg.mod.Helm", G, "PROTOBUF", T.replace(".", "::"), "subscribes"))
    interface.add(PubSubEntry("interprocess", "pkg.mod.Helm", "out", "PROTOBUF", T.replace(".", "::"), "publishes"))
    return interface


def _record(direction: str, group: str, thread: str = "Helm") -> InterfaceEntry:
    return InterfaceEntry("interprocess", direction, group, "PROTOBUF", T, thread, "app")


def test_matching_run_has_no_problems() -> None:
    runtime = [_record("subscribe", G), _record("subscribe", "goby::zeromq::_internal_manager_response")]
    assert drift_problems(runtime, [_interface()]) == []  # a publication that did not happen is fine
    assert covered_threads(runtime, [_interface()]) == {"Helm"}


def test_undeclared_call_and_missing_subscription_are_flagged() -> None:
    problems = drift_problems([_record("publish", "sneaky")], [_interface()])
    assert any("missing from its interface file" in p and "sneaky" in p for p in problems)
    assert any("never subscribed at run time" in p and G in p for p in problems)


def test_threads_only_on_one_side_are_not_compared() -> None:
    assert drift_problems([_record("publish", "x", thread="Other")], [_interface()]) == []
