"""Interface YAML in goby_clang_tool's layout, and back."""

from __future__ import annotations

import pytest

from launch.interfaces.interface_yaml import InterfaceFileError, dumps, loads
from launch.interfaces.model import ApplicationInterface, PubSubEntry

THREAD = "translators.frontseat.translation.FrontSeatTranslation"
DESIRED = ("goby::middleware::frontseat::desired_course", "goby::middleware::frontseat::protobuf::DesiredCourse")
NODE = ("goby::middleware::frontseat::node_status", "goby::middleware::frontseat::protobuf::NodeStatus")


def _frontseat_plugin() -> ApplicationInterface:
    interface = ApplicationInterface("frontseat_plugin")
    interface.add(PubSubEntry("interprocess", THREAD, DESIRED[0], "PROTOBUF", DESIRED[1], "publishes"))
    interface.add(PubSubEntry("interprocess", THREAD, NODE[0], "PROTOBUF", NODE[1], "subscribes"))
    return interface


def test_layout_matches_goby_schema() -> None:
    expected = f"""application: frontseat_plugin
interprocess:
  publishes:
    - group: {DESIRED[0]}
      scheme: PROTOBUF
      type: {DESIRED[1]}
      thread: {THREAD}
  subscribes:
    - group: {NODE[0]}
      scheme: PROTOBUF
      type: {NODE[1]}
      necessity: optional
      thread: {THREAD}
interthread:
  threads:
    - name: {THREAD}
      known: true
      publishes:
        - group: {DESIRED[0]}
          scheme: CXX_OBJECT
          type: {DESIRED[1]}
          inner: true
      subscribes: []
"""
    assert dumps(_frontseat_plugin()) == expected


def test_publication_is_copied_to_inner_layers_only() -> None:
    interface = ApplicationInterface("a")
    interface.add(PubSubEntry("intervehicle", "T", "g;1", "DCCL", "x::Y", "publishes"))
    layers = sorted((e.layer, e.scheme, e.inner) for e in interface.entries)
    assert layers == [
        ("interprocess", "DCCL", True),
        ("interprocess", "PROTOBUF", True),
        ("interthread", "CXX_OBJECT", True),
        ("intervehicle", "DCCL", False),
    ]
    assert interface.used_layers() == ["intervehicle", "interprocess", "interthread"]


def test_round_trip_keeps_every_entry() -> None:
    original = _frontseat_plugin()
    original.add(PubSubEntry("interprocess", THREAD, "with space", "CSTR", "std::string", "subscribes", "required"))
    again = loads(dumps(original))
    assert again.application == original.application
    assert again.entries == original.entries
    assert '"with space"' in dumps(original)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("not: [valid", "not valid YAML"),
        ("interprocess: {}", "'application' key"),
        ("application: a\ninterprocess:\n  publishes:\n    - group: g\n", "needs group, scheme and type"),
        ("application: a\ninterprocess: 3\n", "must be a mapping"),
    ],
)
def test_bad_files_are_named(text: str, message: str) -> None:
    with pytest.raises(InterfaceFileError, match=message) as info:
        loads(text, "bad.yml")
    assert "bad.yml" in str(info.value)


def test_unknown_layer_or_necessity_is_refused() -> None:
    with pytest.raises(ValueError, match="unknown layer"):
        PubSubEntry("interplanetary", "T", "g", "PROTOBUF", "t", "publishes")
    with pytest.raises(ValueError, match="unknown necessity"):
        PubSubEntry("interprocess", "T", "g", "PROTOBUF", "t", "subscribes", necessity="maybe")
